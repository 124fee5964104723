/* Self-collision (libwetcloth/selfcollide.c):
 *  (a) a vertex thrown through a face in one step is stopped on its own side,
 *      at least the thickness away;
 *  (a') a particle a collider pass pushed into the band over a face stays at
 *      rest (the push is not taken as approach);
 *  (b) two edges thrown across each other are stopped likewise;
 *  (c) the fail-safe: a stack of layers all thrown through one another, which
 *      the response passes cannot sort out, ends with no collision left in
 *      the step's motion; reverted particles are exactly at their start, at
 *      rest;
 *  (d) the same crumpled cloth resolved on 1, 2 and 4 threads gives the same
 *      bits;
 *  (e) end to end: a 64 x 64 cloth whose right half is thrown over its left
 *      half folds onto itself and settles on a ground plate; the independent
 *      checker (wc_world_count_intersections) finds no cloth-cloth
 *      intersection at any frame.
 *  (f) two separate cloths (collide_with_cloths): one thrown at 3 m/s onto
 *      the other, which lies on a plate and does not self-collide, comes to
 *      rest on it with no intersection in any frame, the same bits on 1 and
 *      4 threads; with collide_with_cloths = 0 on the thrown one it passes
 *      through (the checker sees it), so the flag is what keeps them apart.
 *  (g) the normal-cone cull's contour condition (contour.h): which
 *      triangle sets are oriented disks; which projected boundary motions
 *      stay simple; and a U-shaped cloth whose arm slides in its own plane
 *      over the other arm and down through it in one step, every triangle
 *      facing up throughout, is stopped: the cone alone would skip the
 *      region's element tests.
 *  (h) a layer knocked onto a collider's tip: a cloth of two 5 x 5 layers
 *      over a thin pyramid, the lower one resting 2 mm above the contact
 *      distance from its tip, the upper one thrown down onto it at 20 m/s;
 *      the response between the layers pushes the lower one down over the
 *      tip in the same step, and what it moved goes through the collider
 *      stage again (world.c), so no step ends with the tip through the
 *      cloth (without that second pass: 4 cloth-pyramid pairs).
 * (a)-(d), (g) drive wci_self_collide directly on a cloth's internal arrays, with
 * a brute-force check (every vertex-face and edge-edge pair, no broadphase)
 * of what remains. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "cloth.h"
#include "contour.h"
#include "primitives.h"
#include "scenes.h"
#include "selfcollide.h"
#include "test_util.h"
#include "wetcloth.h"
#include "world.h"

static uint64_t rng = 0x2545F4914F6CDD1Dull;
static double uniform(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (double)(rng >> 11) / 9007199254740992.0;
}

static wc_world *new_world(int threads)
{
    wc_world_def wd = wc_world_def_default();
    wd.thread_count = threads;
    wc_world *w = NULL;
    wc_message m;
    wc_status s = wc_world_create(&wd, &w, &m);
    CHECK(s == WC_OK, "world: %s", m.text);
    return w;
}

/* A mesh cloth with self-collision; returns its internal struct. */
static wc_cloth *add_mesh(wc_world *w, const double *xyz, int32_t n, const int32_t *faces,
                          int32_t face_count, double thickness)
{
    wc_mesh_cloth_def d = wc_mesh_cloth_def_default();
    d.vertices = xyz;
    d.vertex_count = n;
    d.faces = faces;
    d.face_count = face_count;
    d.face_size = 3;
    d.material.thickness = thickness;
    d.self_collision = 1;
    int32_t id;
    wc_status s = wc_world_add_mesh_cloth(w, &d, &id);
    CHECK(s == WC_OK, "add_mesh_cloth: %s", wc_world_last_error(w));
    return s == WC_OK ? w->cloths[id] : NULL;
}

static void clear_contacts(wc_cloth *c)
{
    memset(c->contact, 0, (size_t)c->particle_count);
    memset(c->history_override, 0, (size_t)c->particle_count);
}

static void get(const double *x, const double *y, const double *z, int32_t i, double out[3])
{
    out[0] = x[i], out[1] = y[i], out[2] = z[i];
}

static void set_end(wc_cloth *c, int32_t i, double x, double y, double z)
{
    c->nx[i] = x, c->ny[i] = y, c->nz[i] = z;
}

/* Unique edges of the cloth's triangles, brute force (small meshes). */
static int32_t collect_edges(const wc_cloth *c, int32_t *edges)
{
    int32_t count = 0;
    for (int32_t t = 0; t < c->topology.triangle_count; ++t)
        for (int k = 0; k < 3; ++k) {
            int32_t a = c->topology.triangles[3 * t + k], b = c->topology.triangles[3 * t + (k + 1) % 3];
            if (a > b) {
                int32_t tmp = a;
                a = b, b = tmp;
            }
            int found = 0;
            for (int32_t e = 0; e < count && !found; ++e) found = edges[2 * e] == a && edges[2 * e + 1] == b;
            if (!found) edges[2 * count] = a, edges[2 * count + 1] = b, ++count;
        }
    return count;
}

/* Every vertex-face and edge-edge pair whose motion x -> nx collides
 * (coplanar within tol). No broadphase: checks the solver's. */
static int32_t count_ccd_collisions(const wc_cloth *c, double tol)
{
    int32_t hits = 0, nt = c->topology.triangle_count;
    const int32_t *tris = c->topology.triangles;
    for (int32_t t = 0; t < nt; ++t) {
        double a0[3], a1[3], b0[3], b1[3], c0[3], c1[3];
        const int32_t *tri = tris + 3 * t;
        get(c->x, c->y, c->z, tri[0], a0), get(c->nx, c->ny, c->nz, tri[0], a1);
        get(c->x, c->y, c->z, tri[1], b0), get(c->nx, c->ny, c->nz, tri[1], b1);
        get(c->x, c->y, c->z, tri[2], c0), get(c->nx, c->ny, c->nz, tri[2], c1);
        for (int32_t v = 0; v < c->particle_count; ++v) {
            if (v == tri[0] || v == tri[1] || v == tri[2]) continue;
            double p0[3], p1[3], time, bary[3];
            get(c->x, c->y, c->z, v, p0), get(c->nx, c->ny, c->nz, v, p1);
            hits += wci_ccd_point_triangle(p0, p1, a0, a1, b0, b1, c0, c1, tol, &time, bary);
        }
    }
    int32_t *edges = malloc(sizeof(int32_t) * 6 * (size_t)nt);
    int32_t ne = collect_edges(c, edges);
    for (int32_t e = 0; e < ne; ++e)
        for (int32_t f = e + 1; f < ne; ++f) {
            const int32_t *E = edges + 2 * e, *F = edges + 2 * f;
            if (E[0] == F[0] || E[0] == F[1] || E[1] == F[0] || E[1] == F[1]) continue;
            double p[4][2][3], time, s, u;
            int32_t ids[4] = {E[0], E[1], F[0], F[1]};
            for (int j = 0; j < 4; ++j) {
                get(c->x, c->y, c->z, ids[j], p[j][0]);
                get(c->nx, c->ny, c->nz, ids[j], p[j][1]);
            }
            hits += wci_ccd_edge_edge(p[0][0], p[0][1], p[1][0], p[1][1], p[2][0], p[2][1], p[3][0],
                                     p[3][1], tol, &time, &s, &u);
        }
    free(edges);
    return hits;
}

/* ------------------------------------------------------------------------ */
/* (a) vertex through a face                                                */
/* ------------------------------------------------------------------------ */

/* Triangle A flat at z = 0; triangle B above, its apex (vertex 3)
 * pointing down at z = 0.05 over A's interior. */
static wc_cloth *apex_over_face(wc_world *w, double thickness)
{
    double xyz[] = {-0.5, -0.5, 0.0, 0.5, -0.5, 0.0, 0.0, 0.5, 0.0,
                    0.0,  0.0,  0.05, 0.3, 0.1, 0.4, -0.3, 0.1, 0.4};
    int32_t faces[] = {0, 1, 2, 3, 4, 5};
    return add_mesh(w, xyz, 6, faces, 2, thickness);
}

static void test_vertex_face(void)
{
    const double h = 0.01;
    wc_world *w = new_world(1);
    wc_cloth *c = apex_over_face(w, h);
    if (!c) return;
    /* Apex thrown 0.2 m down through A in one step; the rest of B follows a
     * little; A is still. */
    for (int32_t i = 0; i < 6; ++i) set_end(c, i, c->x[i], c->y[i], c->z[i]);
    set_end(c, 3, 0.0, 0.0, -0.15);
    set_end(c, 4, 0.3, 0.1, 0.35);
    set_end(c, 5, -0.3, 0.1, 0.35);
    clear_contacts(c);
    CHECK(count_ccd_collisions(c, 1e-9) > 0, "setup: the apex should pass through A");
    wc_step_stats stats;
    memset(&stats, 0, sizeof stats);
    wc_status s = wci_self_collide(c, 0.01, 1, &stats);
    CHECK(s == WC_OK, "wci_self_collide: %d", (int)s);
    double p[3], a[3], b[3], q[3], bary[3];
    get(c->nx, c->ny, c->nz, 3, p);
    get(c->nx, c->ny, c->nz, 0, a);
    get(c->nx, c->ny, c->nz, 1, b);
    get(c->nx, c->ny, c->nz, 2, q);
    double d = sqrt(wci_point_triangle_closest(p, a, b, q, bary));
    double plane = p[2] - (bary[0] * a[2] + bary[1] * b[2] + bary[2] * q[2]);
    printf("vertex-face: apex ends %.6g m above A (thickness %g), contacts %d, fail-safe %d\n",
           plane, h, (int)stats.cloth_contacts, (int)stats.failsafe_particles);
    CHECK(plane > 0.0, "the apex ended below A: %g", plane);
    CHECK(d >= 0.999 * h, "the apex ended %g from A, closer than the thickness %g", d, h);
    CHECK(count_ccd_collisions(c, 1e-9) == 0, "a collision remains");
    CHECK(stats.failsafe_particles == 0, "needed the fail-safe (%d)", (int)stats.failsafe_particles);
    CHECK(stats.cloth_contacts >= 4, "contacts: %d", (int)stats.cloth_contacts);
    CHECK(c->contact[3] == WC_CONTACT_CLOTH && c->normal_z[3] > 0.99,
          "apex contact %d normal z %g", (int)c->contact[3], c->normal_z[3]);
    CHECK(c->contact[0] == WC_CONTACT_CLOTH && c->normal_z[0] < -0.99,
          "face contact %d normal z %g", (int)c->contact[0], c->normal_z[0]);
    /* Momentum: equal and opposite displacement changes (inelastic). */
    double before = c->mass[3] * (-0.2), after = 0.0;
    for (int32_t i = 0; i < 6; ++i)
        if (i != 4 && i != 5) after += c->mass[i] * (c->nz[i] - c->z[i]);
    CHECK(fabs(after - before) < 1e-12, "vertical momentum changed: %g -> %g", before, after);
    wc_world_destroy(w);
}

/* (a') A particle a collider pass has just pushed (by delta, toward a face
 * of its own cloth, into the self-collision band) carries the push in both
 * its end and its history (history_override, q moved by the same delta: a
 * change of position, not of velocity). The pair's approach must be measured
 * from q: measured from the step's start, the push counted as approach and
 * came back as a velocity of delta / dt (3b87f65: a 0.35 mm push at 8.6 us
 * steps launched particles at 40 m/s in the 101 x 101 drape). Every particle
 * is at rest before; the response may move them apart but must leave them at
 * rest: the velocity the next step sees, (end - previous) / dt, stays zero
 * to rounding; without the fix the fastest particle here got 18.5 m/s. */
static void test_pushed_particle_at_rest(void)
{
    const double h = 0.01, dt = 1e-4;
    wc_world *w = new_world(1);
    wc_cloth *c = apex_over_face(w, h);
    if (!c) return;
    double band = wci_self_thickness(c);
    clear_contacts(c);
    /* the apex starts the step at rest on the band over A, and a collider
     * pass pushed it 0.2 band down */
    c->z[3] = band;
    for (int32_t i = 0; i < 6; ++i) set_end(c, i, c->x[i], c->y[i], c->z[i]);
    double push = -0.2 * band;
    c->nz[3] += push;
    c->qx[3] = c->x[3], c->qy[3] = c->y[3], c->qz[3] = c->z[3] + push;
    c->history_override[3] = 1;
    wc_step_stats stats;
    memset(&stats, 0, sizeof stats);
    CHECK(wci_self_collide(c, dt, 1, &stats) == WC_OK, "wci_self_collide failed");
    double fastest = 0.0;
    for (int32_t i = 0; i < 6; ++i) {
        double prev[3] = {c->x[i], c->y[i], c->z[i]};
        if (c->history_override[i]) prev[0] = c->qx[i], prev[1] = c->qy[i], prev[2] = c->qz[i];
        double v[3] = {(c->nx[i] - prev[0]) / dt, (c->ny[i] - prev[1]) / dt, (c->nz[i] - prev[2]) / dt};
        fastest = fmax(fastest, sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]));
    }
    printf("pushed particle: band %g m, contacts %d, fastest particle after the response %.3g m/s\n",
           band, (int)stats.cloth_contacts, fastest);
    CHECK(stats.cloth_contacts > 0, "setup: the pushed apex is not in contact with A");
    CHECK(c->nz[3] > c->z[3] + push, "setup: the response did not move the apex out");
    /* rounding: positions ~0.5 m to 1e-16 relative, over dt = 1e-4 s */
    CHECK(fastest < 1e-9, "the response turned the push into a velocity of %g m/s", fastest);
    wc_world_destroy(w);
}

/* ------------------------------------------------------------------------ */
/* (b) edge through an edge                                                 */
/* ------------------------------------------------------------------------ */

static void test_edge_edge(void)
{
    const double h = 0.01;
    /* A: vertical triangle in the plane y = 0, top edge along x at z = 0.
     * B: vertical triangle in the plane x = 0 (apex slightly off it), bottom
     * edge along y at z = 0.05, right above A's top edge. B drops 0.2 m: its
     * bottom edge crosses A's top edge, and no vertex goes through a face. */
    double xyz[] = {-0.5, 0.0, 0.0,  0.5, 0.0, 0.0,  0.0,  0.0, -0.5,
                    0.0, -0.2, 0.05, 0.0, 0.2, 0.05, 0.02, 0.0, 0.4};
    int32_t faces[] = {0, 1, 2, 3, 4, 5};
    wc_world *w = new_world(1);
    wc_cloth *c = add_mesh(w, xyz, 6, faces, 2, h);
    if (!c) return;
    for (int32_t i = 0; i < 6; ++i) set_end(c, i, c->x[i], c->y[i], c->z[i] - (i >= 3 ? 0.2 : 0.0));
    clear_contacts(c);
    CHECK(count_ccd_collisions(c, 1e-9) > 0, "setup: the edges should cross");
    wc_step_stats stats;
    memset(&stats, 0, sizeof stats);
    wc_status s = wci_self_collide(c, 0.01, 1, &stats);
    CHECK(s == WC_OK, "wci_self_collide: %d", (int)s);
    double p0[3], p1[3], q0[3], q1[3], u, v;
    get(c->nx, c->ny, c->nz, 0, p0);
    get(c->nx, c->ny, c->nz, 1, p1);
    get(c->nx, c->ny, c->nz, 3, q0);
    get(c->nx, c->ny, c->nz, 4, q1);
    double d = sqrt(wci_segment_segment_closest(p0, p1, q0, q1, &u, &v));
    double gap = (q0[2] + (q1[2] - q0[2]) * v) - (p0[2] + (p1[2] - p0[2]) * u);
    printf("edge-edge: B's edge ends %.6g m above A's (thickness %g), contacts %d, fail-safe %d\n",
           gap, h, (int)stats.cloth_contacts, (int)stats.failsafe_particles);
    CHECK(gap > 0.0, "B's edge ended below A's: %g", gap);
    CHECK(d >= 0.999 * h, "edges end %g apart, closer than the thickness %g", d, h);
    CHECK(count_ccd_collisions(c, 1e-9) == 0, "a collision remains");
    CHECK(stats.failsafe_particles == 0, "needed the fail-safe (%d)", (int)stats.failsafe_particles);
    wc_world_destroy(w);
}

/* ------------------------------------------------------------------------ */
/* Pinned particles                                                         */
/* ------------------------------------------------------------------------ */

/* A vertex thrown through a face whose corners are all pinned: the face does
 * not move, the vertex takes the whole response. */
static void test_pinned_face(void)
{
    const double h = 0.01;
    double xyz[] = {-0.5, -0.5, 0.0, 0.5, -0.5, 0.0, 0.0, 0.5, 0.0,
                    0.0,  0.0,  0.05, 0.3, 0.1, 0.4, -0.3, 0.1, 0.4};
    int32_t faces[] = {0, 1, 2, 3, 4, 5};
    wc_world *w = new_world(1);
    wc_cloth *c = add_mesh(w, xyz, 6, faces, 2, h);
    if (!c) return;
    int32_t pins[3] = {0, 1, 2};
    wc_status ps = wc_cloth_pin(w, 0, pins, 3);
    CHECK(ps == WC_OK, "pin: %s", wc_world_last_error(w));
    for (int32_t i = 0; i < 6; ++i) set_end(c, i, c->x[i], c->y[i], c->z[i]);
    set_end(c, 3, 0.0, 0.0, -0.15);
    clear_contacts(c);
    wc_step_stats stats;
    memset(&stats, 0, sizeof stats);
    wci_self_collide(c, 0.01, 1, &stats);
    for (int32_t i = 0; i < 3; ++i)
        CHECK(c->nx[i] == c->x[i] && c->ny[i] == c->y[i] && c->nz[i] == c->z[i],
              "pinned particle %d moved", (int)i);
    CHECK(c->nz[3] >= 0.999 * h, "the apex ends at z = %g, below the thickness %g", c->nz[3], h);
    CHECK(count_ccd_collisions(c, 1e-9) == 0, "a collision remains");
    wc_world_destroy(w);
}

/* ------------------------------------------------------------------------ */
/* (c) the fail-safe                                                        */
/* ------------------------------------------------------------------------ */

/* `layers` square patches of k x k particles, stacked `gap` apart. */
static wc_cloth *add_stack(wc_world *w, int layers, int k, double gap, double h)
{
    int32_t n = layers * k * k, nf = layers * 2 * (k - 1) * (k - 1);
    double *xyz = malloc(sizeof(double) * 3 * (size_t)n);
    int32_t *faces = malloc(sizeof(int32_t) * 3 * (size_t)nf);
    int32_t f = 0;
    for (int l = 0; l < layers; ++l) {
        int32_t base = l * k * k;
        for (int j = 0; j < k; ++j)
            for (int i = 0; i < k; ++i) {
                double *p = xyz + 3 * (size_t)(base + j * k + i);
                /* each layer slightly shifted and tilted: no coplanar
                 * degeneracies between layers */
                p[0] = 0.1 * i + 0.013 * l;
                p[1] = 0.1 * j - 0.007 * l;
                p[2] = gap * l + 0.002 * i - 0.001 * j;
            }
        for (int j = 0; j + 1 < k; ++j)
            for (int i = 0; i + 1 < k; ++i) {
                int32_t a = base + j * k + i, b = a + 1, c = a + k, d = c + 1;
                int32_t *t = faces + 3 * (size_t)f;
                t[0] = a, t[1] = b, t[2] = d, t[3] = a, t[4] = d, t[5] = c;
                f += 2;
            }
    }
    wc_cloth *c = add_mesh(w, xyz, n, faces, nf, h);
    free(xyz);
    free(faces);
    return c;
}

static void test_failsafe(void)
{
    const int layers = 10, k = 5;
    const double gap = 0.03, h = 0.005;
    wc_world *w = new_world(1);
    wc_cloth *c = add_stack(w, layers, k, gap, h);
    if (!c) return;
    /* Every layer is thrown through all the others (the order of the stack
     * reverses) and every particle gets a random kick of several layer gaps
     * on top: a tangle that a few response passes cannot sort out. Every
     * particle moves. */
    rng = 12345;
    for (int32_t i = 0; i < c->particle_count; ++i) {
        int l = i / (k * k);
        double dz = -2.0 * gap * l + gap * (layers - 1);
        set_end(c, i, c->x[i] + 0.6 * (uniform() - 0.5), c->y[i] + 0.6 * (uniform() - 0.5),
                c->z[i] + dz + 0.6 * (uniform() - 0.5));
    }
    clear_contacts(c);
    int32_t before = count_ccd_collisions(c, 1e-9);
    wc_step_stats stats;
    memset(&stats, 0, sizeof stats);
    wc_status s = wci_self_collide(c, 0.01, 1, &stats);
    CHECK(s == WC_OK, "wci_self_collide: %d", (int)s);
    int32_t after = count_ccd_collisions(c, 1e-9);
    int32_t at_start = 0, bad_history = 0;
    for (int32_t i = 0; i < c->particle_count; ++i) {
        if (c->nx[i] != c->x[i] || c->ny[i] != c->y[i] || c->nz[i] != c->z[i]) continue;
        ++at_start;
        /* at rest: the previous position the next step sees is the start */
        if (!c->history_override[i] || c->qx[i] != c->x[i] || c->qy[i] != c->y[i] || c->qz[i] != c->z[i])
            ++bad_history;
    }
    printf("fail-safe: %d colliding pairs in the thrown motion, %d after; %d of %d particles "
           "reverted (%d at their start), contacts %d\n",
           (int)before, (int)after, (int)stats.failsafe_particles, (int)c->particle_count,
           (int)at_start, (int)stats.cloth_contacts);
    CHECK(before > 50, "setup: only %d collisions", (int)before);
    CHECK(after == 0, "%d collisions remain", (int)after);
    CHECK(stats.failsafe_particles > 0, "the fail-safe did not run");
    CHECK(at_start >= stats.failsafe_particles, "%d reverted but only %d at their start",
          (int)stats.failsafe_particles, (int)at_start);
    CHECK(bad_history == 0, "%d reverted particles not at rest", (int)bad_history);
    wc_world_destroy(w);
}

/* ------------------------------------------------------------------------ */
/* (d) determinism across thread counts                                     */
/* ------------------------------------------------------------------------ */

/* A size x size grid crumpled in its plane (shrunk to 40 %) with folds and
 * noise out of it, thrown with random velocities: thousands of contacts. */
static wc_world *crumpled(int size, int threads, double thickness)
{
    wc_world *w = new_world(threads);
    wc_grid_cloth_def g = wc_grid_cloth_def_default();
    g.count_u = g.count_v = size;
    g.material.thickness = thickness;
    g.self_collision = 1;
    int32_t id;
    wc_status s = wc_world_add_grid_cloth(w, &g, &id);
    CHECK(s == WC_OK, "add_grid_cloth: %s", wc_world_last_error(w));
    wc_cloth *c = w->cloths[id];
    double edge = 1.0 / (size - 1);
    rng = 777;
    for (int32_t i = 0; i < c->particle_count; ++i) {
        double u = c->x[i], v = c->y[i];
        c->x[i] = 0.4 * u;
        c->y[i] = 0.4 * v;
        c->z[i] = 0.03 * sin(40.0 * u) * cos(23.0 * v) + 0.3 * edge * (uniform() - 0.5);
        set_end(c, i, c->x[i] + 0.5 * edge * (uniform() - 0.5), c->y[i] + 0.5 * edge * (uniform() - 0.5),
                c->z[i] + 2.0 * edge * (uniform() - 0.5));
    }
    clear_contacts(c);
    return w;
}

static void test_threads(void)
{
    const int size = 80; /* 6400 particles: above WC_PARALLEL_MIN */
    double *ref = NULL;
    size_t n = 0;
    wc_step_stats ref_stats;
    memset(&ref_stats, 0, sizeof ref_stats);
    int thread_counts[3] = {1, 2, 4};
    for (int r = 0; r < 3; ++r) {
        wc_world *w = crumpled(size, thread_counts[r], 0.004);
        wc_cloth *c = w->cloths[0];
        n = (size_t)c->particle_count;
        wc_step_stats stats;
        memset(&stats, 0, sizeof stats);
        wc_status s = wci_self_collide(c, 0.001, thread_counts[r], &stats);
        CHECK(s == WC_OK, "wci_self_collide: %d", (int)s);
        /* Everything the call writes, as bits. */
        double *out = malloc(sizeof(double) * 11 * n);
        const double *arrays[9] = {c->nx, c->ny, c->nz, c->qx, c->qy, c->qz, c->normal_x, c->normal_y, c->normal_z};
        for (int a = 0; a < 9; ++a) memcpy(out + a * n, arrays[a], n * sizeof(double));
        for (size_t i = 0; i < n; ++i) {
            /* q is only meaningful where overridden */
            if (!c->history_override[i]) out[3 * n + i] = out[4 * n + i] = out[5 * n + i] = 0.0;
            out[9 * n + i] = c->contact[i];
            out[10 * n + i] = c->history_override[i];
        }
        if (r == 0) {
            ref = out;
            ref_stats = stats;
            printf("threads: crumpled %dx%d cloth: %d contacts, %d reverted\n", size, size,
                   (int)stats.cloth_contacts, (int)stats.failsafe_particles);
            CHECK(stats.cloth_contacts > 1000, "only %d contacts", (int)stats.cloth_contacts);
        } else {
            CHECK(memcmp(out, ref, sizeof(double) * 11 * n) == 0, "%d threads differ from 1",
                  thread_counts[r]);
            CHECK(stats.cloth_contacts == ref_stats.cloth_contacts &&
                      stats.failsafe_particles == ref_stats.failsafe_particles,
                  "%d threads: stats differ", thread_counts[r]);
            free(out);
        }
        wc_world_destroy(w);
    }
    free(ref);
}

/* ------------------------------------------------------------------------ */
/* (e) a cloth folding onto itself, end to end                              */
/* ------------------------------------------------------------------------ */

/* Under the sanitizers (and their unoptimised build) a coarser cloth keeps
 * the run short; the checks are the same. */
#if defined(__SANITIZE_ADDRESS__)
#define FOLD_SIZE 24
#else
#define FOLD_SIZE 64
#endif

static void test_fold(void)
{
    const int size = FOLD_SIZE, frames = 16;
    wc_world *w = scene_world(1);
    double center[3] = {0.0, 0.0, 0.0}, u[3] = {1.0, 0.0, 0.0}, v[3] = {0.0, 1.0, 0.0};
    scene_add_plate(w, center, u, v, 4.0, 0.0);
    wc_grid_cloth_def g = wc_grid_cloth_def_default();
    g.count_u = g.count_v = size;
    g.center[2] = 0.3;
    g.self_collision = 1;
    int32_t id;
    wc_status s = wc_world_add_grid_cloth(w, &g, &id);
    CHECK(s == WC_OK, "add_grid_cloth: %s", wc_world_last_error(w));
    if (s) return;
    /* Not perfectly flat (0.1 mm of noise): real cloth never is, and a
     * sheet flat to the last bit compressed in its plane has no side to
     * buckle to. The right half is thrown up and over to the left: it turns
     * about the middle column like a page and lands on the left half. */
    int32_t n = wc_cloth_particle_count(w, id);
    double *xyz = malloc(sizeof(double) * 3 * (size_t)n);
    wc_cloth_get_positions(w, id, xyz, n);
    rng = 4242;
    for (int32_t i = 0; i < n; ++i) xyz[3 * i + 2] += 1e-4 * (uniform() - 0.5);
    s = wc_cloth_set_positions(w, id, xyz, n);
    CHECK(s == WC_OK, "set_positions: %s", wc_world_last_error(w));
    double *vel = calloc(3 * (size_t)n, sizeof(double));
    for (int32_t i = 0; i < n; ++i)
        if (i % size >= size / 2) vel[3 * i] = -2.0, vel[3 * i + 2] = 1.5;
    s = wc_cloth_set_velocities(w, id, vel, n);
    CHECK(s == WC_OK, "set_velocities: %s", wc_world_last_error(w));
    int32_t worst = 0, worst_frame = -1, failsafe = 0;
    long steps = 0;
    wc_step_stats last;
    memset(&last, 0, sizeof last);
    for (int f = 0; f < frames; ++f) {
        s = wc_world_advance(w, 1.0 / 24.0, 0);
        CHECK(s == WC_OK, "frame %d: %s", f, wc_world_last_error(w));
        if (s) break;
        steps += wc_world_last_substeps(w);
        last = wc_world_get_stats(w);
        failsafe += last.failsafe_particles;
        wc_intersection_counts counts;
        s = wc_world_count_intersections(w, &counts);
        CHECK(s == WC_OK, "count_intersections: %s", wc_world_last_error(w));
        if (counts.cloth_cloth > worst) worst = counts.cloth_cloth, worst_frame = f;
        CHECK(counts.cloth_cloth == 0, "frame %d: %d cloth-cloth intersections", f,
              (int)counts.cloth_cloth);
    }
    /* It did fold: the right half lies over the left, on it. */
    wc_cloth_get_positions(w, id, xyz, n);
    int32_t over = 0;
    double top = 0.0;
    for (int32_t i = 0; i < n; ++i) {
        if (i % size >= size / 2 && xyz[3 * i] < 0.0) ++over;
        if (xyz[3 * i + 2] > top) top = xyz[3 * i + 2];
    }
    printf("fold: %dx%d cloth, %d frames (%ld steps): right half over the left %d/%d, top %.4f m, "
           "cloth contacts at the end %d, fail-safe particles over the run %d, cloth-cloth "
           "intersections at worst %d (frame %d)\n",
           size, size, frames, steps, (int)over, (int)(n / 2), top, (int)last.cloth_contacts,
           (int)failsafe, (int)worst, worst_frame);
    CHECK(over > n / 2 * 9 / 10, "the cloth did not fold: %d of %d over", (int)over, (int)(n / 2));
    CHECK(top < 0.1, "the cloth has not landed: top at %g m", top);
    CHECK(last.cloth_contacts > n / 10, "layers not in contact: %d", (int)last.cloth_contacts);
    free(xyz);
    free(vel);
    wc_world_destroy(w);
}

/* Two 20 x 20 cloths over a plate: the lower at 2 cm (no self-collision),
 * the upper 10 cm above it, turned by 30 degrees and thrown down at 3 m/s
 * (self-collision on). Returns the positions hash; *worst gets the most
 * cloth-cloth intersections in a frame, *gap the upper cloth's mean height
 * above the lower's at the end. */
static uint64_t two_cloths(int threads, int upper_collides, int32_t *worst, double *gap,
                           int32_t *contacts)
{
    const int n = 20;
    wc_world *w = scene_world(threads);
    double center[3] = {0.0, 0.0, 0.0}, u[3] = {1.0, 0.0, 0.0}, v[3] = {0.0, 1.0, 0.0};
    scene_add_plate(w, center, u, v, 4.0, 0.0);
    wc_grid_cloth_def g = wc_grid_cloth_def_default();
    g.count_u = g.count_v = n;
    g.center[2] = 0.02;
    int32_t lower, upper;
    CHECK(wc_world_add_grid_cloth(w, &g, &lower) == WC_OK, "%s", wc_world_last_error(w));
    g.center[2] = 0.12;
    g.axis_u[0] = cos(0.5236), g.axis_u[1] = sin(0.5236);
    g.axis_v[0] = -sin(0.5236), g.axis_v[1] = cos(0.5236);
    g.self_collision = 1;
    g.collide_with_cloths = upper_collides;
    CHECK(wc_world_add_grid_cloth(w, &g, &upper) == WC_OK, "%s", wc_world_last_error(w));
    double *vel = calloc(3 * (size_t)n * n, sizeof(double)), *p = malloc(sizeof(double) * 3 * n * n);
    for (int i = 0; i < n * n; ++i) vel[3 * i + 2] = -3.0;
    CHECK(wc_cloth_set_velocities(w, upper, vel, n * n) == WC_OK, "%s", wc_world_last_error(w));
    *worst = 0, *contacts = 0;
    for (int f = 0; f < 12; ++f) {
        wc_status s = wc_world_advance(w, 1.0 / 48.0, 0);
        CHECK(s == WC_OK, "two cloths, frame %d: %s", f, wc_world_last_error(w));
        if (s) break;
        wc_intersection_counts c;
        CHECK(wc_world_count_intersections(w, &c) == WC_OK, "%s", wc_world_last_error(w));
        if (c.cloth_cloth > *worst) *worst = c.cloth_cloth;
        *contacts = wc_world_get_stats(w).cloth_contacts;
    }
    double mean[2] = {0.0, 0.0};
    for (int k = 0; k < 2; ++k) {
        wc_cloth_get_positions(w, k ? upper : lower, p, n * n);
        for (int i = 0; i < n * n; ++i) mean[k] += p[3 * i + 2] / (n * n);
    }
    *gap = mean[1] - mean[0];
    uint64_t h = scene_hash_positions(w, lower) * 31u + scene_hash_positions(w, upper);
    free(vel);
    free(p);
    wc_world_destroy(w);
    return h;
}

static void test_two_cloths(void)
{
    int32_t worst, worst4, contacts, through_worst, through_contacts;
    double gap, gap4, through_gap;
    uint64_t one = two_cloths(1, 1, &worst, &gap, &contacts);
    uint64_t four = two_cloths(4, 1, &worst4, &gap4, &contacts);
    two_cloths(1, 0, &through_worst, &through_gap, &through_contacts);
    printf("two cloths: colliding, worst %d cloth-cloth intersections in a frame, the upper "
           "%.4f m above the lower at the end, %d cloth contacts, 1 and 4 threads %s; with "
           "collide_with_cloths = 0 on the upper: worst %d intersections, %.4f m above\n",
           (int)worst, gap, (int)contacts, one == four ? "the same" : "DIFFERENT",
           (int)through_worst, through_gap);
    CHECK(worst == 0 && worst4 == 0, "two cloths: %d cloth-cloth intersections in a frame",
          (int)(worst > worst4 ? worst : worst4));
    CHECK(one == four, "two cloths: 1 and 4 threads end differently");
    /* resting on it: about one thickness (5 mm) above, not through */
    CHECK(gap > 0.004 && gap < 0.03, "two cloths: the upper cloth is %g m above the lower", gap);
    CHECK(contacts > 0, "two cloths: no cloth contacts in the last step");
    CHECK(through_worst > 0 && through_gap < 0.004,
          "two cloths that do not collide: %d intersections, %g m apart", (int)through_worst,
          through_gap);
}

/* ------------------------------------------------------------------------ */
/* (g) the contour condition                                                */
/* ------------------------------------------------------------------------ */

/* A flat U of quads on a 4 x 5 grid of unit spacing (particle i + 4 j at
 * (i, j, 0)): the base row of three quads, and one quad wide arms over
 * columns 0 and 2, three rows high. 9 quads, 18 triangles, all facing +z. */
enum { U_PARTICLES = 20, U_TRIANGLES = 18 };
static void u_shape(double *xyz, int32_t *tris)
{
    for (int j = 0; j < 5; ++j)
        for (int i = 0; i < 4; ++i) {
            double *p = xyz + 3 * (i + 4 * j);
            p[0] = i, p[1] = j, p[2] = 0.0;
        }
    int32_t t = 0;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 3; ++i) {
            if (j > 0 && i == 1) continue;
            int32_t a = i + 4 * j, b = a + 1, c = a + 5, d = a + 4;
            int32_t q[6] = {a, b, c, a, c, d};
            memcpy(tris + 3 * t, q, sizeof q);
            t += 2;
        }
}

static int disk(const int32_t *tris, int32_t count)
{
    int32_t list[64], vertices[192];
    wc_half_edge halves[192];
    for (int32_t k = 0; k < count; ++k) list[k] = k;
    return wci_region_is_disk(tris, list, count, halves, vertices);
}

/* Boundary half-edges of triangles tris[0 .. count) (brute force). */
static int32_t boundary_of(const int32_t *tris, int32_t count, wc_contour_segment *out)
{
    int32_t n = 0;
    for (int32_t t = 0; t < count; ++t)
        for (int k = 0; k < 3; ++k) {
            int32_t a = tris[3 * t + k], b = tris[3 * t + (k + 1) % 3], twin = 0;
            for (int32_t u = 0; u < count; ++u)
                for (int m = 0; m < 3; ++m) twin |= tris[3 * u + m] == b && tris[3 * u + (m + 1) % 3] == a;
            if (!twin) out[n].from = a, out[n].to = b, ++n;
        }
    return n;
}

static void test_contour(void)
{
    double xyz[3 * U_PARTICLES];
    int32_t tris[3 * U_TRIANGLES];
    u_shape(xyz, tris);
    /* Topology. */
    int32_t annulus[3 * 16], at = 0; /* 3 x 3 quads less the middle one */
    for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 3; ++i) {
            if (i == 1 && j == 1) continue;
            int32_t a = i + 4 * j, q[6] = {a, a + 1, a + 5, a, a + 5, a + 4};
            memcpy(annulus + at, q, sizeof q);
            at += 6;
        }
    int32_t bowtie[6] = {0, 1, 5, 5, 6, 10};      /* two triangles sharing particle 5 */
    int32_t flipped[6] = {0, 1, 5, 0, 4, 5};      /* the second turned over */
    int32_t fin[9] = {0, 1, 5, 1, 0, 4, 0, 1, 8}; /* edge 0-1 in three triangles */
    int32_t apart[6] = {0, 1, 5, 10, 11, 15};
    int u = disk(tris, U_TRIANGLES), a = disk(annulus, 16), b = disk(bowtie, 2), f = disk(flipped, 2),
        three = disk(fin, 3), two = disk(apart, 2), one = disk(tris, 1);
    printf("contour: disks: U %d, annulus %d, bowtie %d, flipped %d, three on an edge %d, apart %d, "
           "one triangle %d\n",
           u, a, b, f, three, two, one);
    CHECK(u && one, "a U of quads, or one triangle, is not taken for a disk");
    CHECK(!a && !b && !f && !three && !two, "a set that is no oriented disk is taken for one");

    /* Boundary motions, projected along z. */
    const double up[3] = {0.0, 0.0, 1.0};
    wc_contour_segment seg[64];
    double x[U_PARTICLES], y[U_PARTICLES], z[U_PARTICLES], nx[U_PARTICLES], ny[U_PARTICLES],
        nz[U_PARTICLES];
    for (int i = 0; i < U_PARTICLES; ++i) {
        x[i] = nx[i] = xyz[3 * i], y[i] = ny[i] = xyz[3 * i + 1], z[i] = nz[i] = xyz[3 * i + 2];
        nx[i] += 0.3, ny[i] -= 0.2, nz[i] += 0.5; /* a rigid shift */
    }
    int32_t n = boundary_of(tris, U_TRIANGLES, seg);
    int still = wci_contour_simple(seg, n, up, x, y, z, nx, ny, nz, 1.0);
    /* arm 0's top two rows slide over arm 2 (x + 2) */
    for (int i = 0; i < U_PARTICLES; ++i) nx[i] = x[i], ny[i] = y[i], nz[i] = z[i];
    for (int j = 2; j < 5; ++j)
        for (int i = 0; i < 2; ++i) nx[i + 4 * j] += 2.0;
    n = boundary_of(tris, U_TRIANGLES, seg);
    int slid = wci_contour_simple(seg, n, up, x, y, z, nx, ny, nz, 1.0);
    /* the same, stopped a quarter short of the other arm: apart all along */
    for (int j = 2; j < 5; ++j)
        for (int i = 0; i < 2; ++i) nx[i + 4 * j] -= 1.75;
    n = boundary_of(tris, U_TRIANGLES, seg);
    int short_of = wci_contour_simple(seg, n, up, x, y, z, nx, ny, nz, 1.0);
    /* one triangle whose corner passes over the opposite edge: its two
     * boundary edges at that corner's neighbour fold onto each other */
    double tx[3] = {0.0, 1.0, 0.5}, ty[3] = {0.0, 0.0, 1.0}, tz[3] = {0.0, 0.0, 0.0};
    double ux[3] = {0.0, 1.0, 0.5}, uy[3] = {0.0, 0.0, -1.0}, uz[3] = {0.0, 0.0, 0.0};
    int32_t one_tri[3] = {0, 1, 2};
    n = boundary_of(one_tri, 1, seg);
    int folded = wci_contour_simple(seg, n, up, tx, ty, tz, ux, uy, uz, 1.0);
    /* the U's base row (three quads, star-shaped round its centre) thrown
     * 10 quads sideways in one step, and the same with a corner pulled
     * across the opposite side */
    int32_t base[18];
    memcpy(base, tris, sizeof base);
    for (int i = 0; i < U_PARTICLES; ++i) nx[i] = x[i] + 10.0, ny[i] = y[i], nz[i] = z[i];
    n = boundary_of(base, 6, seg);
    int thrown = wci_contour_simple(seg, n, up, x, y, z, nx, ny, nz, 1.0);
    ny[4] = y[4] - 2.0; /* particle 4, the corner (0, 1), ends below the bottom side */
    n = boundary_of(base, 6, seg);
    int pulled = wci_contour_simple(seg, n, up, x, y, z, nx, ny, nz, 1.0);
    printf("contour: U shifted rigidly: simple %d; an arm slid over the other: %d; slid to a quarter "
           "short: %d; a triangle turned over in its plane: %d; a row of quads thrown 10 quads: %d, "
           "with a corner pulled across: %d\n",
           still, slid, short_of, folded, thrown, pulled);
    CHECK(still && short_of && thrown, "a boundary that stays simple is not taken for simple");
    CHECK(!slid && !folded && !pulled, "a boundary that crosses itself is taken for simple");
}

/* The U as a cloth (thickness 0.05, unit quads): arm 0's top two rows start
 * 0.3 above the plane and in one step slide over arm 2 and down to 0.3
 * below it, every triangle still facing up. */
static void test_in_plane_fold(void)
{
    double xyz[3 * U_PARTICLES];
    int32_t tris[3 * U_TRIANGLES];
    u_shape(xyz, tris);
    wc_world *w = new_world(1);
    wc_cloth *c = add_mesh(w, xyz, U_PARTICLES, tris, U_TRIANGLES, 0.05);
    if (!c) {
        wc_world_destroy(w);
        return;
    }
    for (int32_t i = 0; i < U_PARTICLES; ++i) {
        int arm = i % 4 < 2 && i / 4 >= 2;
        c->z[i] = arm ? 0.3 : 0.0;
        set_end(c, i, c->x[i] + (arm ? 2.0 : 0.0), c->y[i], arm ? -0.3 : 0.0);
    }
    clear_contacts(c);
    int32_t before = count_ccd_collisions(c, 0.0);
    wc_step_stats st;
    memset(&st, 0, sizeof st);
    wc_status s = wci_self_collide(c, 1.0 / 24, 1, &st);
    CHECK(s == WC_OK, "self_collide: %d", (int)s);
    int32_t after = count_ccd_collisions(c, 0.0);
    printf("in-plane fold: colliding pairs in the motion before %d, after %d; cloth contacts %d, "
           "fail-safe particles %d\n",
           (int)before, (int)after, (int)st.cloth_contacts, (int)st.failsafe_particles);
    CHECK(before > 0, "the arm's motion does not cross the other arm");
    CHECK(after == 0, "the arm passes through the other: %d colliding pairs left", (int)after);
    wc_world_destroy(w);
}

/* ------------------------------------------------------------------------ */
/* (h) knocked onto a collider's tip                                        */
/* ------------------------------------------------------------------------ */

static void test_knocked_onto_tip(void)
{
    wc_world_def wd = wc_world_def_default();
    wd.thread_count = 1;
    wd.gravity[2] = 0.0;
    wc_world *w = NULL;
    wc_message m;
    CHECK(wc_world_create(&wd, &w, &m) == WC_OK, "world: %s", m.text);
    if (!w) return;
    const double verts[15] = {0, 0, 0, -0.05, -0.05, -0.5, 0.05, -0.05, -0.5, 0.05, 0.05, -0.5,
                              -0.05, 0.05, -0.5};
    const int32_t tris[18] = {0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 4, 1, 1, 3, 2, 1, 4, 3};
    wc_mesh_collider_def d = wc_mesh_collider_def_default();
    d.vertices = verts, d.vertex_count = 5, d.triangles = tris, d.triangle_count = 6;
    d.thickness = 0.0;
    int32_t col;
    CHECK(wc_world_add_mesh_collider(w, &d, &col) == WC_OK, "%s", wc_world_last_error(w));
    /* two layers of 5 x 5 particles (0.2 m), the tip under the middle of a
     * triangle of the lower one */
    double xyz[3 * 50], vel[3 * 50];
    int32_t faces[3 * 64], nf = 0;
    const double h = 0.005, lower = h + 0.002, upper = lower + 0.02;
    for (int layer = 0; layer < 2; ++layer)
        for (int j = 0; j < 5; ++j)
            for (int i = 0; i < 5; ++i) {
                int k = 25 * layer + 5 * j + i;
                xyz[3 * k] = -0.1 + 0.05 * i + 0.013, xyz[3 * k + 1] = -0.1 + 0.05 * j + 0.017;
                xyz[3 * k + 2] = layer ? upper : lower;
                vel[3 * k] = vel[3 * k + 1] = 0.0, vel[3 * k + 2] = layer ? -20.0 : 0.0;
            }
    for (int layer = 0; layer < 2; ++layer)
        for (int j = 0; j < 4; ++j)
            for (int i = 0; i < 4; ++i) {
                int32_t a = 25 * layer + 5 * j + i, q[6] = {a, a + 1, a + 6, a, a + 6, a + 5};
                memcpy(faces + 3 * nf, q, sizeof q);
                nf += 2;
            }
    wc_mesh_cloth_def md = wc_mesh_cloth_def_default();
    md.vertices = xyz, md.vertex_count = 50, md.faces = faces, md.face_count = nf, md.face_size = 3;
    md.material.thickness = h;
    md.self_collision = 1;
    int32_t cl;
    CHECK(wc_world_add_mesh_cloth(w, &md, &cl) == WC_OK, "%s", wc_world_last_error(w));
    CHECK(wc_cloth_set_velocities(w, cl, vel, 50) == WC_OK, "%s", wc_world_last_error(w));
    int32_t worst_collider = 0, worst_cloth = 0;
    double lowest = INFINITY;
    for (int step = 0; step < 8; ++step) {
        CHECK(wc_world_step(w, 1.0 / 240) == WC_OK, "step %d: %s", step, wc_world_last_error(w));
        wc_intersection_counts k;
        CHECK(wc_world_count_intersections(w, &k) == WC_OK, "%s", wc_world_last_error(w));
        if (k.cloth_collider > worst_collider) worst_collider = k.cloth_collider;
        if (k.cloth_cloth > worst_cloth) worst_cloth = k.cloth_cloth;
        wc_cloth_get_positions(w, cl, xyz, 50);
        for (int i = 0; i < 25; ++i) lowest = fmin(lowest, xyz[3 * i + 2]);
    }
    printf("knocked onto a tip: lower layer's lowest particle %.4f m (started %.4f above the tip); "
           "worst intersections in a step: %d with the pyramid, %d between the layers\n",
           lowest, lower, (int)worst_collider, (int)worst_cloth);
    CHECK(lowest < 0.0, "the lower layer was not knocked down past the tip (lowest at %g m)", lowest);
    CHECK(worst_collider == 0 && worst_cloth == 0,
          "knocked onto a tip: %d cloth-pyramid and %d cloth-cloth intersections",
          (int)worst_collider, (int)worst_cloth);
    wc_world_destroy(w);
}

int main(void)
{
    test_vertex_face();
    test_pushed_particle_at_rest();
    test_edge_edge();
    test_pinned_face();
    test_failsafe();
    test_threads();
    test_fold();
    test_two_cloths();
    test_contour();
    test_in_plane_fold();
    test_knocked_onto_tip();
    return test_report("test_selfcollide");
}
