/* Cloth topology (docs/model.md, Particles and links) and the material mapping (wetcloth.h,
 * wc_material): link sets computed independently from grid coordinates or
 * by hand for small meshes, rest lengths, particle areas and masses, per-link
 * K and R, surface triangles, and the tension-only stretch force. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cloth.h"
#include "forces.h"
#include "test_util.h"
#include "wetcloth.h"
#include "world.h"

/* Positions are computed by the library as center + (i/(n-1) - 0.5) size axis;
 * the test recomputes them the same way in double, so lengths agree to a few
 * rounding errors of the coordinates: 1e-14 relative is ample and still
 * catches any wrong pairing (lengths differ by factors >= sqrt(2)). */
#define LENGTH_TOL 1e-14

static wc_world *new_world(void)
{
    wc_world_def def = wc_world_def_default();
    def.thread_count = 1;
    wc_world *w = NULL;
    wc_message msg;
    wc_status s = wc_world_create(&def, &w, &msg);
    CHECK(s == WC_OK && w, "wc_world_create: %s", msg.text);
    return w;
}

static int compare_pairs(const void *a, const void *b)
{
    const int32_t *p = a, *q = b;
    if (p[0] != q[0]) return p[0] < q[0] ? -1 : 1;
    return (p[1] > q[1]) - (p[1] < q[1]);
}

/* Expected link pairs of a grid: particle (i, j) to (i + s di, j + s dj) for
 * the 8 directions, s = 1 (stretch) or 2 (bend), each pair once, sorted. */
static int32_t grid_pairs(int32_t nu, int32_t nv, int step, int32_t *out)
{
    static const int dirs[8][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1},
                                   {1, 1}, {-1, -1}, {1, -1}, {-1, 1}};
    int32_t count = 0;
    for (int32_t j = 0; j < nv; ++j)
        for (int32_t i = 0; i < nu; ++i)
            for (int d = 0; d < 8; ++d) {
                int32_t i2 = i + step * dirs[d][0], j2 = j + step * dirs[d][1];
                if (i2 < 0 || i2 >= nu || j2 < 0 || j2 >= nv) continue;
                int32_t a = j * nu + i, b = j2 * nu + i2;
                if (a < b) { /* each unordered pair seen twice: keep one */
                    out[2 * count] = a;
                    out[2 * count + 1] = b;
                    ++count;
                }
            }
    qsort(out, (size_t)count, 2 * sizeof *out, compare_pairs);
    return count;
}

/* Compares the links of a kind with an expected sorted pair list; rest
 * lengths against `xyz`. */
static void check_links(const wc_world *w, int32_t cloth, wc_link_kind kind, const int32_t *expect,
                        int32_t expect_count, const double *xyz, const char *what)
{
    int32_t n = wc_cloth_link_count(w, cloth, kind);
    CHECK(n == expect_count, "%s: %d links, expected %d", what, n, expect_count);
    int32_t cap = n > expect_count ? n : expect_count;
    int32_t *pairs = calloc(2 * (size_t)cap + 2, sizeof *pairs);
    double *rest = calloc((size_t)cap + 1, sizeof *rest);
    wc_status s = wc_cloth_get_links(w, cloth, kind, pairs, rest, cap);
    CHECK(s == WC_OK, "%s: get_links: %s", what, wc_world_last_error(w));
    int mismatches = 0;
    for (int32_t e = 0; e < n && e < expect_count; ++e) {
        if (pairs[2 * e] != expect[2 * e] || pairs[2 * e + 1] != expect[2 * e + 1]) {
            if (mismatches++ < 5)
                CHECK(0, "%s: link %d is (%d, %d), expected (%d, %d)", what, e, pairs[2 * e],
                      pairs[2 * e + 1], expect[2 * e], expect[2 * e + 1]);
            continue;
        }
        const double *p = xyz + 3 * (size_t)pairs[2 * e], *q = xyz + 3 * (size_t)pairs[2 * e + 1];
        double l = sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) +
                        (p[2] - q[2]) * (p[2] - q[2]));
        CHECK(fabs(rest[e] - l) <= LENGTH_TOL * l, "%s: link (%d, %d) rest %.17g, expected %.17g",
              what, pairs[2 * e], pairs[2 * e + 1], rest[e], l);
    }
    /* sorted, lower index first, no duplicates */
    for (int32_t e = 0; e < n; ++e) {
        CHECK(pairs[2 * e] < pairs[2 * e + 1], "%s: link %d not lower-first", what, e);
        if (e) CHECK(compare_pairs(pairs + 2 * (e - 1), pairs + 2 * e) < 0, "%s: not sorted at %d", what, e);
    }
    /* a capacity one short is refused */
    if (n > 0)
        CHECK(wc_cloth_get_links(w, cloth, kind, pairs, rest, n - 1) == WC_ERROR_INVALID_ARGUMENT,
              "%s: capacity n-1 accepted", what);
    free(pairs);
    free(rest);
}

/* ------------------------------------------------------------------------ */
/* Grids                                                                     */
/* ------------------------------------------------------------------------ */

static void test_grid(int32_t nu, int32_t nv, double size_u, double size_v, int rotated)
{
    char what[96];
    wc_world *w = new_world();
    wc_grid_cloth_def def = wc_grid_cloth_def_default();
    def.count_u = nu;
    def.count_v = nv;
    def.size_u = size_u;
    def.size_v = size_v;
    def.center[0] = 0.3, def.center[1] = -1.2, def.center[2] = 2.0;
    def.material.density = 0.37;
    def.material.stretch_stiffness = 123.0;
    def.material.bend_stiffness = 4e-4;
    if (rotated) { /* u tilted out of the xy plane; v = y stays perpendicular */
        def.axis_u[0] = cos(0.3), def.axis_u[1] = 0.0, def.axis_u[2] = sin(0.3);
    }
    int32_t id = -1;
    wc_status st = wc_world_add_grid_cloth(w, &def, &id);
    CHECK(st == WC_OK, "add grid: %s", wc_world_last_error(w));
    int32_t n = nu * nv;
    CHECK(wc_cloth_particle_count(w, id) == n, "particle count %d", wc_cloth_particle_count(w, id));

    /* Rest positions from (i, j), as the header documents them. */
    double *xyz = malloc(3 * (size_t)n * sizeof *xyz);
    for (int32_t j = 0; j < nv; ++j)
        for (int32_t i = 0; i < nu; ++i) {
            double u = ((double)i / (nu - 1) - 0.5) * size_u;
            double v = ((double)j / (nv - 1) - 0.5) * size_v;
            for (int k = 0; k < 3; ++k)
                xyz[3 * ((size_t)j * nu + i) + k] = def.center[k] + u * def.axis_u[k] + v * def.axis_v[k];
        }
    double *pos = malloc(3 * (size_t)n * sizeof *pos);
    CHECK(wc_cloth_get_positions(w, id, pos, n) == WC_OK, "get_positions");
    double worst = 0.0;
    for (int32_t k = 0; k < 3 * n; ++k) worst = fmax(worst, fabs(pos[k] - xyz[k]));
    CHECK(worst <= 1e-14 * (2.0 + size_u + size_v), "rest positions off by %g", worst);

    int32_t *expect = malloc(8 * (size_t)n * sizeof *expect);
    int32_t m = grid_pairs(nu, nv, 1, expect);
    /* closed form: (nu-1) nv + nu (nv-1) axis links + 2 (nu-1)(nv-1) diagonals */
    CHECK(m == (nu - 1) * nv + nu * (nv - 1) + 2 * (nu - 1) * (nv - 1), "stretch count formula");
    snprintf(what, sizeof what, "%dx%d grid (%gx%g) stretch", nu, nv, size_u, size_v);
    check_links(w, id, WC_LINK_STRETCH, expect, m, xyz, what);
    int32_t mb = grid_pairs(nu, nv, 2, expect);
    snprintf(what, sizeof what, "%dx%d grid (%gx%g) bend", nu, nv, size_u, size_v);
    check_links(w, id, WC_LINK_BEND, expect, mb, xyz, what);
    printf("%dx%d grid %gx%g: %d stretch, %d bend links (expected %d, %d)\n", nu, nv, size_u, size_v,
           wc_cloth_link_count(w, id, WC_LINK_STRETCH), wc_cloth_link_count(w, id, WC_LINK_BEND), m,
           mb);

    /* Areas and masses: a cell is hu x hv; a particle gets a quarter of each
     * of its (1, 2 or 4) cells. */
    double hu = size_u / (nu - 1), hv = size_v / (nv - 1);
    wc_cloth_view view;
    CHECK(wc_cloth_get_view(w, id, &view) == WC_OK, "get_view");
    double total = 0.0;
    double *area = malloc((size_t)n * sizeof *area);
    for (int32_t j = 0; j < nv; ++j)
        for (int32_t i = 0; i < nu; ++i) {
            int cu = (i > 0) + (i < nu - 1), cv = (j > 0) + (j < nv - 1);
            double a = 0.25 * cu * cv * hu * hv;
            area[j * nu + i] = a;
            double mass = view.mass[j * nu + i];
            total += mass;
            CHECK(fabs(mass - def.material.density * a) <= 1e-14 * def.material.density * a,
                  "mass of (%d,%d) = %.17g, expected %.17g", i, j, mass, def.material.density * a);
        }
    CHECK(fabs(total - def.material.density * size_u * size_v) <= 1e-13 * total,
          "total mass %.17g, expected density * area = %.17g", total,
          def.material.density * size_u * size_v);

    /* Per-link constants from the documented mapping (wetcloth.h):
     * K = 12/5 * S * A_e / l^2, A_e = sum over the link's quads of area/6;
     * R = B * (A_a/n_a + A_c/n_c) / l. Recomputed from (i, j). */
    const wc_cloth *c = w->cloths[id];
    const wc_topology *t = &c->topology;
    for (int32_t e = 0; e < t->stretch.count; ++e) {
        int32_t a = t->stretch.a[e], b = t->stretch.b[e];
        int32_t ia = a % nu, ja = a / nu, ib = b % nu, jb = b / nu;
        int quads;
        if (ja == jb) /* horizontal edge: quads above and below */
            quads = (ja > 0) + (ja < nv - 1);
        else if (ia == ib) /* vertical edge */
            quads = (ia > 0) + (ia < nu - 1);
        else /* diagonal: one quad */
            quads = 1;
        double l = t->stretch.rest[e];
        double k = 12.0 / 5.0 * def.material.stretch_stiffness * quads * hu * hv / 6.0 / (l * l);
        CHECK(fabs(c->stretch_k[e] - k) <= 1e-13 * k, "K of (%d,%d) = %.17g, expected %.17g", a, b,
              c->stretch_k[e], k);
    }
    int32_t *degree = calloc((size_t)n, sizeof *degree);
    for (int32_t e = 0; e < t->bend.count; ++e) degree[t->bend.a[e]]++, degree[t->bend.b[e]]++;
    for (int32_t e = 0; e < t->bend.count; ++e) {
        int32_t a = t->bend.a[e], b = t->bend.b[e];
        double r = def.material.bend_stiffness * (area[a] / degree[a] + area[b] / degree[b]) /
                   t->bend.rest[e];
        CHECK(fabs(c->bend_r[e] - r) <= 1e-13 * r, "R of (%d,%d) = %.17g, expected %.17g", a, b,
              c->bend_r[e], r);
    }

    /* Surface triangles: two per quad, each a 3-particle face of a cell. */
    int32_t tc = wc_cloth_triangle_count(w, id);
    CHECK(tc == 2 * (nu - 1) * (nv - 1), "triangle count %d", tc);
    int32_t *tri = malloc(3 * (size_t)tc * sizeof *tri);
    CHECK(wc_cloth_get_triangles(w, id, tri, tc) == WC_OK, "get_triangles");
    double tri_area = 0.0;
    for (int32_t k = 0; k < tc; ++k) {
        const double *p = xyz + 3 * (size_t)tri[3 * k], *q = xyz + 3 * (size_t)tri[3 * k + 1],
                     *r = xyz + 3 * (size_t)tri[3 * k + 2];
        double u[3], v[3], cr[3];
        for (int d = 0; d < 3; ++d) u[d] = q[d] - p[d], v[d] = r[d] - p[d];
        cr[0] = u[1] * v[2] - u[2] * v[1];
        cr[1] = u[2] * v[0] - u[0] * v[2];
        cr[2] = u[0] * v[1] - u[1] * v[0];
        tri_area += 0.5 * sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]);
    }
    CHECK(fabs(tri_area - size_u * size_v) <= 1e-12 * size_u * size_v,
          "triangles cover %.17g m^2, expected %.17g", tri_area, size_u * size_v);

    free(tri);
    free(degree);
    free(area);
    free(expect);
    free(pos);
    free(xyz);
    wc_world_destroy(w);
}

/* ------------------------------------------------------------------------ */
/* Meshes                                                                    */
/* ------------------------------------------------------------------------ */

static void check_masses(const wc_world *w, int32_t id, const double *area, int32_t n, double density,
                         const char *what)
{
    wc_cloth_view view;
    CHECK(wc_cloth_get_view(w, id, &view) == WC_OK, "%s: get_view", what);
    CHECK(view.particle_count == n, "%s: view count %d", what, view.particle_count);
    double total = 0.0, expect_total = 0.0;
    for (int32_t i = 0; i < n; ++i) {
        total += view.mass[i];
        expect_total += density * area[i];
        CHECK(fabs(view.mass[i] - density * area[i]) <= 1e-14 * density * area[i],
              "%s: mass %d = %.17g, expected %.17g", what, i, view.mass[i], density * area[i]);
    }
    CHECK(fabs(total - expect_total) <= 1e-14 * expect_total, "%s: total mass %.17g vs %.17g", what,
          total, expect_total);
}

/* A regular hexagon around a centre: 7 vertices, 6 triangles. Stretch links:
 * 6 spokes + 6 rim edges; bend links: only through the centre between
 * opposite rim vertices (180 degrees); at a rim vertex the straightest pair
 * is 120 degrees. */
static void test_hexagon(void)
{
    double xyz[21] = {0.0, 0.0, 0.0};
    const double s = 0.4, pi = 3.14159265358979323846;
    for (int k = 0; k < 6; ++k) {
        xyz[3 * (k + 1)] = s * cos(pi / 3.0 * k);
        xyz[3 * (k + 1) + 1] = s * sin(pi / 3.0 * k);
        xyz[3 * (k + 1) + 2] = 0.1;
    }
    xyz[2] = 0.1;
    int32_t faces[18];
    for (int k = 0; k < 6; ++k) faces[3 * k] = 0, faces[3 * k + 1] = 1 + k, faces[3 * k + 2] = 1 + (k + 1) % 6;
    wc_world *w = new_world();
    wc_mesh_cloth_def def = wc_mesh_cloth_def_default();
    def.vertices = xyz;
    def.vertex_count = 7;
    def.faces = faces;
    def.face_count = 6;
    def.face_size = 3;
    def.material.density = 0.2;
    int32_t id = -1;
    CHECK(wc_world_add_mesh_cloth(w, &def, &id) == WC_OK, "hexagon: %s", wc_world_last_error(w));

    int32_t stretch[24], m = 0;
    for (int k = 1; k <= 6; ++k) stretch[2 * m] = 0, stretch[2 * m + 1] = k, ++m;
    for (int k = 1; k <= 6; ++k) {
        int32_t a = k, b = k % 6 + 1;
        stretch[2 * m] = a < b ? a : b, stretch[2 * m + 1] = a < b ? b : a, ++m;
    }
    qsort(stretch, (size_t)m, 2 * sizeof *stretch, compare_pairs);
    check_links(w, id, WC_LINK_STRETCH, stretch, m, xyz, "hexagon stretch");
    int32_t bend[6] = {1, 4, 2, 5, 3, 6};
    check_links(w, id, WC_LINK_BEND, bend, 3, xyz, "hexagon bend");

    double tri = sqrt(3.0) / 4.0 * s * s, area[7];
    area[0] = 6.0 * tri / 3.0;
    for (int k = 1; k <= 6; ++k) area[k] = 2.0 * tri / 3.0;
    check_masses(w, id, area, 7, def.material.density, "hexagon");
    CHECK(wc_cloth_triangle_count(w, id) == 6, "hexagon triangles %d", wc_cloth_triangle_count(w, id));

    /* K = 8/3 S A_e / l^2 with A_e = sum over faces of area/3: spokes have
     * two triangles, rim edges one. */
    const wc_cloth *c = w->cloths[id];
    for (int32_t e = 0; e < c->topology.stretch.count; ++e) {
        int faces_of = c->topology.stretch.a[e] == 0 ? 2 : 1;
        double l = c->topology.stretch.rest[e];
        double k = 8.0 / 3.0 * def.material.stretch_stiffness * faces_of * tri / 3.0 / (l * l);
        CHECK(fabs(c->stretch_k[e] - k) <= 1e-13 * k, "hexagon K[%d] = %.17g, expected %.17g", e,
              c->stretch_k[e], k);
    }
    wc_world_destroy(w);
}

/* Mixed faces with face_size 4: a unit quad (0,1,4,3) and two triangles
 * (1,2,5,-1), (1,5,4,-1) on the 3 x 2 lattice
 *     3 --- 4 --- 5
 *     |  q  | t2 /|
 *     |     |  /  |       (triangle t1 = 1,2,5 under the diagonal 1-5)
 *     0 --- 1 --- 2
 * Stretch: quad edges 01 14 34 03 and diagonals 04 13; triangle edges 12 25
 * 15 45 (14 shared) -> 10 links. Bend: 0-1-2 and 3-4-5 are straight (180
 * degrees); every other angle is <= 135 degrees -> (0,2), (3,5).
 * Areas: quad 1 (a quarter to each corner), triangles 1/2 (a third each). */
static void test_mixed_mesh(void)
{
    const double h = 0.25; /* lattice spacing, m */
    double xyz[18];
    for (int k = 0; k < 6; ++k) {
        xyz[3 * k] = h * (k % 3);
        xyz[3 * k + 1] = h * (k / 3);
        xyz[3 * k + 2] = -0.5;
    }
    int32_t faces[12] = {0, 1, 4, 3, 1, 2, 5, -1, 1, 5, 4, -1};
    wc_world *w = new_world();
    wc_mesh_cloth_def def = wc_mesh_cloth_def_default();
    def.vertices = xyz;
    def.vertex_count = 6;
    def.faces = faces;
    def.face_count = 3;
    def.face_size = 4;
    def.material.density = 0.5;
    int32_t id = -1;
    CHECK(wc_world_add_mesh_cloth(w, &def, &id) == WC_OK, "mixed: %s", wc_world_last_error(w));
    int32_t stretch[20] = {0, 1, 0, 3, 0, 4, 1, 2, 1, 3, 1, 4, 1, 5, 2, 5, 3, 4, 4, 5};
    check_links(w, id, WC_LINK_STRETCH, stretch, 10, xyz, "mixed stretch");
    int32_t bend[4] = {0, 2, 3, 5};
    check_links(w, id, WC_LINK_BEND, bend, 2, xyz, "mixed bend");
    double q = h * h / 4.0, t = h * h / 2.0 / 3.0;
    double area[6] = {q, q + 2 * t, t, q, q + t, 2 * t};
    check_masses(w, id, area, 6, def.material.density, "mixed");
    double sum = 0.0;
    for (int k = 0; k < 6; ++k) sum += area[k];
    CHECK(fabs(sum - 2.0 * h * h) < 1e-15, "hand areas sum %.17g", sum);
    CHECK(wc_cloth_triangle_count(w, id) == 4, "mixed triangles %d", wc_cloth_triangle_count(w, id));

    /* Link constants: the quad shares 12/5 * 1/6 of its area with each of
     * its 6 links; a triangle 8/3 * 1/3 of its area with each of its 3.
     * Link 1-4 belongs to the quad and triangle t2. */
    const wc_cloth *c = w->cloths[id];
    const wc_topology *tp = &c->topology;
    double S = def.material.stretch_stiffness, qa = h * h, ta = h * h / 2.0;
    for (int32_t e = 0; e < tp->stretch.count; ++e) {
        int32_t a = tp->stretch.a[e], b = tp->stretch.b[e];
        /* quad links: 01 03 04 13 14 34 */
        int in_quad = (a == 0 && (b == 1 || b == 3 || b == 4)) || (a == 1 && (b == 3 || b == 4)) ||
                  (a == 3 && b == 4);
        int tris = (a == 1 && (b == 2 || b == 5 || b == 4)) + (a == 2 && b == 5) +
                   (a == 4 && b == 5) + (a == 1 && b == 5);
        double share = in_quad * 12.0 / 5.0 * qa / 6.0 + tris * 8.0 / 3.0 * ta / 3.0;
        double l = tp->stretch.rest[e];
        double k = S * share / (l * l);
        CHECK(fabs(c->stretch_k[e] - k) <= 1e-13 * k, "mixed K(%d,%d) = %.17g, expected %.17g", a, b,
              c->stretch_k[e], k);
    }
    wc_world_destroy(w);
}

/* ------------------------------------------------------------------------ */
/* Stretch is tension only                                                   */
/* ------------------------------------------------------------------------ */

/* Right triangle 0=(0,0,0), 1=(1,0,0), 2=(0,1,0): no bend links (largest
 * angle 90 degrees). Deformed so that link 0-1 is compressed and 0-2, 1-2
 * stretched: particle 0 must feel only link 0-2, so its force is parallel to
 * x2 - x0 = (0, 1.2, 0.3) and its x component is exactly zero; particle 1
 * only link 1-2. Forces are compared with -K (d - l) u computed here. */
static void test_tension_only(void)
{
    double xyz[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    int32_t faces[3] = {0, 1, 2};
    wc_world_def wd = wc_world_def_default();
    wd.gravity[0] = wd.gravity[1] = wd.gravity[2] = 0.0;
    wd.thread_count = 1;
    wc_world *w = NULL;
    CHECK(wc_world_create(&wd, &w, NULL) == WC_OK, "world");
    wc_mesh_cloth_def def = wc_mesh_cloth_def_default();
    def.vertices = xyz;
    def.vertex_count = 3;
    def.faces = faces;
    def.face_count = 1;
    def.material.stretch_damping = 0.0;
    def.material.air_drag = 0.0;
    int32_t id = -1;
    CHECK(wc_world_add_mesh_cloth(w, &def, &id) == WC_OK, "triangle: %s", wc_world_last_error(w));
    CHECK(wc_cloth_link_count(w, id, WC_LINK_BEND) == 0, "right triangle has bend links");
    wc_cloth *c = w->cloths[id];
    const double g0[3] = {0.0, 0.0, 0.0};

    /* At rest, and uniformly compressed to half size: no force at all. */
    wci_forces_compute(c, g0, 1);
    for (int i = 0; i < 3; ++i)
        CHECK(c->fx[i] == 0.0 && c->fy[i] == 0.0 && c->fz[i] == 0.0, "rest force on %d", i);
    double half[9];
    for (int k = 0; k < 9; ++k) half[k] = 0.5 * xyz[k] + 0.1;
    CHECK(wc_cloth_set_positions(w, id, half, 3) == WC_OK, "set_positions");
    wci_forces_compute(c, g0, 1);
    for (int i = 0; i < 3; ++i)
        CHECK(c->fx[i] == 0.0 && c->fy[i] == 0.0 && c->fz[i] == 0.0,
              "compressed triangle: force on %d = (%g, %g, %g)", i, c->fx[i], c->fy[i], c->fz[i]);

    /* One link compressed, two stretched. */
    double def_xyz[9] = {0, 0, 0, 0.9, 0, 0, 0, 1.2, 0.3};
    CHECK(wc_cloth_set_positions(w, id, def_xyz, 3) == WC_OK, "set_positions");
    wci_forces_compute(c, g0, 1);
    double expect[9] = {0};
    const wc_link_set *ls = &c->topology.stretch;
    for (int32_t e = 0; e < ls->count; ++e) {
        int32_t a = ls->a[e], b = ls->b[e];
        double D[3], d = 0.0;
        for (int k = 0; k < 3; ++k) D[k] = def_xyz[3 * a + k] - def_xyz[3 * b + k], d += D[k] * D[k];
        d = sqrt(d);
        if (d <= ls->rest[e]) continue;
        for (int k = 0; k < 3; ++k) {
            double f = -c->stretch_k[e] * (d - ls->rest[e]) * D[k] / d;
            expect[3 * a + k] += f;
            expect[3 * b + k] -= f;
        }
    }
    double got[9] = {c->fx[0], c->fy[0], c->fz[0], c->fx[1], c->fy[1], c->fz[1],
                     c->fx[2], c->fy[2], c->fz[2]};
    double scale = 0.0;
    for (int k = 0; k < 9; ++k) scale = fmax(scale, fabs(expect[k]));
    for (int k = 0; k < 9; ++k)
        CHECK(fabs(got[k] - expect[k]) <= 1e-14 * scale, "force[%d] = %.17g, expected %.17g", k,
              got[k], expect[k]);
    CHECK(c->fx[0] == 0.0, "particle 0 feels the compressed link: fx = %g", c->fx[0]);
    /* particle 1's force is along x2 - x1 = (-0.9, 1.2, 0.3): cross product zero */
    double cx = c->fy[1] * 0.3 - c->fz[1] * 1.2, cz = c->fx[1] * 1.2 - c->fy[1] * (-0.9);
    CHECK(fabs(cx) <= 1e-14 * scale && fabs(cz) <= 1e-14 * scale,
          "particle 1's force not along link 1-2 (%g, %g)", cx, cz);
    CHECK(c->fy[0] > 0.0, "particle 0 not pulled toward particle 2");
    printf("tension only: F0 = (%g, %g, %g), F1 = (%g, %g, %g)\n", c->fx[0], c->fy[0], c->fz[0],
           c->fx[1], c->fy[1], c->fz[1]);
    wc_world_destroy(w);
}

/* On a grid the bend links are the skip-one set. With cells of
 * aspect ratio above sqrt(3), the 150-degree rule also links an axis
 * neighbour to the opposite diagonal neighbour (angle atan(hu/hv) + 90 >
 * 150 degrees), so this case checks that the grid keeps the thesis' set. */
static void test_anisotropic_grid(void)
{
    test_grid(7, 4, 3.0, 0.5, 0); /* cells 0.5 x 0.1667: aspect 3 */
}

int main(void)
{
    test_grid(5, 4, 1.0, 1.0, 0);
    test_grid(7, 7, 1.0, 1.0, 0);
    test_grid(6, 9, 1.3, 1.7, 1);
    test_grid(2, 2, 0.5, 0.5, 0);
    test_grid(32, 17, 2.0, 1.0, 0);
    test_hexagon();
    test_mixed_mesh();
    test_tension_only();
    test_anisotropic_grid();
    return test_report("test_topology");
}
