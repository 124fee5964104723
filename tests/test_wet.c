/* Wet cloth (docs/wetness.md; thesis 2.3-2.4 and 3.2-3.7):
 *   1. a dry cloth (wetness 0) is bit for bit the plain model, whatever the
 *      wet parameters;
 *   2. wrap: the thesis scene, wet against dry (Fig. 3.2-3.4);
 *   3. spreading: the stuck area grows, levels off, is larger with stronger
 *      adhesion and smaller with stiffer bending (Fig. 3.5);
 *   4. slack: a stuck lower part stays when the pinned top moves sideways,
 *      a dry one slides (Fig. 3.6);
 *   5. fold: surplus cloth between two stuck regions rises into a fold
 *      (Fig. 3.7);
 *   6. the wetness API, wicking (conserves water) and drying (exp decay);
 *   7. wet mass and the stable step.
 * Every scene runs with one thread; the figures are printed. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "primitives.h"
#include "scenes.h"
#include "test_util.h"
#include "wetness.h"
#include "world.h"
#include "wetcloth.h"

static const double PI = 3.14159265358979323846;

static double seconds(void)
{
    return (double)clock() / CLOCKS_PER_SEC;
}

static wc_world *world_with_gravity(double gz)
{
    wc_world_def def = wc_world_def_default();
    def.integrator = WC_INTEGRATOR_VERLET; /* as scene_world (scenes.c) */
    def.thread_count = 1;
    def.gravity[2] = gz;
    return scene_world_from(&def);
}

static void advance_or_fail(wc_world *w, double frame, int32_t substeps)
{
    wc_status s = wc_world_advance(w, frame, substeps);
    CHECK(s == WC_OK, "advance: %s", wc_world_last_error(w));
    if (s != WC_OK) exit(test_report("test_wet"));
}

static int count_stuck(const wc_world *w, int32_t cloth)
{
    int32_t n = wc_cloth_particle_count(w, cloth);
    uint8_t *stuck = malloc((size_t)n);
    CHECK(wc_cloth_get_stuck(w, cloth, stuck, n) == WC_OK, "%s", wc_world_last_error(w));
    int count = 0;
    for (int32_t i = 0; i < n; ++i) count += stuck[i];
    free(stuck);
    return count;
}

/* ------------------------------------------------------------------------ */
/* 1. Dry is exactly the plain model                                        */
/* ------------------------------------------------------------------------ */

/* A 12 x 12 cloth (0.8 m) falls 0.1 m onto the thesis sphere and drapes for
 * 12 frames (contacts, collider features, friction all active). */
static uint64_t small_drop(const wc_material *m, double wetness)
{
    wc_world *w = scene_world(1);
    scene_add_thesis_sphere(w, 0.3);
    wc_grid_cloth_def g = wc_grid_cloth_def_default();
    g.count_u = g.count_v = 12;
    g.size_u = g.size_v = 0.8;
    g.center[2] = 0.4;
    g.material = *m;
    g.wetness = wetness;
    int32_t cl = scene_add_grid(w, &g);
    for (int f = 0; f < 12; ++f) advance_or_fail(w, 1.0 / 24, 0);
    CHECK(wc_world_get_stats(w).collider_contacts > 20, "the dry-check cloth barely touches (%d)",
          wc_world_get_stats(w).collider_contacts);
    uint64_t h = scene_hash_positions(w, cl);
    wc_world_destroy(w);
    return h;
}

/* Dry cloth (w = 0) must behave exactly as the plain cloth model.
 * The same drop with the default wet material, with every wet parameter
 * zeroed (adhesion 0, spread 0, wet_friction 1, wet_mass_gain 0,
 * wet_softening 0) and with all of them at extremes (wicking and drying on,
 * which run their update every step) must give bitwise the same positions.
 * The same cloth soaked must not (otherwise the check would be vacuous). */
static void dry_is_plain(void)
{
    wc_material wet = wc_material_default(), plain = wet, extreme = wet;
    plain.adhesion = 0.0, plain.spread = 0.0, plain.wet_friction = 1.0;
    plain.wet_mass_gain = 0.0, plain.wet_softening = 0.0;
    extreme.adhesion = 1e4, extreme.spread = 1.0, extreme.wet_friction = 0.0;
    extreme.wet_mass_gain = 10.0, extreme.wet_softening = 0.99;
    extreme.wicking = 0.1, extreme.drying = 10.0;
    uint64_t h_default = small_drop(&wet, 0.0), h_plain = small_drop(&plain, 0.0);
    uint64_t h_extreme = small_drop(&extreme, 0.0), h_soaked = small_drop(&wet, 1.0);
    printf("dry = plain: hashes default %016llx, zeroed %016llx, extreme %016llx; soaked %016llx\n",
           (unsigned long long)h_default, (unsigned long long)h_plain, (unsigned long long)h_extreme,
           (unsigned long long)h_soaked);
    CHECK(h_default == h_plain, "dry cloth with the default wet material differs from the plain model");
    CHECK(h_extreme == h_plain, "dry cloth with extreme wet parameters differs from the plain model");
    CHECK(h_soaked != h_plain, "the soaked cloth moves exactly like the dry one");
}

/* ------------------------------------------------------------------------ */
/* 2. Wrap (thesis Fig. 3.2-3.4)                                            */
/* ------------------------------------------------------------------------ */

typedef struct wrap_result {
    /* Contact hold, steps of frames 13-18 (settled; see wrap()): particle-
     * steps with the particle resting on the sphere, those in contact, and
     * stuck flags of resting particles that changed from the step before. */
    long resting, resting_in_contact, resting_stuck_flips, steps;
    int near;              /* particles within 1 cm of the sphere at the end */
    double edge_radius;    /* lower edge's mean distance from the z axis, mean over frames 25-48 */
    double edge_final;     /* the same at the last frame */
    int intersections;     /* summed over every frame */
    int stuck;
} wrap_result;

#define R_SPHERE 0.3
/* Resting on the sphere: within the contact distance (the default
 * thickness) plus half the band by which a wet contact may part before it
 * breaks (WC_WET_HOLD_BAND, 10 %): 5.25 mm from the faces. The feature pass
 * lifts resting particles up to ~0.15 mm beyond 5 mm, so these are on the
 * surface by any measure; particles bridging over the sphere's proud
 * vertices lie 6-23 mm off it. */
#define RESTING (0.005 * (1.0 + 0.5 * WC_WET_HOLD_BAND))

/* The thesis scene: a 20 x 20 grid cloth (1 m, default material) 0.6 m above
 * the 114-vertex sphere (radius 0.3), 48 frames at 24 fps. The lower edge is
 * the row j = 0, one of the four edges that hang down past the equator. */
static wrap_result wrap_run(double wetness)
{
    wc_world *w = scene_world(1);
    scene_add_thesis_sphere(w, R_SPHERE);
    wc_grid_cloth_def g = wc_grid_cloth_def_default();
    g.count_u = g.count_v = 20;
    g.center[2] = 0.6;
    g.wetness = wetness;
    int32_t cl = scene_add_grid(w, &g);
    wrap_result r;
    memset(&r, 0, sizeof r);
    double p[3 * 400], v[3 * 114], dist[400];
    int32_t t[3 * 224], nt;
    uint8_t kind[400], stuck[400], stuck_before[400];
    scene_uv_sphere(R_SPHERE, 16, 8, v, t, &nt);
    for (int f = 1; f <= 48; ++f) {
        if (f < 13 || f > 18) {
            advance_or_fail(w, 1.0 / 24, 0);
        } else {
            /* the same steps one by one (with a static collider and no pins
             * wc_world_step does what advance's substeps do) */
            int32_t substeps = wc_world_last_substeps(w);
            for (int32_t k = 0; k < substeps; ++k) {
                wc_status st = wc_world_step(w, 1.0 / 24 / substeps);
                CHECK(st == WC_OK, "step: %s", wc_world_last_error(w));
                wc_cloth_get_positions(w, cl, p, 400);
                wc_cloth_get_contacts(w, cl, kind, NULL, 400);
                wc_cloth_get_stuck(w, cl, stuck, 400);
                scene_distances_to_mesh(p, 400, v, t, nt, dist);
                for (int i = 0; i < 400; ++i) {
                    if (!(dist[i] < RESTING)) continue;
                    r.resting++;
                    r.resting_in_contact += kind[i] != WC_CONTACT_NONE;
                    if (r.steps) r.resting_stuck_flips += stuck[i] != stuck_before[i];
                }
                memcpy(stuck_before, stuck, sizeof stuck);
                r.steps++;
            }
        }
        r.intersections += scene_intersections(w);
        wc_cloth_get_positions(w, cl, p, 400);
        double edge = 0.0;
        for (int i = 0; i < 20; ++i) edge += hypot(p[3 * i], p[3 * i + 1]) / 20;
        if (f > 24) r.edge_radius += edge / 24;
        r.edge_final = edge;
    }
    r.near = scene_count_near_sphere(w, cl, 0.3, 0.01);
    r.stuck = count_stuck(w, cl);
    wc_world_destroy(w);
    return r;
}

/* 48 frames rather than the 96 of the first measurement (which gave 251 /
 * 162 near, edges 0.275 / 0.305 m): the wet cloth has settled by frame 12,
 * the dry one swings on, and 96 frames would double the test's time.
 * Measured (48 frames): wet 250 particles within 1 cm of the sphere, dry
 * 161 (ratio 1.55). Wet lower edge at mean radius 0.274 m (tucked under the
 * equator, hugging the lower hemisphere); the dry edge hangs straight down
 * from the equator and swings about 0.305 m = R + thickness with a period
 * of ~0.75 s, still between 0.292 and 0.316 m in the second second, so a
 * single frame can dip below R: the dry criterion uses the mean over the
 * second second (frames 25-48, 1.3 swings), 0.305 m.
 * Criteria:
 *  - wet near > 1.3 x dry near (a quarter below the measured 1.55);
 *  - dry mean edge radius > R (the edge stands off: it hangs straight down
 *    from the widest ring, whose vertices are at R and edge midpoints at
 *    R cos(pi/16) = 0.294, at the contact distance 0.005 outside it;
 *    measured 4.7 mm above R);
 *  - wet edge radius (mean and last frame) < R - 1.5 cm = 0.285: clearly
 *    inside the equator (measured 0.274, 2.6 cm inside);
 *  - no intersection at any frame in either.
 * Contact hold (adhesion acts "every step while in contact, so it
 * touches again next step"), measured over every step of frames 13-18, when
 * the wet cloth has settled: of the particle-steps with the particle resting
 * on the sphere (within RESTING of its faces, by brute force), the fraction
 * in contact, and how often a resting particle's stuck flag changes from one
 * step to the next. Before the hold band (wetness.c says why it is needed)
 * resting particles ended each contact step up to 0.15 mm beyond the
 * contact distance, missed the surface in the next step and touched again
 * in the one after: measured with this test, 82.0 % in contact and 8.78
 * stuck-flag changes per step (408 steps, ~108 resting particles). Measured
 * now: 100.0 % and 0.00 per step. Criteria: at least 99 %, and at most 1
 * change per step (an eighth of the flicker; a particle arriving or
 * leaving at the rim now and then is allowed). Particles bridging over the
 * proud vertices are marked in contact by the feature pass through their
 * triangle, whenever it pushes that triangle; they are not on the surface
 * and are not counted here. */
static void wrap(void)
{
    const double R = R_SPHERE;
    wrap_result dry = wrap_run(0.0), wet = wrap_run(1.0);
    printf("wrap: near (1 cm) dry %d wet %d (ratio %.2f); lower edge radius, mean of frames 25-48: "
           "dry %.4f wet %.4f m (last frame %.4f / %.4f); stuck at the end: wet %d; "
           "intersections dry %d wet %d\n",
           dry.near, wet.near, (double)wet.near / dry.near, dry.edge_radius, wet.edge_radius,
           dry.edge_final, wet.edge_final, wet.stuck, dry.intersections, wet.intersections);
    CHECK(wet.near > 1.3 * dry.near, "wet cloth not closer to the sphere: %d vs %d", wet.near, dry.near);
    CHECK(dry.edge_radius > R, "dry lower edge does not stand off: %.4f m", dry.edge_radius);
    CHECK(wet.edge_radius < R - 0.015 && wet.edge_final < R - 0.015,
          "wet lower edge does not wrap under the equator: %.4f m (last %.4f)", wet.edge_radius,
          wet.edge_final);
    CHECK(dry.intersections == 0 && wet.intersections == 0, "intersections: dry %d wet %d",
          dry.intersections, wet.intersections);
    double held = (double)wet.resting_in_contact / (double)wet.resting;
    double flips = (double)wet.resting_stuck_flips / (double)(wet.steps - 1);
    printf("wrap, contact hold over %ld steps of frames 13-18: resting particles (within %.2f mm) in "
           "contact %.4f of %ld particle-steps (dry %.4f of %ld); their stuck flags change %.2f times "
           "per step\n",
           wet.steps, 1e3 * RESTING, held, wet.resting,
           (double)dry.resting_in_contact / (double)dry.resting, dry.resting, flips);
    CHECK(wet.resting > 50 * wet.steps, "too few resting particles to judge (%ld particle-steps)", wet.resting);
    CHECK(held >= 0.99, "resting wet particles in contact in only %.4f of the steps", held);
    CHECK(flips <= 1.0, "stuck flags of resting particles change %.2f times per step", flips);
}

/* ------------------------------------------------------------------------ */
/* 3. Spreading (thesis Fig. 3.5)                                           */
/* ------------------------------------------------------------------------ */

#define SPREAD_FRAMES 72
/* The base run's stuck area grows without shrinking up to this frame, and
 * from 6 frames later on it is balancing (below). */
#define SPREAD_GROWTH 24

typedef struct spread_result {
    int count[SPREAD_FRAMES + 1]; /* stuck particles after each frame */
    int stats_mismatch;           /* frames where stats and get_stuck disagree */
    int intersections;
} spread_result;

/* No gravity: only adhesion and spreading bring cloth onto the surface. A
 * flat 21 x 21 cloth (1 m) touches the top of a smooth sphere (convex
 * collider, radius 0.3) at its centre: the centre particle and its
 * neighbours are within the contact distance at the start. Every other
 * particle gets there only by being pulled down by its stuck neighbours
 * (eq. 2.9), against bending (wrapping a flat sheet on a sphere also
 * compresses it, which the bend links resist). */
static spread_result spread_run(double adhesion, double bend)
{
    wc_world *w = world_with_gravity(0.0);
    wc_convex_collider_def d = wc_convex_collider_def_default();
    d.shape = WC_SHAPE_SPHERE;
    d.radius = 0.3;
    int32_t col;
    CHECK(wc_world_add_convex_collider(w, &d, &col) == WC_OK, "%s", wc_world_last_error(w));
    wc_grid_cloth_def g = wc_grid_cloth_def_default();
    g.count_u = g.count_v = 21;
    g.center[2] = 0.3 + 0.004;
    g.wetness = 1.0;
    g.material.adhesion = adhesion;
    g.material.bend_stiffness = bend;
    int32_t cl = scene_add_grid(w, &g);
    spread_result r;
    memset(&r, 0, sizeof r);
    for (int f = 1; f <= SPREAD_FRAMES; ++f) {
        advance_or_fail(w, 1.0 / 24, 0);
        r.count[f] = count_stuck(w, cl);
        r.stats_mismatch += r.count[f] != wc_world_get_stats(w).stuck_particles;
    }
    r.intersections = scene_intersections(w);
    wc_world_destroy(w);
    return r;
}

/* Mean stuck count over the last quarter (frames 55-72). */
static double late_mean(const spread_result *r)
{
    double sum = 0.0;
    for (int f = 55; f <= SPREAD_FRAMES; ++f) sum += r->count[f];
    return sum / (SPREAD_FRAMES - 54);
}

/* Measured (stuck particles of 441 after frames 6, 12, ..., 72):
 *   adhesion 40 Pa, bending 5e-2 N m:  25 25 45 105 193 177 177 177 177 177 177 177
 *   adhesion 80 Pa, bending 5e-2 N m:  61 209 265 265 ... 265
 *   adhesion 40 Pa, bending 1e-1 N m:  21 25 25 43 56 53 67 83 83 82 82 82
 *   adhesion 40 Pa, bending 1e-5 N m (the default): 297 441 441 ... 441
 * With the default bending adhesion wins everywhere: the whole cloth sticks
 * within 10 frames (and, lapping round the sphere, passes through itself:
 * self-collision is off). A balance needs bending of order 1e-2 N m at this
 * spacing (5 cm), so the other runs use a stiff sheet. There the cloth
 * sticks along the diagonals out to the corners, while between them four
 * folds stand up to 19 cm off the sphere along the axes.
 * Criteria, on the base run (40 Pa, 5e-2 N m):
 *   - it grows: the count never decreases from frame to frame up to frame
 *     24, and the final count is at least 4 x the count after the first
 *     frame (20 x measured);
 *   - it balances: from frame 30 on it stays within 10 % of the final count.
 *     The rim overshoots by a ring and flickers while it settles (one ring
 *     of this grid is 8 particles, 4.5 % of the final 177): 185 and 193
 *     alternate over frames 28-45, with the grip unbounded too;
 *   - it levels off: over the last quarter (frames 55-72) max - min is at
 *     most 5 % of the final count (0 measured);
 *   - it stops with at least 40 % of the cloth free (60 % measured), where
 *     the default bending sticks it all;
 * and between runs (means over the last quarter):
 *   - adhesion 80 Pa: at least 1.25 x the base area (1.50 x measured);
 *   - bending 1e-1 N m: at most half the base area (0.46 x measured; 0.27 x
 *     with the wet grip unbounded, material.wet_grip = 1e6);
 *   - bending 1e-5 N m: at least 95 % of the cloth (100 % measured).
 * Also: stats.stuck_particles equals the wc_cloth_get_stuck count after
 * every frame, and the stiff cloths do not pass through themselves. */
static void spreading(void)
{
    const int total = 21 * 21;
    spread_result base = spread_run(40.0, 5e-2);
    spread_result strong = spread_run(80.0, 5e-2);
    spread_result stiff = spread_run(40.0, 1e-1);
    spread_result soft = spread_run(40.0, 1e-5);
    const spread_result *runs[4] = {&base, &strong, &stiff, &soft};
    const char *names[4] = {"adhesion 40 Pa, bending 5e-2", "adhesion 80 Pa, bending 5e-2",
                            "adhesion 40 Pa, bending 1e-1", "adhesion 40 Pa, bending 1e-5"};
    for (int k = 0; k < 4; ++k) {
        printf("spreading (%s): stuck at frames 6..72:", names[k]);
        for (int f = 6; f <= SPREAD_FRAMES; f += 6) printf(" %d", runs[k]->count[f]);
        printf("; last-quarter mean %.1f of %d; intersections %d\n", late_mean(runs[k]), total,
               runs[k]->intersections);
        CHECK(runs[k]->stats_mismatch == 0, "%s: stats.stuck_particles differs from the stuck flags in %d frames",
              names[k], runs[k]->stats_mismatch);
        if (k < 3) CHECK(runs[k]->intersections == 0, "%s: %d intersections", names[k], runs[k]->intersections);
    }
    int final = base.count[SPREAD_FRAMES], lo = final, hi = final;
    for (int f = 2; f <= SPREAD_GROWTH; ++f)
        CHECK(base.count[f] >= base.count[f - 1], "stuck area shrank from %d to %d between frames %d and %d",
              base.count[f - 1], base.count[f], f - 1, f);
    for (int f = SPREAD_GROWTH + 6; f <= SPREAD_FRAMES; ++f)
        CHECK(abs(base.count[f] - final) <= 0.1 * final,
              "stuck area at frame %d (%d) not within 10 %% of its balance (%d)", f, base.count[f], final);
    for (int f = 55; f <= SPREAD_FRAMES; ++f) {
        lo = base.count[f] < lo ? base.count[f] : lo;
        hi = base.count[f] > hi ? base.count[f] : hi;
    }
    CHECK(final >= 4 * base.count[1], "stuck area did not grow: %d after frame 1, %d at the end",
          base.count[1], final);
    CHECK(hi - lo <= 0.05 * final, "stuck area still changing: %d .. %d over the last quarter", lo, hi);
    CHECK(final <= 0.6 * total, "the stuck area did not stop: %d of %d", final, total);
    CHECK(late_mean(&strong) >= 1.25 * late_mean(&base), "stronger adhesion: %.1f vs %.1f stuck",
          late_mean(&strong), late_mean(&base));
    CHECK(late_mean(&stiff) <= 0.5 * late_mean(&base), "stiffer bending: %.1f vs %.1f stuck",
          late_mean(&stiff), late_mean(&base));
    CHECK(late_mean(&soft) >= 0.95 * total, "default bending: only %.1f of %d stuck", late_mean(&soft), total);
}

/* ------------------------------------------------------------------------ */
/* 4. Slack (thesis Fig. 3.6)                                               */
/* ------------------------------------------------------------------------ */

typedef struct slack_result {
    double bottom_drift;  /* mean x drift of the bottom row over the move and after */
    int bottom_stuck_before, bottom_stuck_after, bottom_contact_before;
    int stuck_before, stuck_after;
    int intersections;
} slack_result;

/* A 16 x 16 cloth (1 m) lies on a wall leaning back 20 degrees from the
 * vertical (a 4 m plate; gravity presses the cloth on with sin 20 deg of
 * its weight, so even dry cloth touches it and has Coulomb friction). Its
 * top row is pinned; the pins are pulled 0.15 m off the wall over one
 * second, so the upper part hangs free and only the lower part lies on the
 * wall, and the cloth settles for one more second. Then the pins move
 * 0.15 m sideways over 0.5 s and the cloth settles for 1 s. */
static slack_result slack_run(double wetness)
{
    const int n = 16, count = 16 * 16;
    const double alpha = 20.0 * PI / 180.0, out = 0.15, D = 0.15;
    const double normal[3] = {0.0, cos(alpha), sin(alpha)};
    wc_world *w = scene_world(1);
    double c[3] = {0, 0, 0}, u[3] = {1, 0, 0}, v[3] = {0, -sin(alpha), cos(alpha)};
    scene_add_plate(w, c, u, v, 4.0, 0.0);
    wc_grid_cloth_def g = wc_grid_cloth_def_default();
    g.count_u = g.count_v = n;
    for (int k = 0; k < 3; ++k) g.center[k] = 0.004 * normal[k], g.axis_v[k] = v[k];
    g.wetness = wetness;
    int32_t cl = scene_add_grid(w, &g);
    int32_t top[16];
    for (int i = 0; i < n; ++i) top[i] = (n - 1) * n + i;
    CHECK(wc_cloth_pin(w, cl, top, n) == WC_OK, "%s", wc_world_last_error(w));
    double p[3 * 16 * 16], p0[3 * 16 * 16], base[3 * 16], target[3 * 16];
    wc_cloth_get_positions(w, cl, p, count);
    for (int i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k) base[3 * i + k] = p[3 * top[i] + k];
    for (int f = 0; f < 48; ++f) {
        double s = f < 24 ? (f + 1.0) / 24 : 1.0;
        for (int i = 0; i < n; ++i)
            for (int k = 0; k < 3; ++k) target[3 * i + k] = base[3 * i + k] + s * out * normal[k];
        wc_cloth_set_pin_targets(w, cl, target, n);
        advance_or_fail(w, 1.0 / 24, 0);
    }
    slack_result r;
    memset(&r, 0, sizeof r);
    uint8_t stuck[16 * 16], kind[16 * 16];
    wc_cloth_get_positions(w, cl, p0, count);
    wc_cloth_get_stuck(w, cl, stuck, count);
    wc_cloth_get_contacts(w, cl, kind, NULL, count);
    for (int i = 0; i < count; ++i) r.stuck_before += stuck[i];
    for (int i = 0; i < n; ++i) {
        r.bottom_stuck_before += stuck[i];
        r.bottom_contact_before += kind[i] == WC_CONTACT_COLLIDER;
    }
    for (int f = 0; f < 36; ++f) {
        double s = f < 12 ? (f + 1.0) / 12 : 1.0;
        for (int i = 0; i < n; ++i) {
            for (int k = 0; k < 3; ++k) target[3 * i + k] = base[3 * i + k] + out * normal[k];
            target[3 * i] += s * D;
        }
        wc_cloth_set_pin_targets(w, cl, target, n);
        advance_or_fail(w, 1.0 / 24, 0);
    }
    wc_cloth_get_positions(w, cl, p, count);
    wc_cloth_get_stuck(w, cl, stuck, count);
    for (int i = 0; i < count; ++i) r.stuck_after += stuck[i];
    for (int i = 0; i < n; ++i) {
        r.bottom_drift += (p[3 * i] - p0[3 * i]) / n / D;
        r.bottom_stuck_after += stuck[i];
    }
    r.intersections = scene_intersections(w);
    wc_world_destroy(w);
    return r;
}

/* Measured: the wet bottom row drifts 6 % of the pins' 0.15 m (it creeps
 * a little: the sheared cloth above pulls on it with more than adhesion and
 * friction hold, and wet friction only slows it); the dry bottom row follows
 * the pins, 102 % (it swings past and back). Criteria: wet < 20 %, dry
 * > 50 % of the pins' displacement; the wet bottom row is stuck before and
 * after the move, the dry one lies on the wall before it (so it slides, not
 * swings free); no intersections. */
static void slack(void)
{
    slack_result wet = slack_run(1.0), dry = slack_run(0.0);
    printf("slack: bottom row drift / pin displacement: wet %.3f, dry %.3f; wet stuck before %d "
           "(bottom row %d/16), after %d (bottom row %d/16); dry bottom row in contact before %d/16; "
           "intersections wet %d dry %d\n",
           wet.bottom_drift, dry.bottom_drift, wet.stuck_before, wet.bottom_stuck_before,
           wet.stuck_after, wet.bottom_stuck_after, dry.bottom_contact_before, wet.intersections,
           dry.intersections);
    CHECK(fabs(wet.bottom_drift) < 0.2, "the stuck lower edge moved %.3f of the pins' displacement",
          wet.bottom_drift);
    CHECK(dry.bottom_drift > 0.5, "the dry lower edge moved only %.3f of the pins' displacement",
          dry.bottom_drift);
    CHECK(wet.bottom_stuck_before == 16 && wet.bottom_stuck_after == 16,
          "wet bottom row stuck before %d, after %d of 16", wet.bottom_stuck_before, wet.bottom_stuck_after);
    CHECK(dry.bottom_contact_before == 16, "dry bottom row touches the wall with %d of 16",
          dry.bottom_contact_before);
    CHECK(wet.intersections == 0 && dry.intersections == 0, "intersections: wet %d dry %d",
          wet.intersections, dry.intersections);
}

/* ------------------------------------------------------------------------ */
/* 5. Fold (thesis Fig. 3.7)                                                */
/* ------------------------------------------------------------------------ */

typedef struct fold_result {
    double top;          /* highest particle at the end, m */
    double end_drift[2]; /* mean x drift of the outer 4 columns at each end */
    int stuck_ends;      /* stuck particles in those columns at the end */
    int intersections;
} fold_result;

/* A strip (21 x 5 particles, 1 m x 0.2 m) of stiff cloth (bending 5e-2 N m)
 * lies across two floor plates that meet under its middle. Its middle
 * 0.3 m starts in a low bump (2 cm, cosine-shaped): a perfectly flat sheet
 * pressed together in its plane cannot leave the plane. The plates slide
 * 0.1 m toward each other over 0.5 s and stop for 0.5 s, carrying the cloth
 * lying on them as far as it holds on. */
static fold_result fold_run(double wetness)
{
    const int nu = 21, nv = 5, count = 21 * 5;
    const double D = 0.1, size = 2.0;
    wc_world *w = scene_world(1);
    double u[3] = {1, 0, 0}, v[3] = {0, 1, 0};
    double centers[2][3] = {{-size / 2, 0, 0}, {size / 2, 0, 0}};
    int32_t plates[2];
    for (int k = 0; k < 2; ++k) plates[k] = scene_add_plate(w, centers[k], u, v, size, 0.0);
    wc_grid_cloth_def g = wc_grid_cloth_def_default();
    g.count_u = nu, g.count_v = nv;
    g.size_u = 1.0, g.size_v = 0.2;
    g.center[2] = 0.004;
    g.material.bend_stiffness = 5e-2;
    g.wetness = wetness;
    int32_t cl = scene_add_grid(w, &g);
    double p[3 * 21 * 5], p0[3 * 21 * 5];
    wc_cloth_get_positions(w, cl, p, count);
    for (int i = 0; i < count; ++i)
        if (fabs(p[3 * i]) < 0.15) p[3 * i + 2] += 0.02 * 0.5 * (1.0 + cos(PI * p[3 * i] / 0.15));
    CHECK(wc_cloth_set_positions(w, cl, p, count) == WC_OK, "%s", wc_world_last_error(w));
    memcpy(p0, p, sizeof p);
    for (int f = 0; f < 24; ++f) {
        double s = f < 12 ? (f + 1.0) / 12 : 1.0;
        for (int k = 0; k < 2; ++k) {
            double c[3] = {centers[k][0] + (k ? -s * D : s * D), 0, 0}, verts[12];
            scene_plate_vertices(c, u, v, size, verts);
            CHECK(wc_collider_set_vertices(w, plates[k], verts, 4) == WC_OK, "%s", wc_world_last_error(w));
        }
        advance_or_fail(w, 1.0 / 24, 0);
    }
    fold_result r;
    memset(&r, 0, sizeof r);
    uint8_t stuck[21 * 5];
    wc_cloth_get_positions(w, cl, p, count);
    wc_cloth_get_stuck(w, cl, stuck, count);
    r.top = -INFINITY;
    for (int i = 0; i < count; ++i) {
        int column = i % nu;
        r.top = fmax(r.top, p[3 * i + 2]);
        if (column < 4 || column >= nu - 4) {
            r.end_drift[column >= nu - 4] += (p[3 * i] - p0[3 * i]) / (4 * nv);
            r.stuck_ends += stuck[i];
        }
    }
    r.intersections = scene_intersections(w);
    wc_world_destroy(w);
    return r;
}

/* Measured: the wet ends ride with the plates (drift +-0.100 m, every
 * particle there stuck) and the surplus 0.2 m between them stands up in a
 * single fold 0.187 m high; the dry strip slips on the plates (it moves
 * 0.043 m as a whole, the friction from both plates nearly cancelling) and
 * stays flat, its highest particle at the contact distance, 5 mm.
 * Criteria: the wet fold is higher than 10 x the thickness (5 cm; a quarter
 * of the measured height), the dry strip no higher than 2 x the thickness;
 * the wet ends follow their plates within 5 % of 0.1 m and stay stuck; no
 * intersections.
 * With bending up to 2e-2 N m no fold forms (measured at 1e-5, 1e-4, 5e-4,
 * 1e-3, 3e-3, 1e-2, 2e-2: highest particle 5.0 mm; 5e-2 and 1e-1: 0.206
 * and 0.216 m): the spreading pull (eq. 2.9) zips the bump down onto the
 * floor within a frame, and the surplus is then taken up by compressing the
 * flat cloth in its plane (stretch links resist only tension; the bend
 * links' resistance to compression acts in the plane). docs/model.md
 * ("Wetness and bending") says why this needs a stiff sheet. */
static void fold(void)
{
    const double thickness = wc_material_default().thickness;
    fold_result wet = fold_run(1.0), dry = fold_run(0.0);
    printf("fold: highest particle wet %.4f m, dry %.4f m (thickness %.3f); wet ends drift %+.4f / "
           "%+.4f m (plates +-0.1), %d/40 stuck; dry ends drift %+.4f / %+.4f m; intersections wet %d "
           "dry %d\n",
           wet.top, dry.top, thickness, wet.end_drift[0], wet.end_drift[1], wet.stuck_ends,
           dry.end_drift[0], dry.end_drift[1], wet.intersections, dry.intersections);
    CHECK(wet.top > 10 * thickness, "no fold: the wet strip rises only to %.4f m", wet.top);
    CHECK(dry.top < 2 * thickness, "the dry strip rises to %.4f m", dry.top);
    CHECK(fabs(wet.end_drift[0] - 0.1) < 0.005 && fabs(wet.end_drift[1] + 0.1) < 0.005,
          "wet ends did not ride with the plates: %+.4f / %+.4f m", wet.end_drift[0], wet.end_drift[1]);
    CHECK(wet.stuck_ends == 40, "only %d of the 40 particles at the wet ends are stuck", wet.stuck_ends);
    CHECK(wet.intersections == 0 && dry.intersections == 0, "intersections: wet %d dry %d",
          wet.intersections, dry.intersections);
}

/* ------------------------------------------------------------------------ */
/* 5b. Wet friction at collider features                                    */
/* ------------------------------------------------------------------------ */

typedef struct spike_result {
    double speed;      /* mean x velocity of the cloth at the end, m/s */
    int face_contacts; /* particles within the contact distance of a face, summed over frames */
    int contacts;      /* particles marked in contact, summed over frames */
} spike_result;

/* A small cloth (5 x 5, 0.2 m) slides at 1 m/s over the tip of a tall, thin
 * pyramid (tip at the origin, base 0.1 m wide 0.5 m below): the only
 * contact is the collider's tip vertex inside a cloth triangle, which the
 * feature pass (collider_contacts.c) answers; the cloth's particles stay far
 * from the pyramid's faces. Soaked (w = 1), no adhesion (whose pull would
 * also raise the Coulomb friction), wet friction q as given; 0.1 s. */
static spike_result spike_run(double q)
{
    wc_world *w = scene_world(1);
    const double verts[15] = {0, 0, 0, -0.05, -0.05, -0.5, 0.05, -0.05, -0.5, 0.05, 0.05, -0.5,
                              -0.05, 0.05, -0.5};
    const int32_t tris[18] = {0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 4, 1, 1, 3, 2, 1, 4, 3};
    wc_mesh_collider_def d = wc_mesh_collider_def_default();
    d.vertices = verts, d.vertex_count = 5, d.triangles = tris, d.triangle_count = 6;
    int32_t col;
    CHECK(wc_world_add_mesh_collider(w, &d, &col) == WC_OK, "%s", wc_world_last_error(w));
    wc_grid_cloth_def g = wc_grid_cloth_def_default();
    g.count_u = g.count_v = 5;
    g.size_u = g.size_v = 0.2;
    g.center[0] = 0.01, g.center[1] = 0.013, g.center[2] = 0.004; /* tip inside a triangle */
    g.wetness = 1.0;
    g.material.adhesion = 0.0;
    g.material.wet_friction = q;
    int32_t cl = scene_add_grid(w, &g);
    double vel[3 * 25], p[3 * 25], dist[25];
    for (int i = 0; i < 25; ++i) vel[3 * i] = 1.0, vel[3 * i + 1] = 0.0, vel[3 * i + 2] = 0.0;
    wc_cloth_set_velocities(w, cl, vel, 25);
    spike_result r = {0.0, 0, 0};
    for (int f = 0; f < 12; ++f) {
        advance_or_fail(w, 1.0 / 120, 0);
        wc_cloth_get_positions(w, cl, p, 25);
        scene_distances_to_mesh(p, 25, verts, tris, 6, dist);
        for (int i = 0; i < 25; ++i) r.face_contacts += dist[i] < 1.01 * g.material.thickness;
        r.contacts += wc_world_get_stats(w).collider_contacts;
    }
    wc_cloth_get_velocities(w, cl, vel, 25);
    for (int i = 0; i < 25; ++i) r.speed += vel[3 * i] / 25;
    wc_world_destroy(w);
    return r;
}

/* Measured: with q = 1 (no wet friction) the cloth keeps 0.655 m/s (only
 * Coulomb at the tip); with the default q = 0.05 it is down to 0.154 m/s
 * (0.106 with the wet grip unbounded).
 * Before the feature pass had wet friction both kept 0.645 m/s, to the
 * bit. Criteria: no particle comes within the contact distance of a face
 * (the tip is the only contact), the tip touches (contacts at the end of
 * some frames), and the wet cloth keeps less than half the speed of the
 * slick one (measured 0.24 of it). */
static void feature_wet_friction(void)
{
    spike_result slick = spike_run(1.0), wet = spike_run(wc_material_default().wet_friction);
    printf("wet friction at a collider vertex: cloth speed after 0.1 s: q = 1: %.4f m/s, q = %.2f: "
           "%.4f m/s (from 1); particles near a face: %d / %d; contacts summed over frames: %d / %d\n",
           slick.speed, wc_material_default().wet_friction, wet.speed, slick.face_contacts,
           wet.face_contacts, slick.contacts, wet.contacts);
    CHECK(slick.face_contacts == 0 && wet.face_contacts == 0, "the cloth reached the pyramid's faces");
    CHECK(slick.contacts > 0 && wet.contacts > 0, "the tip does not touch the cloth");
    CHECK(wet.speed < 0.5 * slick.speed, "wet friction at the tip: %.4f vs %.4f m/s", wet.speed,
          slick.speed);
}

/* ------------------------------------------------------------------------ */
/* 5c. Self-adhesion                                                        */
/* ------------------------------------------------------------------------ */

typedef struct self_result {
    double top_mean, top_max; /* height of the upper layer's particles at the end, m */
    int64_t pairs;            /* adhesive pairs after the first frame */
    double force_sum[3];      /* sum of the self-adhesion forces then, N */
    double force_abs;         /* sum of their magnitudes (over particles), N */
    double upper_pull;        /* z force of self-adhesion on the upper layer, N */
    int intersections;
} self_result;

#define FOLD_NU 21
#define FOLD_NV 5

/* A strip (21 x 5 particles, 1 m x 0.2 m, self-collision on) folded onto
 * itself at its middle column: columns 0-10 lie flat at z = 0 and are
 * pinned, columns 11-20 lie back over them 4.5 mm higher (within the 5 mm
 * thickness, so the layers touch from the first step). The pull is gravity
 * reversed: 1 g upward on the upper layer, 2.9 Pa on the soaked cloth
 * (0.3 kg/m^2), a tenth of the default adhesion pressure (30 Pa). 0.5 s. */
static self_result self_run(double wetness)
{
    const double gap = 0.0045;
    wc_world *w = world_with_gravity(+9.81);
    wc_grid_cloth_def g = wc_grid_cloth_def_default();
    g.count_u = FOLD_NU, g.count_v = FOLD_NV;
    g.size_u = 1.0, g.size_v = 0.2;
    g.self_collision = 1;
    g.wetness = wetness;
    int32_t cl = scene_add_grid(w, &g);
    enum { N = FOLD_NU * FOLD_NV };
    double p[3 * N];
    int32_t pins[N], pin_count = 0;
    wc_cloth_get_positions(w, cl, p, N);
    for (int i = 0; i < N; ++i) {
        int column = i % FOLD_NU;
        double x = 0.05 * column;
        p[3 * i] = column <= 10 ? x - 0.5 : 0.5 - x;
        p[3 * i + 2] = column <= 10 ? 0.0 : gap;
        if (column <= 10) pins[pin_count++] = i;
    }
    CHECK(wc_cloth_set_positions(w, cl, p, N) == WC_OK, "%s", wc_world_last_error(w));
    CHECK(wc_cloth_pin(w, cl, pins, pin_count) == WC_OK, "%s", wc_world_last_error(w));
    self_result r;
    memset(&r, 0, sizeof r);
    for (int f = 0; f < 12; ++f) {
        advance_or_fail(w, 1.0 / 24, 0);
        r.intersections += scene_intersections(w);
        if (f == 0) {
            /* the self-adhesion forces the next step will apply */
            const wc_cloth *c = w->cloths[cl];
            double fx[N], fy[N], fz[N];
            memset(fx, 0, sizeof fx), memset(fy, 0, sizeof fy), memset(fz, 0, sizeof fz);
            wci_wet_self_adhesion(c, fx, fy, fz);
            r.pairs = c->adhesive_count;
            for (int i = 0; i < N; ++i) {
                r.force_sum[0] += fx[i], r.force_sum[1] += fy[i], r.force_sum[2] += fz[i];
                r.force_abs += sqrt(fx[i] * fx[i] + fy[i] * fy[i] + fz[i] * fz[i]);
                if (i % FOLD_NU > 10) r.upper_pull += fz[i];
            }
        }
    }
    wc_cloth_get_positions(w, cl, p, N);
    r.top_max = -INFINITY;
    for (int i = 0; i < N; ++i) {
        if (i % FOLD_NU <= 10) continue;
        r.top_mean += p[3 * i + 2] / (10 * FOLD_NV);
        r.top_max = fmax(r.top_max, p[3 * i + 2]);
    }
    wc_world_destroy(w);
    return r;
}

/* Measured: the soaked upper layer stays on the lower one (mean and highest
 * particle at 5.0 mm, the thickness); the dry one lifts off (mean 0.138 m,
 * highest 0.206 m after 0.5 s). After the first frame 456 pairs adhere
 * (each vertex of either layer touches the faces round the vertex under
 * it); their forces sum to 2.2e-16 N of 5.7 N in all (rounding); they pull
 * the upper layer down with 2.85 N, where half the adhesion times both
 * layers' touching areas (0.5 x 30 Pa x (0.095 + 0.105) m^2) is 2.9 N,
 * ten times the 0.29 N pull on the layer.
 * Criteria: wet upper layer at most 2 h (1 cm) high everywhere; dry mean
 * above 10 cm; the dry cloth forms no adhesive pairs; the force sum within
 * 1e-14 of the total (a few roundings per pair, ~1e-16 each); the pull on
 * the upper layer downward, 1.5-6 N (half to twice 2.9 N); no
 * intersections. */
static void self_adhesion(void)
{
    self_result wet = self_run(1.0), dry = self_run(0.0);
    printf("self-adhesion: upper layer height after 0.5 s of a 1 g pull: wet mean %.4f max %.4f m, "
           "dry mean %.4f max %.4f m; wet adhesive pairs %lld (dry %lld); force sum (%.3g, %.3g, %.3g) N "
           "of total %.4f N; pull on the upper layer %.4f N; intersections wet %d dry %d\n",
           wet.top_mean, wet.top_max, dry.top_mean, dry.top_max, (long long)wet.pairs,
           (long long)dry.pairs, wet.force_sum[0], wet.force_sum[1], wet.force_sum[2], wet.force_abs,
           wet.upper_pull, wet.intersections, dry.intersections);
    double sum = sqrt(wet.force_sum[0] * wet.force_sum[0] + wet.force_sum[1] * wet.force_sum[1] +
                      wet.force_sum[2] * wet.force_sum[2]);
    CHECK(wet.top_max < 0.01, "the wet upper layer lifted to %.4f m", wet.top_max);
    CHECK(dry.top_mean > 0.1, "the dry upper layer stayed down (mean %.4f m)", dry.top_mean);
    CHECK(wet.pairs > 0 && dry.pairs == 0, "adhesive pairs: wet %lld, dry %lld", (long long)wet.pairs,
          (long long)dry.pairs);
    CHECK(sum <= 1e-14 * wet.force_abs, "self-adhesion forces sum to %.3g N of %.3g N", sum, wet.force_abs);
    CHECK(wet.upper_pull < -1.5 && wet.upper_pull > -6.0, "pull on the upper layer %.4f N", wet.upper_pull);
    CHECK(wet.intersections == 0 && dry.intersections == 0, "intersections: wet %d dry %d",
          wet.intersections, dry.intersections);
}

/* Wet friction between layers: one cloth of two separate 6 x 6 squares
 * (0.25 m, quads), the lower pinned flat at z = 0, the upper 4.5 mm above it
 * (within the 5 mm thickness), both soaked so adhesion keeps them in
 * contact, self-collision on, gravity down. The upper square is sent
 * sliding at 0.3 m/s along x; its mean speed after 0.1 s with wet_friction
 * q = 1 and with the default q. Coulomb friction is off: with the adhesion
 * pressing the layers together it alone would stop the layer in
 * milliseconds, and the test is about wet friction. */
#define SLIDE_N 6
static double self_slide_run(double q)
{
    enum { PER = SLIDE_N * SLIDE_N, N = 2 * PER, CELLS = (SLIDE_N - 1) * (SLIDE_N - 1) };
    double p[3 * N], v[3 * N];
    int32_t faces[2 * 4 * CELLS], pins[PER], nf = 0;
    for (int layer = 0; layer < 2; ++layer)
        for (int j = 0; j < SLIDE_N; ++j)
            for (int i = 0; i < SLIDE_N; ++i) {
                int k = layer * PER + j * SLIDE_N + i;
                p[3 * k] = 0.05 * i, p[3 * k + 1] = 0.05 * j, p[3 * k + 2] = layer ? 0.0045 : 0.0;
                v[3 * k] = layer ? 0.3 : 0.0, v[3 * k + 1] = v[3 * k + 2] = 0.0;
                if (!layer) pins[k] = k;
                if (i + 1 < SLIDE_N && j + 1 < SLIDE_N) {
                    int32_t *f = faces + 4 * nf++;
                    f[0] = k, f[1] = k + 1, f[2] = k + 1 + SLIDE_N, f[3] = k + SLIDE_N;
                }
            }
    wc_world *w = world_with_gravity(-9.81);
    wc_mesh_cloth_def d = wc_mesh_cloth_def_default();
    d.vertices = p, d.vertex_count = N, d.faces = faces, d.face_count = nf, d.face_size = 4;
    d.self_collision = 1;
    d.wetness = 1.0;
    d.material.wet_friction = q;
    d.material.friction = 0.0; /* no Coulomb: what slows the layer is wet friction alone */
    int32_t cl = -1;
    CHECK(wc_world_add_mesh_cloth(w, &d, &cl) == WC_OK, "%s", wc_world_last_error(w));
    CHECK(wc_cloth_set_velocities(w, cl, v, N) == WC_OK, "%s", wc_world_last_error(w));
    CHECK(wc_cloth_pin(w, cl, pins, PER) == WC_OK, "%s", wc_world_last_error(w));
    int crossings = 0;
    for (int f = 0; f < 3; ++f) {
        advance_or_fail(w, 1.0 / 30, 0);
        crossings += scene_intersections(w);
    }
    CHECK(crossings == 0, "%d intersections", crossings);
    wc_cloth_get_velocities(w, cl, v, N);
    double speed = 0.0;
    for (int k = PER; k < N; ++k) speed += v[3 * k] / PER;
    wc_world_destroy(w);
    return speed;
}

/* Criterion: the soaked layers in sustained contact keep less than half the
 * sliding speed with the default q than with q = 1 (wet friction off), and
 * the slick run still slides (keeps over a third of its 0.3 m/s), so the
 * difference is the wet friction's. */
static void self_wet_friction(void)
{
    double slick = self_slide_run(1.0), wet = self_slide_run(wc_material_default().wet_friction);
    printf("wet friction between layers: upper layer speed after 0.1 s (from 0.3 m/s): q = 1: "
           "%.4f m/s, q = %.2f: %.4f m/s\n", slick, wc_material_default().wet_friction, wet);
    CHECK(slick > 0.1, "the slick layer did not slide: %.4f m/s", slick);
    CHECK(wet < 0.5 * slick, "wet friction between layers: %.4f vs %.4f m/s", wet, slick);
}

/* ------------------------------------------------------------------------ */
/* 5c. The wet grip                                                         */
/* ------------------------------------------------------------------------ */

/* A soaked 11 x 11 cloth rests on a floor plate under gravity tilted by 45
 * degrees, with no Coulomb friction and no adhesion, and full wet friction
 * (q = 0): only the wet grip holds it. Every particle's grip is the same
 * acceleration, a = wet_grip / (density (1 + wet_mass_gain)) (area and mass
 * are in proportion), so the closed form is that of a block on a slope with
 * a friction force capped at m a: the cloth holds when g sin 45 <= a, and
 * otherwise slides with acceleration g sin 45 - a. Mean velocity along the
 * slope after 0.5 s, from rest, at the world's default integrator and its
 * automatic steps. */
static double grip_slide_run(double wet_grip)
{
    const double tilt = 0.25 * 3.14159265358979323846;
    wc_world_def def = wc_world_def_default();
    def.thread_count = 1;
    def.gravity[0] = 9.81 * sin(tilt), def.gravity[1] = 0.0, def.gravity[2] = -9.81 * cos(tilt);
    wc_world *w = scene_world_from(&def);
    double c[3] = {0, 0, 0}, u[3] = {1, 0, 0}, v[3] = {0, 1, 0};
    scene_add_plate(w, c, u, v, 4.0, 0.0);
    wc_grid_cloth_def g = wc_grid_cloth_def_default();
    g.count_u = g.count_v = 11;
    g.size_u = g.size_v = 0.5;
    g.center[2] = 0.005; /* the contact distance: resting on the plate */
    g.wetness = 1.0;
    g.material.friction = 0.0;
    g.material.adhesion = 0.0;
    g.material.wet_friction = 0.0;
    g.material.wet_grip = wet_grip;
    int32_t cl = scene_add_grid(w, &g);
    for (int f = 0; f < 12; ++f) advance_or_fail(w, 1.0 / 24, 0);
    static double vel[3 * 121];
    wc_cloth_get_velocities(w, cl, vel, 121);
    double mean = 0.0;
    for (int i = 0; i < 121; ++i) mean += vel[3 * i] / 121;
    wc_world_destroy(w);
    return mean;
}

/* Grips of 1.5 and 3 Pa on soaked default cloth (0.3 kg/m^2) are 5 and 10
 * m/s^2 against g sin 45 = 6.94 m/s^2. Criteria: the weaker grip slides at
 * (6.94 - 5) 0.5 = 0.968 m/s within 2 % (0.962 measured; the first step of contact is not
 * yet sustained, so it takes no wet friction: 1/24 / steps of free slide,
 * under 1 % at the automatic step); the stronger one holds (under 1 mm/s);
 * without the grip bound (1e6 Pa) it holds too. */
static void wet_grip(void)
{
    const double slope = 9.81 * sin(0.25 * 3.14159265358979323846);
    const double per_area = 0.15 * 2.0; /* default density, soaked (gain 1) */
    double weak = grip_slide_run(1.5), strong = grip_slide_run(3.0), unbounded = grip_slide_run(1e6);
    double expect = (slope - 1.5 / per_area) * 0.5;
    printf("wet grip on a 45-degree slope after 0.5 s: grip 1.5 Pa %.4f m/s (closed form %.4f), "
           "3 Pa %.5f m/s, 1e6 Pa %.5f m/s\n", weak, expect, strong, unbounded);
    CHECK(fabs(weak - expect) <= 0.02 * expect, "weak grip slides at %.4f m/s, closed form %.4f",
          weak, expect);
    CHECK(fabs(strong) < 1e-3, "a grip above the pull did not hold: %.5f m/s", strong);
    CHECK(fabs(unbounded) < 1e-3, "an unbounded grip did not hold: %.5f m/s", unbounded);
}

/* ------------------------------------------------------------------------ */
/* 5d. Thread count                                                         */
/* ------------------------------------------------------------------------ */

/* A soaked 64 x 64 cloth (4096 particles: above the size at which the
 * per-particle loops, the contact hold among them, run in parallel) lies 4 mm above a
 * floor plate (within the contact distance) and is kicked upward in a wave,
 * v_z = 0.5 sin(7 x) cos(5 y) m/s, so parts of it leave the floor and come
 * back, keep or lose their held contacts: 100 steps at 0.9 of the stable
 * step. Positions, stuck flags and contacts must be bitwise the same with
 * 1, 2 and 4 threads. */
static uint64_t wet_threads_run(int32_t threads, int *stuck)
{
    wc_world *w = scene_world(threads);
    double c[3] = {0, 0, 0}, u[3] = {1, 0, 0}, v[3] = {0, 1, 0};
    scene_add_plate(w, c, u, v, 2.0, 0.0);
    wc_grid_cloth_def g = wc_grid_cloth_def_default();
    g.count_u = g.count_v = 64;
    g.center[2] = 0.004;
    g.wetness = 1.0;
    int32_t cl = scene_add_grid(w, &g);
    static double p[3 * 64 * 64], vel[3 * 64 * 64];
    wc_cloth_get_positions(w, cl, p, 64 * 64);
    for (int i = 0; i < 64 * 64; ++i)
        vel[3 * i] = vel[3 * i + 1] = 0.0, vel[3 * i + 2] = 0.5 * sin(7 * p[3 * i]) * cos(5 * p[3 * i + 1]);
    wc_cloth_set_velocities(w, cl, vel, 64 * 64);
    double dt = 0.9 * wc_world_stable_dt(w);
    for (int k = 0; k < 100; ++k) {
        wc_status st = wc_world_step(w, dt);
        CHECK(st == WC_OK, "step: %s", wc_world_last_error(w));
    }
    enum { N = 64 * 64 };
    static uint8_t flags[2 * N];
    wc_cloth_get_stuck(w, cl, flags, N);
    wc_cloth_get_contacts(w, cl, flags + N, NULL, N);
    uint64_t h = scene_hash_positions(w, cl);
    *stuck = 0;
    for (int i = 0; i < 2 * N; ++i) {
        h = (h ^ flags[i]) * 1099511628211ull;
        if (i < N) *stuck += flags[i];
    }
    wc_world_destroy(w);
    return h;
}

static void thread_count(void)
{
    int stuck[3];
    uint64_t h1 = wet_threads_run(1, &stuck[0]), h2 = wet_threads_run(2, &stuck[1]);
    uint64_t h4 = wet_threads_run(4, &stuck[2]);
    printf("threads: wet 64 x 64 kicked off a floor, 100 steps: hashes %016llx %016llx %016llx (1, 2, 4 "
           "threads), %d stuck\n", (unsigned long long)h1, (unsigned long long)h2, (unsigned long long)h4,
           stuck[0]);
    /* measured 3974: most of it stuck, the highest crests of the wave off */
    CHECK(stuck[0] > 1000 && stuck[0] < 4096, "%d of 4096 stuck: the run does not exercise the wet paths",
          stuck[0]);
    CHECK(h1 == h2 && h1 == h4, "wet results depend on the thread count");
}

/* ------------------------------------------------------------------------ */
/* 6. Wetness API, wicking, drying                                          */
/* ------------------------------------------------------------------------ */

/* Masses and the stable step, to see that a failed call changed nothing. */
static void masses(const wc_world *w, int32_t cl, double *out, int32_t n)
{
    wc_cloth_view view;
    CHECK(wc_cloth_get_view(w, cl, &view) == WC_OK, "%s", wc_world_last_error(w));
    memcpy(out, view.mass, sizeof(double) * (size_t)n);
}

static void wetness_api(void)
{
    wc_world *w = world_with_gravity(-9.81);
    wc_grid_cloth_def g = wc_grid_cloth_def_default();
    g.count_u = g.count_v = 8;
    int32_t cl = scene_add_grid(w, &g);
    enum { N = 64 };
    double map[N], got[N], mass_before[N], mass_after[N];
    for (int i = 0; i < N; ++i) map[i] = (double)((i * 37) % 64) / 63.0; /* 0 .. 1, both ends included */
    int round_trip = 1;
    CHECK(wc_cloth_set_wetness(w, cl, map, N) == WC_OK, "%s", wc_world_last_error(w));
    CHECK(wc_cloth_get_wetness(w, cl, got, N) == WC_OK, "%s", wc_world_last_error(w));
    round_trip &= memcmp(map, got, sizeof map) == 0;
    wc_cloth_view view;
    wc_cloth_get_view(w, cl, &view);
    round_trip &= memcmp(view.wetness, map, sizeof map) == 0;
    CHECK(wc_cloth_set_wetness_uniform(w, cl, 0.375) == WC_OK, "%s", wc_world_last_error(w));
    wc_cloth_get_wetness(w, cl, got, N);
    for (int i = 0; i < N; ++i) round_trip &= got[i] == 0.375;
    CHECK(round_trip, "wetness does not read back as set");

    /* Out of range: rejected, with the index named, and nothing changes. */
    wc_cloth_set_wetness(w, cl, map, N);
    masses(w, cl, mass_before, N);
    double dt_before = wc_cloth_stable_dt(w, cl);
    const double bad[3] = {-0.1, 1.5, NAN};
    int rejected = 0, named = 0, unchanged = 1;
    for (int k = 0; k < 3; ++k) {
        double attempt[N];
        memcpy(attempt, map, sizeof map);
        for (int i = 0; i < N; ++i) attempt[i] = 1.0 - attempt[i]; /* a valid change everywhere ... */
        attempt[7 + 20 * k] = bad[k];                                 /* ... but one bad value */
        char index[32];
        snprintf(index, sizeof index, "wetness[%d]", 7 + 20 * k);
        rejected += wc_cloth_set_wetness(w, cl, attempt, N) == WC_ERROR_INVALID_ARGUMENT;
        named += strstr(wc_world_last_error(w), index) != NULL;
        if (k == 0) printf("wetness API: rejected with \"%s\"\n", wc_world_last_error(w));
        rejected += wc_cloth_set_wetness_uniform(w, cl, bad[k]) == WC_ERROR_INVALID_ARGUMENT;
        named += strstr(wc_world_last_error(w), "wetness") != NULL;
        wc_cloth_get_wetness(w, cl, got, N);
        masses(w, cl, mass_after, N);
        unchanged &= memcmp(got, map, sizeof map) == 0 &&
                     memcmp(mass_before, mass_after, sizeof mass_before) == 0 &&
                     wc_cloth_stable_dt(w, cl) == dt_before;
    }
    CHECK(rejected == 6, "%d of 6 out-of-range calls rejected", rejected);
    CHECK(named == 6, "%d of 6 messages name the bad value's place", named);
    CHECK(unchanged, "a rejected call changed the wetness, masses or stable step");
    CHECK(wc_cloth_set_wetness(w, cl, map, N - 1) == WC_ERROR_INVALID_ARGUMENT, "wrong count accepted");
    CHECK(wc_cloth_set_wetness(w, cl, NULL, N) == WC_ERROR_INVALID_ARGUMENT, "NULL map accepted");
    CHECK(wc_cloth_get_wetness(w, cl, NULL, N) == WC_ERROR_INVALID_ARGUMENT, "NULL output accepted");
    CHECK(wc_cloth_set_wetness_uniform(w, 3, 0.5) == WC_ERROR_NOT_FOUND, "cloth 3 found");
    CHECK(wc_cloth_get_stuck(w, 3, NULL, N) != WC_OK, "stuck flags of cloth 3");

    /* Out of range in the description. */
    g.wetness = 1.5;
    int32_t other = -1;
    CHECK(wc_world_add_grid_cloth(w, &g, &other) == WC_ERROR_INVALID_ARGUMENT &&
              strstr(wc_world_last_error(w), "wetness") != NULL,
          "grid wetness 1.5 accepted or not named: %s", wc_world_last_error(w));
    g.wetness = NAN;
    CHECK(wc_world_add_grid_cloth(w, &g, &other) == WC_ERROR_INVALID_ARGUMENT, "grid wetness NaN accepted");
    CHECK(wc_world_cloth_count(w) == 1, "a rejected cloth was added");
    wc_world_destroy(w);
}

/* Wicking on an 11 x 11 grid (spacing 0.1 m) with D = 0.01 m^2/s, the
 * columns i < 5 soaked, the rest dry; no gravity, no colliders; 1 s.
 * The graph diffusion moves water along links in equal and opposite
 * amounts, so the plain sum of wetness is conserved up to rounding, ~1e-16
 * per step over ~10^3 steps: 1e-9 relative is generous (measured 7e-16).
 * Diffusion keeps each row's profile monotone and within [0, 1] (the
 * explicit substeps stay below the stability limit). The dry half (columns
 * 6-10) must gain a visible share: sqrt(D t) = 0.1 m is one spacing, and it
 * holds 3.94 of the 55 at the end; at least 0.5. Masses follow the wetness:
 * m = density * A * (1 + gain * w), within 1e-13 relative. */
static void wicking(void)
{
    wc_world *w = world_with_gravity(0.0);
    wc_grid_cloth_def g = wc_grid_cloth_def_default();
    g.count_u = g.count_v = 11;
    g.material.wicking = 0.01;
    int32_t cl = scene_add_grid(w, &g);
    enum { N = 121 };
    double map[N], got[N], dry_mass[N], total0 = 0.0;
    masses(w, cl, dry_mass, N);
    for (int i = 0; i < N; ++i) total0 += map[i] = i % 11 < 5 ? 1.0 : 0.0;
    wc_cloth_set_wetness(w, cl, map, N);
    for (int f = 0; f < 24; ++f) advance_or_fail(w, 1.0 / 24, 0);
    wc_cloth_get_wetness(w, cl, got, N);
    double total = 0.0, dry_half = 0.0, worst_mass = 0.0;
    int monotone = 1, in_range = 1;
    wc_cloth_view view;
    wc_cloth_get_view(w, cl, &view);
    for (int i = 0; i < N; ++i) {
        total += got[i];
        if (i % 11 > 5) dry_half += got[i];
        if (i % 11 > 0) monotone &= got[i] <= got[i - 1];
        in_range &= got[i] >= 0.0 && got[i] <= 1.0;
        double expect = dry_mass[i] * (1.0 + g.material.wet_mass_gain * got[i]);
        worst_mass = fmax(worst_mass, fabs(view.mass[i] / expect - 1.0));
    }
    printf("wicking: after %.3f s (%d steps) total wetness %.15g (was %.15g, change %.2g relative); "
           "the dry half (columns 6-10) holds %.4f; masses within %.2g of density*A*(1+gain*w)\n",
           wc_world_time(w), 24 * wc_world_last_substeps(w), total, total0, fabs(total / total0 - 1.0),
           dry_half, worst_mass);
    CHECK(fabs(total / total0 - 1.0) <= 1e-9, "wicking changed the total from %.17g to %.17g", total0, total);
    CHECK(dry_half > 0.5, "the dry half gained only %.4f", dry_half);
    CHECK(monotone && in_range, "wetness profile not monotone (%d) or out of range (%d)", monotone, in_range);
    CHECK(worst_mass <= 1e-13, "masses do not follow the wetness (%.3g)", worst_mass);
    wc_world_destroy(w);
}

/* Drying at 0.5 /s from w = 0.8: w(t) = 0.8 exp(-0.5 t). Each step
 * multiplies by exp(-rate dt) (exact for the ODE), so after n steps the
 * error is n roundings of ~1e-16 plus the rounding of the summed time: about
 * 1e-14 for the few hundred steps here (measured 1e-14); 1e-12 relative. */
static void drying(void)
{
    wc_world *w = world_with_gravity(-9.81);
    wc_grid_cloth_def g = wc_grid_cloth_def_default();
    g.count_u = g.count_v = 6;
    g.material.drying = 0.5;
    g.wetness = 0.8;
    int32_t cl = scene_add_grid(w, &g);
    double got[36], worst = 0.0;
    for (int f = 0; f < 24; ++f) {
        advance_or_fail(w, 1.0 / 24, 0);
        double expect = 0.8 * exp(-0.5 * wc_world_time(w));
        wc_cloth_get_wetness(w, cl, got, 36);
        for (int i = 0; i < 36; ++i) worst = fmax(worst, fabs(got[i] / expect - 1.0));
    }
    printf("drying: w = %.15g after %.6f s (%d steps), 0.8 exp(-0.5 t) = %.15g; worst relative error "
           "%.2g\n", got[0], wc_world_time(w), 24 * wc_world_last_substeps(w),
           0.8 * exp(-0.5 * wc_world_time(w)), worst);
    CHECK(worst <= 1e-12, "drying departs from exp(-rate t) by %.3g", worst);
    wc_world_destroy(w);
}

/* ------------------------------------------------------------------------ */
/* 7. Wet material                                                          */
/* ------------------------------------------------------------------------ */

/* Masses are density * A * (1 + gain * w): at w = 1 exactly (1 + gain) x
 * the dry ones, to rounding (1e-15). Every link constant is scaled by
 * (1 - softening * w) and every mass by (1 + gain * w), so the Gershgorin
 * bound on omega^2 scales by (1 - s) / (1 + g) and the stable step by
 * sqrt((1 + g) / (1 - s)) (the damping ratio does not change; the drag
 * limit, 2 density / drag = 15 s, does not bind): 1e-12 relative. */
static void wet_material(void)
{
    const double gains[2] = {1.0, 0.6}, softenings[2] = {0.3, 0.0};
    for (int k = 0; k < 2; ++k) {
        wc_world *w = world_with_gravity(-9.81);
        wc_grid_cloth_def g = wc_grid_cloth_def_default();
        g.count_u = g.count_v = 10;
        g.material.wet_mass_gain = gains[k];
        g.material.wet_softening = softenings[k];
        int32_t dry = scene_add_grid(w, &g);
        g.wetness = 1.0;
        int32_t wet = scene_add_grid(w, &g);
        double m_dry[100], m_wet[100], worst = 0.0;
        masses(w, dry, m_dry, 100);
        masses(w, wet, m_wet, 100);
        for (int i = 0; i < 100; ++i) worst = fmax(worst, fabs(m_wet[i] / m_dry[i] / (1.0 + gains[k]) - 1.0));
        double ratio = wc_cloth_stable_dt(w, wet) / wc_cloth_stable_dt(w, dry);
        double expect = sqrt((1.0 + gains[k]) / (1.0 - softenings[k]));
        /* the dry cloth soaked halfway afterwards */
        wc_cloth_set_wetness_uniform(w, dry, 0.5);
        double m_half[100], worst_half = 0.0;
        masses(w, dry, m_half, 100);
        for (int i = 0; i < 100; ++i)
            worst_half = fmax(worst_half, fabs(m_half[i] / (m_wet[i] / (1.0 + gains[k])) / (1.0 + 0.5 * gains[k]) - 1.0));
        double ratio_half = wc_cloth_stable_dt(w, dry) / (wc_cloth_stable_dt(w, wet) / expect);
        double expect_half = sqrt((1.0 + 0.5 * gains[k]) / (1.0 - 0.5 * softenings[k]));
        printf("wet material (gain %.1f, softening %.1f): mass ratio error %.2g; stable dt wet/dry %.15f "
               "(expected %.15f); at w = 0.5: mass error %.2g, dt ratio %.15f (expected %.15f); world "
               "stable dt = smallest: %s\n",
               gains[k], softenings[k], worst, ratio, expect, worst_half, ratio_half, expect_half,
               wc_world_stable_dt(w) == fmin(wc_cloth_stable_dt(w, dry), wc_cloth_stable_dt(w, wet)) ? "yes" : "no");
        CHECK(worst <= 1e-15, "wet masses off by %.3g relative", worst);
        CHECK(fabs(ratio / expect - 1.0) <= 1e-12, "stable dt ratio %.17g, expected %.17g", ratio, expect);
        CHECK(worst_half <= 1e-15, "half-wet masses off by %.3g relative", worst_half);
        CHECK(fabs(ratio_half / expect_half - 1.0) <= 1e-12, "half-wet dt ratio %.17g, expected %.17g",
              ratio_half, expect_half);
        CHECK(wc_world_stable_dt(w) == fmin(wc_cloth_stable_dt(w, dry), wc_cloth_stable_dt(w, wet)),
              "world stable dt is not the smallest cloth's");
        wc_world_destroy(w);
    }
}

int main(void)
{
    double t0 = seconds();
    wetness_api();
    wicking();
    drying();
    wet_material();
    printf("(%.1f s) ", seconds() - t0);
    dry_is_plain();
    printf("(%.1f s) ", seconds() - t0);
    spreading();
    printf("(%.1f s) ", seconds() - t0);
    slack();
    printf("(%.1f s) ", seconds() - t0);
    fold();
    feature_wet_friction();
    self_adhesion();
    self_wet_friction();
    wet_grip();
    thread_count();
    printf("(%.1f s) ", seconds() - t0);
    wrap();
    printf("(%.1f s)\n", seconds() - t0);
    return test_report("test_wet");
}
