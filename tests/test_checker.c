/* The intersection checker (checker.c): the triangle-triangle test on
 * crossing, separated, touching, coplanar, parallel and flat pairs, and
 * wc_world_count_intersections on flat, folded and crossing cloths and on
 * mesh and convex colliders, with exact counts where they are easy to know,
 * plus its speed on 64 x 64 and 128 x 128 cloths. */
/* clock_gettime: wall time, since clock() adds up every thread's time */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "checker.h"
#include "convex.h"
#include "predicates.h"
#include "test_util.h"
#include "wetcloth.h"

/* ---- wci_triangles_intersect ---- */

/* Checks a pair both ways round, with the vertices of each rotated, so the
 * answer cannot depend on the order of the arguments. */
static void expect_pair(const double p[3][3], const double q[3][3], int expect, const char *what)
{
    for (int swap = 0; swap < 2; ++swap)
        for (int rp = 0; rp < 3; ++rp)
            for (int rq = 0; rq < 3; ++rq) {
                const double(*a)[3] = swap ? q : p, (*b)[3] = swap ? p : q;
                int got = wci_triangles_intersect(a[rp], a[(rp + 1) % 3], a[(rp + 2) % 3], b[rq],
                                                 b[(rq + 1) % 3], b[(rq + 2) % 3]);
                CHECK(got == expect, "%s (swap %d, rotations %d %d): %d, expected %d", what, swap, rp, rq,
                      got, expect);
            }
}

static void test_triangle_pairs(void)
{
    const double base[3][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    {
        const double q[3][3] = {{0.2, 0.2, -1}, {0.3, 0.2, 1}, {0.2, 0.4, 1}};
        expect_pair(base, q, 1, "crossing");
    }
    {
        const double q[3][3] = {{2, 2, -1}, {3, 2, 1}, {2, 3, 1}};
        expect_pair(base, q, 0, "separated, boxes apart");
    }
    {
        /* boxes overlap, planes cross, but the crossing misses the triangle */
        const double q[3][3] = {{0.8, 0.8, -1}, {0.9, 0.8, 1}, {0.8, 0.9, 1}};
        expect_pair(base, q, 0, "separated beyond the hypotenuse");
    }
    {
        const double q[3][3] = {{0.2, 0.2, 0}, {0.3, 0.2, 1}, {0.2, 0.4, 1}};
        expect_pair(base, q, 1, "vertex touching the face");
    }
    {
        const double q[3][3] = {{1, 0, 0}, {2, 0, 1}, {2, 1, 1}};
        expect_pair(base, q, 1, "vertex touching a vertex");
    }
    {
        const double q[3][3] = {{0.5, -0.5, 0}, {0.5, 0.5, 0.0}, {0.5, 0, 1}};
        expect_pair(base, q, 1, "edge lying across the face");
    }
    {
        /* edge against edge: q's edge crosses p's edge x = 0 at (0, 0.5, 0) */
        const double q[3][3] = {{-0.5, 0.5, -0.5}, {0.5, 0.5, 0.5}, {-1, 2, 0}};
        expect_pair(base, q, 1, "edge through an edge");
    }
    {
        const double q[3][3] = {{0.2, 0.2, 1e-9}, {0.3, 0.2, 1}, {0.2, 0.4, 1}};
        expect_pair(base, q, 0, "vertex just above the face");
    }
    {
        const double q[3][3] = {{0.2, 0.2, 0}, {0.8, 0.1, 0}, {0.1, 0.8, 0}};
        expect_pair(base, q, 1, "coplanar, one inside the other");
    }
    {
        const double q[3][3] = {{0.5, 0.5, 0}, {1.5, 0.5, 0}, {0.5, 1.5, 0}};
        expect_pair(base, q, 1, "coplanar, overlapping");
    }
    {
        const double q[3][3] = {{1, 0, 0}, {2, 0, 0}, {1, 1, 0}};
        expect_pair(base, q, 1, "coplanar, sharing a vertex position");
    }
    {
        const double q[3][3] = {{0.5, 0.5, 0}, {1, 1, 0}, {0, 1, 0}};
        expect_pair(base, q, 1, "coplanar, touching along an edge");
    }
    {
        const double q[3][3] = {{0.6, 0.6, 0}, {1.6, 0.6, 0}, {0.6, 1.6, 0}};
        expect_pair(base, q, 0, "coplanar, separate");
    }
    {
        const double q[3][3] = {{0, 0, 0.1}, {1, 0, 0.1}, {0, 1, 0.1}};
        expect_pair(base, q, 0, "parallel planes");
    }
    {
        /* a flat (zero-area) triangle is its longest edge */
        const double q[3][3] = {{0.2, 0.2, -1}, {0.2, 0.2, 1}, {0.2, 0.2, 0.5}};
        expect_pair(base, q, 1, "flat triangle piercing");
        const double r[3][3] = {{0.9, 0.9, -1}, {0.9, 0.9, 1}, {0.9, 0.9, 0.5}};
        expect_pair(base, r, 0, "flat triangle missing");
        const double s[3][3] = {{0.2, -1, 0}, {0.2, 2, 0}, {0.2, 0.5, 0}};
        expect_pair(base, s, 1, "flat triangle lying across");
        const double t[3][3] = {{-1, 0.5, 0.5}, {1, 0.5, -0.5}, {0, 0.5, 0}};
        const double u[3][3] = {{0, -1, 0}, {0, 1, 0}, {0, 0, 0}};
        expect_pair(t, u, 1, "two flat triangles crossing");
        const double v[3][3] = {{0, -1, 0.01}, {0, 1, 0.01}, {0, 0, 0.01}};
        expect_pair(t, v, 0, "two flat triangles passing");
    }
    {
        /* a flat sheet in a slanted plane: neighbours two cells apart are
         * coplanar up to rounding and must not be found crossing */
        double n[3] = {1, 2, 3}, u[3], v[3];
        double l = sqrt(14.0);
        for (int k = 0; k < 3; ++k) n[k] /= l;
        u[0] = 2 / sqrt(5.0), u[1] = -1 / sqrt(5.0), u[2] = 0;
        v[0] = n[1] * u[2] - n[2] * u[1], v[1] = n[2] * u[0] - n[0] * u[2], v[2] = n[0] * u[1] - n[1] * u[0];
        const double p2[3][2] = {{0, 0}, {1, 0}, {0, 1}}, q2[3][2] = {{1.01, 0}, {2, 0}, {1.01, 1}};
        double p[3][3], q[3][3];
        for (int i = 0; i < 3; ++i)
            for (int k = 0; k < 3; ++k) {
                p[i][k] = 0.3 + p2[i][0] * u[k] + p2[i][1] * v[k];
                q[i][k] = 0.3 + q2[i][0] * u[k] + q2[i][1] * v[k];
            }
        expect_pair((const double(*)[3])p, (const double(*)[3])q, 0, "slanted coplanar, separate");
        /* q's corner moved over p: in exact arithmetic the rounded corners
         * all lie a rounding error above p's plane, so the two only come
         * within 1e-17 m of each other and do not intersect (the checker's
         * predicates are exact: close is not touching) */
        for (int k = 0; k < 3; ++k) q[0][k] = 0.3 + 0.4 * u[k] + 0.4 * v[k];
        expect_pair((const double(*)[3])p, (const double(*)[3])q, 0,
                    "slanted nearly coplanar, over each other by rounding only");
    }
    {
        /* exactly coplanar in a slanted plane, x + 2 y + 4 z = 1 (dyadic
         * coordinates, so every corner is on it exactly): overlapping, then
         * moved apart along the plane, then touching at a corner */
        const double p[3][3] = {{1, 0, 0}, {0, 0.5, 0}, {0, 0, 0.25}};
        double q[3][3] = {{0.5, 0.125, 0.0625}, {1, 0.5, -0.25}, {1, -0.5, 0.25}};
        expect_pair(p, (const double(*)[3])q, 1, "slanted coplanar, overlapping");
        for (int i = 0; i < 3; ++i) q[i][0] += 6, q[i][1] -= 3;
        expect_pair(p, (const double(*)[3])q, 0, "slanted coplanar, moved apart along the plane");
        const double r[3][3] = {{1, 0, 0}, {2, 0.5, -0.5}, {2, -0.5, 0}};
        expect_pair(p, r, 1, "slanted coplanar, touching at a corner");
    }
    {
        /* A layer a hair above another: 1e-15 m is far more than nothing,
         * so no intersection, however close; touching exactly counts. */
        const double a[3][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
        const double b[3][3] = {{-0.5, 0.2, 1e-15}, {1.5, 0.2, 1e-15}, {0.2, 1.5, 1e-15}};
        expect_pair(a, b, 0, "a layer 1e-15 m above another");
        const double c[3][3] = {{0.2, 0.2, 1e-300}, {0.3, 0.2, 1}, {0.2, 0.4, 1}};
        expect_pair(a, c, 0, "a corner 1e-300 m above a face");
        const double d[3][3] = {{0.2, 0.2, 0}, {0.3, 0.2, 1}, {0.2, 0.4, 1}};
        expect_pair(a, d, 1, "a corner exactly on a face");
    }
    {
        /* Two triangles of a 64 x 64 sheet falling flat, half a cell apart,
         * whose heights differ by rounding (up to 6e-14 m) after two frames:
         * once counted as crossing (the line where their planes meet, 1e-9
         * rad apart, was placed by noise). Coordinates as the simulation
         * left them. */
        const double p[3][3] = {{-0.21270064137919761, -0.22854424084076114, 0.27606305938876485},
                                {-0.19688030757707123, -0.22852300966400393, 0.27606305938876485},
                                {-0.19680961672624633, -0.21264994423975106, 0.27606305938882342}};
        const double q[3][3] = {{-0.22854345406938401, -0.21270032952265452, 0.27606305938876485},
                                {-0.2126728895191661, -0.21267313359475115, 0.2760630593888001},
                                {-0.21264858374375845, -0.19681061248855206, 0.2760630593888187}};
        expect_pair(p, q, 0, "noisy flat sheet, half a cell apart");
        /* A real crossing at a small angle (1e-4 rad) is still one. */
        const double a[3][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
        const double b[3][3] = {{0.2, 0.2, -1e-4}, {0.8, 0.2, 1e-4}, {0.2, 0.6, -1e-4}};
        expect_pair(a, b, 1, "crossing at 1e-4 rad");
    }
}

/* Random pairs built to cross must be found, the same pairs lifted clear of
 * the plane must not, and swapping the triangles changes nothing. */
static uint64_t rng_state = 0x2545F4914F6CDD1Dull;
static double uniform(double lo, double hi)
{
    rng_state = rng_state * 6364136223846793005ull + 1442695040888963407ull;
    return lo + (hi - lo) * (double)(rng_state >> 11) * (1.0 / 9007199254740992.0);
}

static void test_random_pairs(void)
{
    int wrong = 0;
    for (int i = 0; i < 20000; ++i) {
        double p[3][3], q[3][3];
        /* q straddles p's plane (one vertex below, two above) over a part
         * of the plane that p always covers (x, y in [0.05, 0.15]) */
        for (int k = 0; k < 3; ++k) p[k][2] = 0;
        p[0][0] = uniform(-1, 0), p[0][1] = uniform(-1, 0);
        p[1][0] = uniform(2, 3), p[1][1] = uniform(-1, 0);
        p[2][0] = uniform(-1, 0), p[2][1] = uniform(2, 3);
        double cx = 0.1, cy = 0.1;
        for (int j = 0; j < 3; ++j) {
            q[j][0] = cx + uniform(-0.05, 0.05);
            q[j][1] = cy + uniform(-0.05, 0.05);
            q[j][2] = j == 0 ? uniform(-1, -0.01) : uniform(0.01, 1);
        }
        int crossing = wci_triangles_intersect(p[0], p[1], p[2], q[0], q[1], q[2]);
        /* lifted above the plane entirely */
        double lift = 1.02 - q[0][2];
        double r[3][3];
        for (int j = 0; j < 3; ++j) memcpy(r[j], q[j], sizeof r[j]), r[j][2] += lift;
        int apart = wci_triangles_intersect(p[0], p[1], p[2], r[0], r[1], r[2]);
        if (!crossing || apart) {
            if (wrong++ < 3) CHECK(0, "random pair %d: crossing %d, lifted %d", i, crossing, apart);
        }
        int swapped = wci_triangles_intersect(q[2], q[0], q[1], p[1], p[2], p[0]);
        if (swapped != crossing && wrong++ < 3) CHECK(0, "random pair %d: swapping changed the answer", i);
    }
    CHECK(wrong == 0, "%d random pairs wrong", wrong);
}

/* ---- through the public API ---- */

static wc_world *new_world(void)
{
    wc_world_def def = wc_world_def_default();
    wc_world *w = NULL;
    wc_message msg;
    wc_status s = wc_world_create(&def, &w, &msg);
    CHECK(s == WC_OK && w, "wc_world_create: %s", msg.text);
    return w;
}

static int32_t add_grid(wc_world *w, int32_t nu, int32_t nv, const double center[3], const double axis_u[3],
                        const double axis_v[3])
{
    wc_grid_cloth_def d = wc_grid_cloth_def_default();
    d.count_u = nu, d.count_v = nv;
    for (int k = 0; k < 3; ++k) d.center[k] = center[k], d.axis_u[k] = axis_u[k], d.axis_v[k] = axis_v[k];
    int32_t id = -1;
    wc_status s = wc_world_add_grid_cloth(w, &d, &id);
    CHECK(s == WC_OK, "add grid cloth: %s", wc_world_last_error(w));
    return id;
}

static wc_intersection_counts count(const wc_world *w, const char *what)
{
    wc_intersection_counts c = {-1, -1};
    wc_status s = wc_world_count_intersections(w, &c);
    CHECK(s == WC_OK, "%s: count_intersections: %s", what, wc_world_last_error(w));
    return c;
}

static const double X[3] = {1, 0, 0}, Y[3] = {0, 1, 0}, Z[3] = {0, 0, 1}, O[3] = {0, 0, 0};

static void test_flat_and_folded(void)
{
    wc_world *w = new_world();
    int32_t c = add_grid(w, 11, 11, O, X, Y);
    wc_intersection_counts n = count(w, "flat grid");
    CHECK(n.cloth_cloth == 0 && n.cloth_collider == 0, "flat grid: %d cloth-cloth, %d cloth-collider",
          n.cloth_cloth, n.cloth_collider);

    /* Fold the upper half back over the lower half along y = 0, first
     * down and then up through the lower half near y = -0.25. */
    int32_t np = wc_cloth_particle_count(w, c);
    double *xyz = malloc(3 * (size_t)np * sizeof *xyz);
    CHECK(wc_cloth_get_positions(w, c, xyz, np) == WC_OK, "get positions");
    for (int32_t i = 0; i < np; ++i) {
        double d = xyz[3 * i + 1];
        if (d <= 0) continue;
        xyz[3 * i + 1] = -d;
        xyz[3 * i + 2] = -0.5 * d + 2 * d * d;
    }
    CHECK(wc_cloth_set_positions(w, c, xyz, np) == WC_OK, "set positions: %s", wc_world_last_error(w));
    n = count(w, "folded grid");
    CHECK(n.cloth_cloth > 0, "folded grid passing through itself: %d cloth-cloth", n.cloth_cloth);
    CHECK(n.cloth_collider == 0, "folded grid: %d cloth-collider", n.cloth_collider);

    /* the same fold kept above the lower half: nothing */
    for (int32_t i = 0; i < np; ++i)
        if (xyz[3 * i + 1] < 0 && xyz[3 * i + 2] != 0) {
            double d = -xyz[3 * i + 1];
            xyz[3 * i + 2] = 0.02 + 0.5 * d;
        }
    CHECK(wc_cloth_set_positions(w, c, xyz, np) == WC_OK, "set positions");
    n = count(w, "folded above");
    CHECK(n.cloth_cloth == 0, "fold kept above: %d cloth-cloth", n.cloth_cloth);
    free(xyz);
    wc_world_destroy(w);

    /* a flat sheet in a slanted plane */
    w = new_world();
    double u[3] = {2 / sqrt(5.0), -1 / sqrt(5.0), 0}, nrm[3] = {1 / sqrt(14.0), 2 / sqrt(14.0), 3 / sqrt(14.0)}, v[3];
    v[0] = nrm[1] * u[2] - nrm[2] * u[1], v[1] = nrm[2] * u[0] - nrm[0] * u[2], v[2] = nrm[0] * u[1] - nrm[1] * u[0];
    double center[3] = {0.3, -0.7, 1.1};
    add_grid(w, 40, 30, center, u, v);
    n = count(w, "slanted flat grid");
    CHECK(n.cloth_cloth == 0, "slanted flat grid: %d cloth-cloth", n.cloth_cloth);
    wc_world_destroy(w);
}

static void test_two_cloths(void)
{
    wc_world *w = new_world();
    add_grid(w, 9, 9, O, X, Y);
    double c2[3] = {0.01, 0.013, 0};
    add_grid(w, 8, 8, c2, X, Z); /* vertical, through the first along x */
    wc_intersection_counts n = count(w, "two crossing cloths");
    CHECK(n.cloth_cloth > 0, "two crossing cloths: %d", n.cloth_cloth);
    wc_world_destroy(w);

    /* exact: one quad (two triangles) and a single triangle piercing one of
     * them away from the diagonal */
    w = new_world();
    wc_grid_cloth_def d = wc_grid_cloth_def_default();
    d.count_u = d.count_v = 2;
    int32_t id;
    CHECK(wc_world_add_grid_cloth(w, &d, &id) == WC_OK, "quad cloth");
    double tri[9] = {0.3, -0.3, -0.5, 0.35, -0.3, 0.5, 0.25, -0.2, 0.5};
    int32_t face[3] = {0, 1, 2};
    wc_mesh_cloth_def m = wc_mesh_cloth_def_default();
    m.vertices = tri, m.vertex_count = 3, m.faces = face, m.face_count = 1, m.face_size = 3;
    CHECK(wc_world_add_mesh_cloth(w, &m, &id) == WC_OK, "triangle cloth: %s", wc_world_last_error(w));
    n = count(w, "quad and triangle");
    CHECK(n.cloth_cloth == 1, "quad pierced by a triangle: %d pairs, expected 1", n.cloth_cloth);
    wc_world_destroy(w);

    /* two parallel sheets 1 cm apart: nothing */
    w = new_world();
    add_grid(w, 20, 20, O, X, Y);
    double up[3] = {0.003, 0.004, 0.01};
    add_grid(w, 20, 20, up, X, Y);
    n = count(w, "parallel sheets");
    CHECK(n.cloth_cloth == 0, "parallel sheets: %d", n.cloth_cloth);
    wc_world_destroy(w);
}

static void test_colliders(void)
{
    wc_world *w = new_world();
    wc_grid_cloth_def d = wc_grid_cloth_def_default();
    d.count_u = d.count_v = 2;
    int32_t id;
    CHECK(wc_world_add_grid_cloth(w, &d, &id) == WC_OK, "quad cloth");
    /* a collider triangle through the lower-right cloth triangle */
    double v[9] = {0.3, -0.3, -0.5, 0.35, -0.3, 0.5, 0.25, -0.2, 0.5};
    int32_t t[3] = {0, 1, 2};
    wc_mesh_collider_def m = wc_mesh_collider_def_default();
    m.vertices = v, m.vertex_count = 3, m.triangles = t, m.triangle_count = 1;
    int32_t col;
    CHECK(wc_world_add_mesh_collider(w, &m, &col) == WC_OK, "mesh collider: %s", wc_world_last_error(w));
    wc_intersection_counts n = count(w, "piercing collider");
    CHECK(n.cloth_collider == 1 && n.cloth_cloth == 0, "collider piercing the quad: %d cloth-collider, %d cloth-cloth; expected 1, 0",
          n.cloth_collider, n.cloth_cloth);
    /* moved below the cloth: nothing */
    double below[9];
    for (int i = 0; i < 9; ++i) below[i] = v[i] - (i % 3 == 2 ? 0.6 : 0.0);
    CHECK(wc_collider_set_vertices(w, col, below, 3) == WC_OK, "set vertices");
    n = count(w, "collider target below");
    /* set_vertices moves the target; the current positions still pierce */
    CHECK(n.cloth_collider == 1, "collider still where it was until a step: %d", n.cloth_collider);
    wc_world_destroy(w);

    /* a degenerate collider triangle through the cloth is ignored */
    w = new_world();
    CHECK(wc_world_add_grid_cloth(w, &d, &id) == WC_OK, "quad cloth");
    double flat[9] = {0.3, -0.3, -0.5, 0.3, -0.3, 0.5, 0.3, -0.3, 0.0};
    m.vertices = flat;
    CHECK(wc_world_add_mesh_collider(w, &m, &col) == WC_OK, "flat collider: %s", wc_world_last_error(w));
    n = count(w, "flat collider");
    CHECK(n.cloth_collider == 0, "degenerate collider triangle counted: %d", n.cloth_collider);
    wc_world_destroy(w);

    /* convex: a sphere through the middle of a cloth, then one clear of it */
    w = new_world();
    add_grid(w, 21, 21, O, X, Y);
    wc_convex_collider_def s = wc_convex_collider_def_default();
    s.radius = 0.1;
    s.position[0] = 0.013, s.position[1] = 0.021, s.position[2] = 0.05;
    CHECK(wc_world_add_convex_collider(w, &s, &col) == WC_OK, "sphere: %s", wc_world_last_error(w));
    s.position[2] = 0.2;
    int32_t col2;
    CHECK(wc_world_add_convex_collider(w, &s, &col2) == WC_OK, "sphere 2: %s", wc_world_last_error(w));
    n = count(w, "sphere through the cloth");
    /* the cut circle has radius sqrt(0.1^2 - 0.05^2) = 0.087 m; cells are
     * 0.05 m: a few dozen triangles, all from the first sphere */
    CHECK(n.cloth_collider >= 8 && n.cloth_collider <= 60, "sphere through the cloth: %d triangles", n.cloth_collider);
    wc_world_destroy(w);
}

/* The broadphase must neither miss nor double-count: a crumpled cloth, a
 * second cloth, big and small collider triangles and a sphere, counted by
 * the checker and by testing every pair. */
static void test_against_all_pairs(int with_ground)
{
    wc_world *w = new_world();
    int32_t a = add_grid(w, 14, 12, O, X, Y);
    double c2[3] = {0.1, 0.05, 0.02};
    int32_t b = add_grid(w, 6, 7, c2, X, Z);
    int32_t cloths[2] = {a, b};
    for (int k = 0; k < 2; ++k) {
        int32_t np = wc_cloth_particle_count(w, cloths[k]);
        double *xyz = malloc(3 * (size_t)np * sizeof *xyz);
        wc_cloth_get_positions(w, cloths[k], xyz, np);
        for (int32_t i = 0; i < 3 * np; ++i) xyz[i] += uniform(-0.06, 0.06);
        CHECK(wc_cloth_set_positions(w, cloths[k], xyz, np) == WC_OK, "crumple");
        free(xyz);
    }
    /* two huge triangles (a tilted ground) and a small fan */
    double v[18] = {-5, -5, -0.05, 5, -5, 0.05, 5, 5, 0.02, -5, 5, -0.03, 0.2, 0.2, -0.3, 0.25, 0.2, 0.3};
    if (!with_ground) /* shrink the ground to a small tile: narrow bands */
        for (int i = 0; i < 12; ++i) v[i] *= 0.02;
    int32_t t[9] = {0, 1, 2, 0, 2, 3, 4, 5, 2};
    wc_mesh_collider_def m = wc_mesh_collider_def_default();
    m.vertices = v, m.vertex_count = 6, m.triangles = t, m.triangle_count = 3;
    int32_t col;
    CHECK(wc_world_add_mesh_collider(w, &m, &col) == WC_OK, "collider: %s", wc_world_last_error(w));
    wc_convex_collider_def sd = wc_convex_collider_def_default();
    sd.shape = WC_SHAPE_BOX;
    sd.half_extents[0] = 0.1, sd.half_extents[1] = 0.05, sd.half_extents[2] = 0.08;
    sd.position[0] = -0.2, sd.position[1] = 0.1;
    sd.rotation[0] = 0.9, sd.rotation[1] = 0.3, sd.rotation[3] = 0.2;
    CHECK(wc_world_add_convex_collider(w, &sd, &col) == WC_OK, "box: %s", wc_world_last_error(w));
    wc_convex_shape box;
    wc_pose pose;
    wc_message msg;
    CHECK(wci_convex_shape_create(&box, &pose, &sd, &msg) == WC_OK, "box shape: %s", msg.text);

    int32_t nt[2], np[2], *tri[2];
    double *pos[2];
    for (int k = 0; k < 2; ++k) {
        nt[k] = wc_cloth_triangle_count(w, cloths[k]);
        np[k] = wc_cloth_particle_count(w, cloths[k]);
        tri[k] = malloc(3 * (size_t)nt[k] * sizeof *tri[k]);
        pos[k] = malloc(3 * (size_t)np[k] * sizeof *pos[k]);
        wc_cloth_get_triangles(w, cloths[k], tri[k], nt[k]);
        wc_cloth_get_positions(w, cloths[k], pos[k], np[k]);
    }
    int cc = 0, cl = 0;
    for (int k = 0; k < 2; ++k)
        for (int32_t i = 0; i < nt[k]; ++i) {
            const int32_t *ti = tri[k] + 3 * i;
            const double *p0 = pos[k] + 3 * ti[0], *p1 = pos[k] + 3 * ti[1], *p2 = pos[k] + 3 * ti[2];
            for (int l = k; l < 2; ++l)
                for (int32_t j = l == k ? i + 1 : 0; j < nt[l]; ++j) {
                    const int32_t *tj = tri[l] + 3 * j;
                    int share = 0;
                    for (int x = 0; x < 3 && l == k; ++x)
                        for (int y = 0; y < 3; ++y) share |= ti[x] == tj[y];
                    if (share) continue;
                    cc += wci_triangles_intersect(p0, p1, p2, pos[l] + 3 * tj[0], pos[l] + 3 * tj[1],
                                                 pos[l] + 3 * tj[2]);
                }
            for (int u = 0; u < 3; ++u)
                cl += wci_triangles_intersect(p0, p1, p2, v + 3 * t[3 * u], v + 3 * t[3 * u + 1], v + 3 * t[3 * u + 2]);
            cl += wci_convex_triangle_intersects(&box, &pose, p0, p1, p2);
        }
    wc_intersection_counts n = count(w, "crumpled scene");
    CHECK(n.cloth_cloth == cc && n.cloth_collider == cl,
          "crumpled scene: checker %d cloth-cloth, %d cloth-collider; all pairs %d, %d", n.cloth_cloth,
          n.cloth_collider, cc, cl);
    CHECK(cc > 10 && cl > 10, "crumpled scene too tame: %d, %d", cc, cl);
    printf("crumpled scene%s: %d cloth-cloth and %d cloth-collider pairs, as testing all pairs finds\n",
           with_ground ? " with a ground" : "", cc, cl);
    for (int k = 0; k < 2; ++k) free(tri[k]), free(pos[k]);
    wci_convex_shape_destroy(&box);
    wc_world_destroy(w);
}

static void test_errors(void)
{
    wc_intersection_counts c;
    CHECK(wc_world_count_intersections(NULL, &c) == WC_ERROR_INVALID_ARGUMENT, "NULL world");
    wc_world *w = new_world();
    CHECK(wc_world_count_intersections(w, NULL) == WC_ERROR_INVALID_ARGUMENT, "NULL out");
    CHECK(strstr(wc_world_last_error(w), "out_counts") != NULL, "message: %s", wc_world_last_error(w));
    /* an empty world has nothing */
    c = count(w, "empty world");
    CHECK(c.cloth_cloth == 0 && c.cloth_collider == 0, "empty world: %d %d", c.cloth_cloth, c.cloth_collider);
    wc_world_destroy(w);
}

static double seconds(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Large flat and crumpled-looking cloths: correct counts, and fast enough to
 * run every frame of a test (timings printed for the record). */
static void test_speed(void)
{
    for (int size = 64; size <= 128; size *= 2) {
        wc_world *w = new_world();
        int32_t c = add_grid(w, size, size, O, X, Y);
        double t0 = seconds();
        wc_intersection_counts n = count(w, "big flat grid");
        double t1 = seconds();
        CHECK(n.cloth_cloth == 0, "%d x %d flat: %d", size, size, n.cloth_cloth);
        /* a wavy sheet, still free of intersections */
        int32_t np = wc_cloth_particle_count(w, c);
        double *xyz = malloc(3 * (size_t)np * sizeof *xyz);
        CHECK(wc_cloth_get_positions(w, c, xyz, np) == WC_OK, "get positions");
        for (int32_t i = 0; i < np; ++i)
            xyz[3 * i + 2] = 0.05 * sin(12 * xyz[3 * i]) * cos(9 * xyz[3 * i + 1]);
        CHECK(wc_cloth_set_positions(w, c, xyz, np) == WC_OK, "set positions");
        double t2 = seconds();
        n = count(w, "wavy grid");
        double t3 = seconds();
        CHECK(n.cloth_cloth == 0, "%d x %d wavy: %d", size, size, n.cloth_cloth);
        printf("count_intersections, %d x %d cloth: flat %.1f ms, wavy %.1f ms\n", size, size,
               1e3 * (t1 - t0), 1e3 * (t3 - t2));
        CHECK(t3 - t2 < 1.0, "%d x %d: %.3f s", size, size, t3 - t2);
        free(xyz);
        wc_world_destroy(w);
    }
}

/* Points a = (0.5 + i u, 0.5 + j u), u = 2^-53, against the line through
 * b = (12, 12) and c = (24, 24): det[b - a, c - a] = 12 (a_y - a_x) =
 * 12 (j - i) u exactly, so the sign is that of j - i. In floating point the
 * determinant is mostly rounding error here (Shewchuk's example), so this
 * tests the exact path. orient3d gets the same points in the plane z = 0
 * and d = (0, 0, 1): the same sign. */
static void test_exact_orientation(void)
{
    const double u = 1.1102230246251565e-16;
    int wrong2 = 0, wrong3 = 0;
    for (int i = 0; i < 64; ++i)
        for (int j = 0; j < 64; ++j) {
            double a2[2] = {0.5 + i * u, 0.5 + j * u}, b2[2] = {12, 12}, c2[2] = {24, 24};
            double a3[3] = {a2[0], a2[1], 0}, b3[3] = {12, 12, 0}, c3[3] = {24, 24, 0},
                   d3[3] = {0, 0, 1};
            int expect = (j > i) - (j < i);
            wrong2 += wci_orient2d(a2, b2, c2) != expect;
            wrong3 += wci_orient3d(a3, b3, c3, d3) != expect;
        }
    /* Long differences: b - a = d has about 50 significant bits (a multiple
     * of 2^-52 in [1/4, 1/2)), c = a + 2 d exactly, moved by s ulps in y:
     * det = d_x s 2^-52, sign s, as small as the rounding error of the
     * floating-point determinant, so many of these go the exact way. */
    uint64_t seed = 12345;
    for (int k = 0; k < 3000; ++k) {
        double dx, dy;
        seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
        dx = 0x1p-2 * (1.0 + (double)(seed >> 11) * 0x1p-53);
        seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
        dy = 0x1p-2 * (1.0 + (double)(seed >> 11) * 0x1p-53);
        int sgn = k % 3 - 1;
        double a2[2] = {1.0, 1.0}, b2[2] = {1.0 + dx, 1.0 + dy};
        double c2[2] = {1.0 + 2.0 * (b2[0] - 1.0), 1.0 + 2.0 * (b2[1] - 1.0) + sgn * 0x1p-52};
        double a3[3] = {a2[0], a2[1], 0}, b3[3] = {b2[0], b2[1], 0}, c3[3] = {c2[0], c2[1], 0},
               d3[3] = {0, 0, 1};
        wrong2 += wci_orient2d(a2, b2, c2) != sgn;
        wrong3 += wci_orient3d(a3, b3, c3, d3) != sgn;
    }
    printf("exact orientation, 4096 near-collinear points and 3000 with long differences: "
           "orient2d %d wrong, orient3d %d wrong\n", wrong2, wrong3);
    CHECK(wrong2 == 0 && wrong3 == 0, "orientation signs wrong: %d (2D), %d (3D)", wrong2, wrong3);
}

int main(void)
{
    test_exact_orientation();
    test_triangle_pairs();
    test_random_pairs();
    test_flat_and_folded();
    test_two_cloths();
    test_colliders();
    for (int i = 0; i < 3; ++i) test_against_all_pairs(i == 0);
    test_errors();
    test_speed();
    return test_report("test_checker");
}
