/* Support planes (support.h) and the particle pass that uses them.
 *
 * - Coulomb friction on a slope against its closed form, the same on a
 *   ground of 2 triangles and of 8,192.
 * - Every triangle's reach on both sides of its plane equals a brute-force
 *   search over every vertex of the collider, on a UV sphere (convex: every
 *   front reach is the cap) and on a ground with a bump and a groove (some
 *   front reaches are short), and the reaches are for the shape they were
 *   measured on: a collider that moved and came to rest has them measured
 *   again.
 * - wci_support_holds against brute force: of random particle paths near
 *   those colliders' triangles, every one it says is held ends no nearer to
 *   any triangle than the face test counts as a touch and meets none (exact
 *   orientation tests); and it does hold most of those above a sphere.
 * - The contact stage: a cloth dropped on a 3,968-triangle sphere and one
 *   dropped into the groove, with supports and without (the test switch):
 *   at the end of every frame every particle is at least the contact
 *   distance from the collider (brute force over its triangles) and no
 *   cloth triangle meets it; with supports the particle pass runs a
 *   fraction of the face tests, and the drape stays within 1 % of the
 *   cloth's width of the one without (the default setting's own error). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cloth.h"
#include "collider.h"
#include "collider_contacts.h"
#include "narrowphase.h"
#include "predicates.h"
#include "primitives.h"
#include "scenes.h"
#include "step_guard.h"
#include "support.h"
#include "test_util.h"
#include "vec3.h"
#include "wetcloth.h"
#include "world.h"

#define THICKNESS 0.02
#define GROUND_N 24

typedef struct mesh {
    double *v;
    int32_t *t;
    int32_t nv, nt;
} mesh;

static mesh sphere_mesh(double radius, int32_t segments, int32_t rings)
{
    mesh m;
    m.v = malloc(3 * (2 + (size_t)(rings - 1) * (size_t)segments) * sizeof *m.v);
    m.t = malloc(6 * (size_t)segments * (size_t)(rings - 1) * sizeof *m.t);
    if (!m.v || !m.t) exit(test_report("test_support"));
    m.nv = scene_uv_sphere(radius, segments, rings, m.v, m.t, &m.nt);
    return m;
}

/* A flat square of side 2 half at z = 0, centred at the origin, of
 * cells x cells squares of two triangles each. */
static mesh flat_grid(int32_t cells, double half)
{
    mesh m;
    m.nv = (cells + 1) * (cells + 1), m.nt = 2 * cells * cells;
    m.v = malloc(3 * (size_t)m.nv * sizeof *m.v);
    m.t = malloc(3 * (size_t)m.nt * sizeof *m.t);
    if (!m.v || !m.t) exit(test_report("test_support"));
    for (int j = 0; j <= cells; ++j)
        for (int i = 0; i <= cells; ++i) {
            double *p = m.v + 3 * (size_t)(j * (cells + 1) + i);
            p[0] = -half + 2.0 * half * i / cells, p[1] = -half + 2.0 * half * j / cells, p[2] = 0.0;
        }
    for (int32_t j = 0, k = 0; j < cells; ++j)
        for (int32_t i = 0; i < cells; ++i) {
            int32_t a = j * (cells + 1) + i, b = a + 1, c = a + cells + 1, d = c + 1;
            m.t[k++] = a, m.t[k++] = b, m.t[k++] = d, m.t[k++] = a, m.t[k++] = d, m.t[k++] = c;
        }
    return m;
}

/* A 0.8 m square of ground, with a bump of `bump` m and a groove along y,
 * 6 cm deep and 12 cm wide (a concave collider). */
static mesh ground_mesh(double bump)
{
    mesh m = flat_grid(GROUND_N, 0.4);
    for (int32_t k = 0; k < m.nv; ++k) {
        double *p = m.v + 3 * (size_t)k, x = p[0], y = p[1];
        double groove = fabs(x + 0.15) < 0.06 ? -0.06 * (1.0 - fabs(x + 0.15) / 0.06) : 0.0;
        p[2] = groove + bump * exp(-((x - 0.15) * (x - 0.15) + y * y) / (2 * 0.08 * 0.08));
    }
    return m;
}

static void mesh_free(mesh *m)
{
    free(m->v), free(m->t);
}

/* The mesh as a collider of the tests' thickness and the given friction
 * (negative: the default). */
static int32_t add_mesh_with(wc_world *w, const mesh *m, double friction)
{
    wc_mesh_collider_def d = wc_mesh_collider_def_default();
    d.vertices = m->v, d.vertex_count = m->nv, d.triangles = m->t, d.triangle_count = m->nt;
    d.thickness = THICKNESS;
    if (friction >= 0.0) d.friction = friction;
    int32_t col = -1;
    CHECK(wc_world_add_mesh_collider(w, &d, &col) == WC_OK, "%s", wc_world_last_error(w));
    return col;
}

static int32_t add_mesh(wc_world *w, const mesh *m)
{
    return add_mesh_with(w, m, -1.0);
}

static const double *corner(const wc_collider *c, int32_t t, int k)
{
    return c->current + 3 * (size_t)c->triangles[3 * (size_t)t + k];
}

/* Triangle t's reach on a side by brute force: every vertex of every
 * triangle, the same heights and distances as support.c computes. */
static double brute_reach(const wc_collider *c, const wc_support *s, int32_t t, int side)
{
    const double *n = c->normals + 3 * (size_t)t, *a = corner(c, t, 0);
    if (n[0] == 0.0 && n[1] == 0.0 && n[2] == 0.0) return 0.0;
    double best2 = s->cap * s->cap, w[3];
    for (int32_t u = 0; u < c->triangle_count; ++u)
        for (int k = 0; k < 3; ++k) {
            const double *v = corner(c, u, k);
            double rel[3];
            sub3(v, a, rel);
            if (!((side ? -1.0 : 1.0) * dot3(rel, n) > s->tolerance)) continue;
            double d2 = wci_point_triangle_closest(v, a, corner(c, t, 1), corner(c, t, 2), w);
            if (d2 < best2) best2 = d2;
        }
    return sqrt(best2);
}

/* Measures every reach of the collider and compares it with brute force;
 * returns how many front reaches are short of the cap. */
static int32_t check_reaches(const wc_collider *c, double r, const char *name)
{
    wc_support s;
    memset(&s, 0, sizeof s);
    CHECK(wci_support_prepare(&s, c, r) == WC_OK && wci_support_ready(&s, c, r), "%s: not ready", name);
    int32_t short_front = 0, wrong = 0;
    for (int32_t t = 0; t < c->triangle_count; ++t)
        for (int side = 0; side < 2; ++side) {
            CHECK(!wci_support_measured(&s, t, side), "%s: triangle %d measured before", name, (int)t);
            wci_support_measure(&s, c, t, side);
            double got = s.reach[2 * (size_t)t + side], want = brute_reach(c, &s, t, side);
            if (got != want && wrong++ < 3)
                CHECK(0, "%s: triangle %d side %d: reach %.17g, brute force %.17g", name, (int)t, side, got,
                      want);
            short_front += side == 0 && got < s.cap;
        }
    CHECK(wrong == 0, "%s: %d reaches differ from brute force", name, (int)wrong);
    printf("%s: %d triangles, cap %.4f m, %d front reaches short of it\n", name, (int)c->triangle_count,
           s.cap, (int)short_front);
    wci_support_destroy(&s);
    return short_front;
}

/* A world with the mesh as its only collider, begun (normals and tree
 * made, as at a step's start). */
static wc_collider *begun_collider(wc_world **w, const mesh *m)
{
    wc_world_def def = wc_world_def_default();
    def.thread_count = 1;
    *w = scene_world_from(&def);
    int32_t col = add_mesh(*w, m);
    wc_collider *c = (*w)->colliders[col];
    CHECK(wci_collider_begin_step(c, 1.0) == WC_OK, "begin step");
    return c;
}

static void reaches_by_brute_force(void)
{
    mesh sphere = sphere_mesh(0.3, 32, 16), ground = ground_mesh(0.05);
    wc_world *w;
    wc_collider *c = begun_collider(&w, &sphere);
    CHECK(check_reaches(c, 0.023, "32 x 16 sphere") == 0, "a convex sphere has a short front reach");
    wc_world_destroy(w);
    c = begun_collider(&w, &ground);
    CHECK(check_reaches(c, 0.023, "ground with a bump and a groove") > 0, "no short front reach on the ground");
    wc_world_destroy(w);

    /* a collider that moves and comes to rest: the reaches it had are not
     * ready for its new shape, and those measured again match it */
    c = begun_collider(&w, &ground);
    wc_support s;
    memset(&s, 0, sizeof s);
    CHECK(wci_support_prepare(&s, c, 0.023) == WC_OK, "prepare");
    mesh flat = ground_mesh(0.0);
    CHECK(wc_collider_set_vertices(w, 0, flat.v, flat.nv) == WC_OK, "%s", wc_world_last_error(w));
    CHECK(wc_world_step(w, 1.0 / 240) == WC_OK, "%s", wc_world_last_error(w));
    CHECK(!c->moving && !wci_support_ready(&s, c, 0.023), "reaches kept for the old shape");
    CHECK(wci_collider_begin_step(c, 1.0) == WC_OK, "begin step");
    check_reaches(c, 0.023, "the ground at rest without its bump");
    CHECK(!wci_support_ready(&s, c, 0.024), "reaches ready for another contact distance");
    wci_support_destroy(&s);
    wc_world_destroy(w);
    mesh_free(&sphere), mesh_free(&ground), mesh_free(&flat);
}

/* Whether segment p-q meets triangle a-b-c, by exact orientation tests (a
 * segment in the triangle's plane counts as meeting it). */
static int segment_meets(const double p[3], const double q[3], const double a[3], const double b[3],
                         const double c[3])
{
    int sp = wci_orient3d(a, b, c, p), sq = wci_orient3d(a, b, c, q);
    if (sp == sq && sp != 0) return 0;
    if (sp == 0 && sq == 0) return 1;
    int s1 = wci_orient3d(p, q, a, b), s2 = wci_orient3d(p, q, b, c), s3 = wci_orient3d(p, q, c, a);
    return (s1 >= 0 && s2 >= 0 && s3 >= 0) || (s1 <= 0 && s2 <= 0 && s3 <= 0);
}

static double uniform(unsigned *state)
{
    *state = *state * 1103515245u + 12345u;
    return ((*state >> 8) & 0xffffff) / (double)0x1000000;
}

/* Random paths ending near the triangles' planes: every held one checked
 * against every triangle. Returns how many were held out of `tries`. */
static int32_t holds_by_brute_force(const mesh *m, double r, int32_t tries, const char *name)
{
    wc_world *w;
    wc_collider *c = begun_collider(&w, m);
    wc_support s;
    memset(&s, 0, sizeof s);
    CHECK(wci_support_prepare(&s, c, r) == WC_OK, "prepare");
    unsigned seed = 12345u;
    int32_t held = 0, bad = 0;
    for (int32_t k = 0; k < tries; ++k) {
        int32_t t = (int32_t)(uniform(&seed) * c->triangle_count);
        const double *n = c->normals + 3 * (size_t)t;
        double u = uniform(&seed), v = uniform(&seed), side = uniform(&seed) < 0.9 ? 1.0 : -1.0;
        if (u + v > 1.0) u = 1.0 - u, v = 1.0 - v;
        double height = r * (0.98 + 0.1 * uniform(&seed)), end[3], start[3];
        for (int j = 0; j < 3; ++j) {
            double foot = corner(c, t, 0)[j] + u * (corner(c, t, 1)[j] - corner(c, t, 0)[j]) +
                          v * (corner(c, t, 2)[j] - corner(c, t, 0)[j]);
            end[j] = foot + side * height * n[j];
            start[j] = end[j] + r * (uniform(&seed) - 0.5) + 0.5 * r * side * n[j] * uniform(&seed);
        }
        int st = wci_support_side(c, t, start);
        if (!wci_support_measured(&s, t, st)) wci_support_measure(&s, c, t, st);
        if (!wci_support_holds(&s, c, t, start, end)) continue;
        ++held;
        for (int32_t q = 0; q < c->triangle_count; ++q) {
            double bary[3];
            const double *a = corner(c, q, 0), *b = corner(c, q, 1), *d = corner(c, q, 2);
            double d2 = wci_point_triangle_closest(end, a, b, d, bary);
            int meets = segment_meets(start, end, a, b, d);
            if ((d2 < r * r * (1.0 - WC_FACE_SLACK) || meets) && bad++ < 3)
                CHECK(0, "%s: a path held by triangle %d %s triangle %d (distance %.17g, r %.17g)", name,
                      (int)t, meets ? "meets" : "ends too near", (int)q, sqrt(d2), r);
        }
    }
    CHECK(bad == 0, "%s: %d held paths touch a triangle", name, (int)bad);
    printf("%s: %d of %d paths held, none touching\n", name, (int)held, (int)tries);
    wci_support_destroy(&s);
    wc_world_destroy(w);
    return held;
}

static void holds_checked(void)
{
    mesh sphere = sphere_mesh(0.3, 32, 16), ground = ground_mesh(0.05);
    int32_t on_sphere = holds_by_brute_force(&sphere, 0.023, 3000, "32 x 16 sphere");
    CHECK(on_sphere > 3000 / 2, "only %d of 3000 paths above the sphere held", (int)on_sphere);
    CHECK(holds_by_brute_force(&ground, 0.023, 3000, "ground") > 0, "no path held on the ground");
    mesh_free(&sphere), mesh_free(&ground);
}

typedef struct drop_result {
    int64_t face_tests;
    double nearest; /* least particle distance from the collider over the frames, / r */
    int32_t intersections;
    double *positions;
    int32_t particles;
} drop_result;

/* A 20 x 20 cloth of 0.6 m dropped from 0.1 m above the collider's top,
 * `frames` frames at the default integrator, supports on or off. */
static drop_result drop(const mesh *m, double top, int support, int frames)
{
    wc_world_def def = wc_world_def_default();
    def.thread_count = 1;
    wc_world *w = scene_world_from(&def);
    add_mesh(w, m);
    wc_grid_cloth_def g = wc_grid_cloth_def_default();
    g.count_u = g.count_v = 20;
    g.size_u = g.size_v = 0.6;
    g.center[2] = top + 0.1;
    int32_t cl = scene_add_grid(w, &g);
    double r = g.material.thickness + THICKNESS;
    drop_result out = {0, INFINITY, 0, NULL, 400};
    double *p = malloc(3 * 400 * sizeof *p), *d = malloc(400 * sizeof *d);
    out.positions = p;
    if (!p || !d) exit(test_report("test_support"));
    for (int f = 0; f < frames; ++f) {
        CHECK(wc_world_advance(w, 1.0 / 24, 0) == WC_OK, "%s", wc_world_last_error(w));
        if (f == 0) wci_collider_contacts_use_support(w->cloths[cl]->collider_contacts, support);
        CHECK(wc_cloth_get_positions(w, cl, p, 400) == WC_OK, "positions");
        scene_distances_to_mesh(p, 400, m->v, m->t, m->nt, d);
        for (int i = 0; i < 400; ++i)
            if (d[i] / r < out.nearest) out.nearest = d[i] / r;
        out.intersections += scene_intersections(w);
    }
    out.face_tests = wci_collider_contacts_face_tests(w->cloths[cl]->collider_contacts);
    free(d);
    wc_world_destroy(w);
    return out;
}

/* The same drop with supports and without: `least_saved` the fewest face
 * tests the supports must save (as a fraction of those without; 0: none,
 * for a collider where few triangles hold). */
static void drop_both_ways(const mesh *m, double top, int frames, double least_saved, const char *name)
{
    drop_result with = drop(m, top, 1, frames), without = drop(m, top, 0, frames);
    double rms = 0.0;
    for (int k = 0; k < 3 * 400; ++k) {
        double d = with.positions[k] - without.positions[k];
        rms += d * d;
    }
    rms = sqrt(rms / 400);
    printf("%s: %lld face tests with supports, %lld without; nearest particle %.9f r and %.9f r; "
           "drapes %.2e m apart\n", name, (long long)with.face_tests, (long long)without.face_tests,
           with.nearest, without.nearest, rms);
    /* a particle put at r sits there up to rounding (the face test's slack) */
    CHECK(with.nearest >= 1.0 - 1e-9 && without.nearest >= 1.0 - 1e-9,
          "%s: a particle nearer than the contact distance (%.12f r, %.12f r without supports)", name,
          with.nearest, without.nearest);
    CHECK(with.intersections == 0 && without.intersections == 0, "%s: %d and %d intersections", name,
          (int)with.intersections, (int)without.intersections);
    CHECK(least_saved <= 0.0 || with.face_tests < (1.0 - least_saved) * without.face_tests,
          "%s: %lld face tests with supports against %lld", name, (long long)with.face_tests,
          (long long)without.face_tests);
    CHECK(rms < 0.01 * 0.6, "%s: the drapes are %.3e m apart", name, rms);
    free(with.positions), free(without.positions);
}

static void contact_stage(void)
{
    mesh sphere = sphere_mesh(0.3, 64, 32), ground = ground_mesh(0.05);
    drop_both_ways(&sphere, 0.3, 16, 0.5, "3,968-triangle sphere");
    drop_both_ways(&ground, 0.05, 16, 0.0, "ground with a bump and a groove");
    mesh_free(&sphere), mesh_free(&ground);
}

/* Steps refused and taken again leave no trace in the hints and the
 * reaches measured (collider_contacts.c): world A refuses every step down
 * to the last halving (its tear ratio 0, step_guard.h), world B takes the
 * steps A ends with and refuses none; with a cloth resting on a sphere,
 * held at nearly every step, they must stay equal bit for bit. */
static void refused_steps_leave_no_hint(void)
{
    mesh sphere = sphere_mesh(0.3, 64, 32);
    wc_world *w[2];
    int32_t cl[2];
    for (int k = 0; k < 2; ++k) {
        wc_world_def def = wc_world_def_default();
        def.thread_count = 1;
        w[k] = scene_world_from(&def);
        add_mesh(w[k], &sphere);
        wc_grid_cloth_def g = wc_grid_cloth_def_default();
        g.count_u = g.count_v = 12;
        g.size_u = g.size_v = 0.5;
        g.center[2] = 0.35;
        cl[k] = scene_add_grid(w[k], &g);
    }
    w[0]->tear_ratio = 0.0, w[0]->tear_growth = -INFINITY;
    int32_t halvings = (1 << WC_TEAR_HALVINGS) - 1, wrong_count = 0;
    for (int f = 0; f < 12; ++f) {
        CHECK(wc_world_advance(w[0], 1.0 / 24, 2) == WC_OK, "A: %s", wc_world_last_error(w[0]));
        CHECK(wc_world_advance(w[1], 1.0 / 24, 16) == WC_OK, "B: %s", wc_world_last_error(w[1]));
        wrong_count += wc_world_get_stats(w[0]).halved_steps != 2 * halvings;
    }
    int64_t held = wci_collider_contacts_face_tests(w[1]->cloths[cl[1]]->collider_contacts);
    uint64_t a = scene_hash_positions(w[0], cl[0]), b = scene_hash_positions(w[1], cl[1]);
    int32_t touching = wc_world_get_stats(w[1]).collider_contacts;
    printf("refused steps: %d particles touching the sphere, %lld face tests; A %016llx, B %016llx\n",
           (int)touching, (long long)held, (unsigned long long)a, (unsigned long long)b);
    CHECK(wrong_count == 0, "%d frames where A did not refuse every step", (int)wrong_count);
    CHECK(touching > 50, "only %d particles touch the sphere", (int)touching);
    CHECK(a == b, "steps refused and taken again changed the result");
    for (int k = 0; k < 2; ++k) wc_world_destroy(w[k]);
    mesh_free(&sphere);
}

/* A 5 x 5 cloth of 0.1 m resting on a flat square of 2 m made of
 * cells x cells squares (two triangles each), gravity tilted by theta:
 * how far its centre slides along the slope in `seconds`. Friction mu for
 * the cloth and the ground (a contact's is sqrt of their product: mu). */
static double slide(int32_t cells, int support, double theta, double mu, double seconds)
{
    wc_world_def def = wc_world_def_default();
    def.thread_count = 1;
    def.gravity[0] = 9.81 * sin(theta), def.gravity[1] = 0.0, def.gravity[2] = -9.81 * cos(theta);
    wc_world *w = scene_world_from(&def);
    mesh m = flat_grid(cells, 1.0);
    add_mesh_with(w, &m, mu);
    wc_grid_cloth_def g = wc_grid_cloth_def_default();
    g.count_u = g.count_v = 5;
    g.size_u = g.size_v = 0.1;
    g.material.friction = mu;
    g.material.air_drag = 0.0;
    g.center[0] = -0.5, g.center[2] = g.material.thickness + THICKNESS;
    int32_t cl = scene_add_grid(w, &g);
    for (int f = 0; f < (int)(seconds * 24 + 0.5); ++f) {
        CHECK(wc_world_advance(w, 1.0 / 24, 0) == WC_OK, "%s", wc_world_last_error(w));
        if (f == 0) wci_collider_contacts_use_support(w->cloths[cl]->collider_contacts, support);
    }
    double p[75], x = 0.0;
    CHECK(wc_cloth_get_positions(w, cl, p, 25) == WC_OK, "positions");
    for (int i = 0; i < 25; ++i) x += p[3 * i] / 25;
    wc_world_destroy(w);
    mesh_free(&m);
    return x + 0.5;
}

/* Coulomb friction on a slope is the same on any triangulation of it: one
 * face answers for a held particle, so its friction is taken once per
 * step, where before a particle near a cell's edge was pushed by the
 * neighbouring face too (along the offset from its edge, then along the
 * normal of its own) and took friction twice. Closed form: the centre
 * slides g (sin theta - mu cos theta) t^2 / 2, which the two-triangle
 * ground gives to 5 digits (the implicit solve resolves the cloth's motion
 * as a whole exactly: test_integrators), so each mesh must come within 2 %
 * of it and, with supports, within 0.6 % of the two-triangle ground
 * (measured: 0.06 % and 0.10 % on the 4 x 4 and 16 x 16 grounds, 0.48 % on
 * the 64 x 64 one, whose 3 cm cells are about the cloth's 2.5 cm spacing;
 * without supports the 64 x 64 ground slid 1.5 % less). */
static void friction_on_any_mesh(void)
{
    double theta = 20.0 * 3.14159265358979323846 / 180.0, mu = 0.2, seconds = 0.5;
    double exact = 0.5 * 9.81 * (sin(theta) - mu * cos(theta)) * seconds * seconds;
    double coarse = slide(1, 1, theta, mu, seconds);
    printf("slide on a slope of 20 degrees, mu 0.2, 0.5 s: closed form %.5f m; 1 x 1 cells %.5f m", exact,
           coarse);
    CHECK(fabs(coarse - exact) < 0.02 * exact, "the slide on two triangles is %.5f m, not %.5f", coarse, exact);
    for (int32_t cells = 4; cells <= 64; cells *= 4) {
        double on = slide(cells, 1, theta, mu, seconds), off = slide(cells, 0, theta, mu, seconds);
        printf(", %d x %d %.5f m (%.5f without supports)", (int)cells, (int)cells, on, off);
        CHECK(fabs(on - exact) < 0.02 * exact, "the slide on %d x %d cells is %.5f m, not %.5f", (int)cells,
              (int)cells, on, exact);
        CHECK(fabs(on - coarse) < 0.006 * coarse, "the slide on %d x %d cells is %.5f m, on two triangles %.5f",
              (int)cells, (int)cells, on, coarse);
    }
    printf("\n");
}

int main(void)
{
    friction_on_any_mesh();
    reaches_by_brute_force();
    holds_checked();
    contact_stage();
    refused_steps_leave_no_hint();
    return test_report("test_support");
}
