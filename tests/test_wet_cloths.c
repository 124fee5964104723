/* Wet adhesion between different cloths (the self-adhesion law, between
 * two cloths): cloths of one world that collide with each other
 * (collide_with_cloths) stick together when wet, by the self-adhesion law
 * applied across them (wetness.c, cloth_group.c):
 *   1. hold: a cloth lying on a second, pinned one, pulled off by 1 g, stays
 *      on it when wet and lifts off when dry; under gravity tilted 45 deg
 *      (steeper than the dry friction angle) the wet one stays and the dry
 *      one slides off;
 *   2. force at rest: the adhesion between the two at rest against the
 *      closed form 1/2 max(a_A w_A, a_B w_B) (area_A + area_B), with the two
 *      cloths' adhesion and wetness different, and equal and opposite;
 *   3. momentum: two free wet cloths touching, no gravity or drag: the total
 *      momentum stays zero to rounding while each cloth's does not;
 *   4. the same bits for 1, 2 and 4 threads;
 *   5. collide_with_cloths = 0 on one of them: no adhesion (it lifts off).
 * Every run counts intersections with the independent checker. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cloth_group.h"
#include "scenes.h"
#include "test_util.h"
#include "world.h"
#include "wetcloth.h"

/* Two equal square grids, B flat at z = 0 and A GAP above it (within the
 * 5 mm thickness, so they touch from the first step), vertex over vertex. */
#define N_SIDE 11
#define SIZE 0.5
#define GAP 0.0045
enum { PER = N_SIDE * N_SIDE };

typedef struct pair_def {
    double gravity[3];
    double wetness[2], adhesion[2]; /* A, B */
    int pin_lower, collide_upper, threads, count;
    double air_drag, size;
} pair_def;

static pair_def pair_def_default(void)
{
    pair_def d;
    memset(&d, 0, sizeof d);
    d.adhesion[0] = d.adhesion[1] = wc_material_default().adhesion;
    d.pin_lower = 1, d.collide_upper = 1, d.threads = 1, d.count = N_SIDE;
    d.air_drag = wc_material_default().air_drag;
    d.size = SIZE;
    return d;
}

static wc_world *make_pair(const pair_def *d)
{
    wc_world_def def = wc_world_def_default();
    /* measured with Verlet (its momentum is exact to rounding) */
    def.integrator = WC_INTEGRATOR_VERLET;
    def.thread_count = d->threads;
    memcpy(def.gravity, d->gravity, sizeof def.gravity);
    wc_world *w = NULL;
    wc_message msg;
    if (wc_world_create(&def, &w, &msg) != WC_OK) {
        fprintf(stderr, "wc_world_create: %s\n", msg.text);
        exit(1);
    }
    for (int k = 0; k < 2; ++k) {
        wc_grid_cloth_def g = wc_grid_cloth_def_default();
        g.count_u = g.count_v = d->count;
        g.size_u = g.size_v = d->size;
        g.center[2] = k == 0 ? GAP : 0.0;
        g.wetness = d->wetness[k];
        g.material.adhesion = d->adhesion[k];
        g.material.air_drag = d->air_drag;
        g.collide_with_cloths = k == 0 ? d->collide_upper : 1;
        int32_t id;
        if (wc_world_add_grid_cloth(w, &g, &id) != WC_OK || id != k) {
            fprintf(stderr, "wc_world_add_grid_cloth: %s\n", wc_world_last_error(w));
            exit(1);
        }
    }
    if (d->pin_lower) {
        int32_t n = d->count * d->count, *all = malloc((size_t)n * sizeof *all);
        for (int32_t i = 0; i < n; ++i) all[i] = i;
        CHECK(wc_cloth_pin(w, 1, all, n) == WC_OK, "%s", wc_world_last_error(w));
        free(all);
    }
    return w;
}

static void advance_or_fail(wc_world *w, int32_t substeps)
{
    wc_status s = wc_world_advance(w, 1.0 / 24, substeps);
    CHECK(s == WC_OK, "advance: %s", wc_world_last_error(w));
    if (s != WC_OK) exit(test_report("test_wet_cloths"));
}

/* Mean displacement of cloth A from where it started, and its highest z. */
typedef struct motion {
    double mean_shift[3], top;
    int intersections;
} motion;

static motion run_pair(const pair_def *d, int frames)
{
    wc_world *w = make_pair(d);
    double start[3 * PER], p[3 * PER];
    wc_cloth_get_positions(w, 0, start, PER);
    motion m;
    memset(&m, 0, sizeof m);
    for (int f = 0; f < frames; ++f) {
        advance_or_fail(w, 0);
        m.intersections += scene_intersections(w);
    }
    wc_cloth_get_positions(w, 0, p, PER);
    m.top = -INFINITY;
    for (int i = 0; i < PER; ++i) {
        for (int k = 0; k < 3; ++k) m.mean_shift[k] += (p[3 * i + k] - start[3 * i + k]) / PER;
        m.top = fmax(m.top, p[3 * i + 2]);
    }
    wc_world_destroy(w);
    return m;
}

/* ------------------------------------------------------------------------ */
/* 1. Hold                                                                  */
/* ------------------------------------------------------------------------ */

/* Upward pull: gravity reversed, 1 g on A (2.9 Pa on soaked default cotton,
 * a tenth of the 30 Pa adhesion), 0.5 s. Expected as for one cloth folded
 * onto itself (test_wet, self-adhesion): the wet A stays at the thickness
 * (5 mm), the dry A lifts off (it rises 1.2 m in 0.5 s of free flight less
 * what B's repulsion and drag take). Criteria: wet top at most 2 h (1 cm);
 * dry mean rise above 10 cm.
 * Slide: gravity tilted 45 deg about y, tan 45 = 1 above the dry friction
 * coefficient 0.5 (sqrt(0.5 * 0.5) between the two): the dry A slides down
 * the slope, 0.5 g (sin - 0.5 cos) t^2 = 0.43 m in 0.5 s without drag;
 * the wet A is pressed on by 30 Pa against 2.1 Pa along the slope and held.
 * Criteria: wet shift along the slope below 1 cm; dry above 0.2 m. */
static void hold(void)
{
    pair_def d = pair_def_default();
    d.gravity[2] = 9.81;
    d.wetness[0] = 1.0;
    motion wet_up = run_pair(&d, 12);
    d.wetness[0] = 0.0;
    motion dry_up = run_pair(&d, 12);
    d.collide_upper = 0, d.wetness[0] = 1.0;
    motion apart = run_pair(&d, 12);
    pair_def s = pair_def_default();
    s.gravity[0] = 9.81 * sqrt(0.5), s.gravity[2] = -9.81 * sqrt(0.5);
    s.wetness[0] = 1.0;
    motion wet_slide = run_pair(&s, 12);
    s.wetness[0] = 0.0;
    motion dry_slide = run_pair(&s, 12);
    printf("hold, 1 g pull off a pinned cloth for 0.5 s: wet top %.4f m (rise %.4f), dry rise %.4f m, "
           "wet without collide_with_cloths rise %.4f m; 45 deg slope: wet shift %.4f m, dry %.4f m; "
           "intersections %d %d %d %d %d\n",
           wet_up.top, wet_up.mean_shift[2], dry_up.mean_shift[2], apart.mean_shift[2],
           wet_slide.mean_shift[0], dry_slide.mean_shift[0], wet_up.intersections,
           dry_up.intersections, apart.intersections, wet_slide.intersections, dry_slide.intersections);
    CHECK(wet_up.top < 0.01, "the wet cloth lifted to %.4f m", wet_up.top);
    CHECK(dry_up.mean_shift[2] > 0.1, "the dry cloth stayed down (rise %.4f m)", dry_up.mean_shift[2]);
    /* A that does not collide with B passes through it freely: it is pulled
     * up as if B were not there, so it must rise as the dry one does */
    CHECK(apart.mean_shift[2] > 0.1, "a wet cloth that does not collide with cloths stuck (rise %.4f m)",
          apart.mean_shift[2]);
    CHECK(fabs(wet_slide.mean_shift[0]) < 0.01, "the wet cloth slid %.4f m", wet_slide.mean_shift[0]);
    CHECK(dry_slide.mean_shift[0] > 0.2, "the dry cloth held on the slope (%.4f m)", dry_slide.mean_shift[0]);
    CHECK(wet_up.intersections + dry_up.intersections + wet_slide.intersections +
                  dry_slide.intersections == 0,
          "intersections: %d %d %d %d", wet_up.intersections, dry_up.intersections,
          wet_slide.intersections, dry_slide.intersections);
}

/* ------------------------------------------------------------------------ */
/* 2. The force at rest                                                     */
/* ------------------------------------------------------------------------ */

/* The adhesion between the cloths that the next step applies: each cloth's
 * fx/fy/fz zeroed (they are scratch, recomputed at the start of every
 * step), the group's adhesion added, read out. */
static void group_forces(wc_world *w, double f[2][3], double *abs_sum)
{
    *abs_sum = 0.0;
    for (int k = 0; k < 2; ++k) {
        wc_cloth *c = w->cloths[k];
        size_t n = (size_t)c->particle_count;
        memset(c->fx, 0, n * sizeof *c->fx), memset(c->fy, 0, n * sizeof *c->fy);
        memset(c->fz, 0, n * sizeof *c->fz);
    }
    wci_cloth_group_adhesion(w->group, w->cloths);
    for (int k = 0; k < 2; ++k) {
        const wc_cloth *c = w->cloths[k];
        f[k][0] = f[k][1] = f[k][2] = 0.0;
        for (int32_t i = 0; i < c->particle_count; ++i) {
            f[k][0] += c->fx[i], f[k][1] += c->fy[i], f[k][2] += c->fz[i];
            *abs_sum += sqrt(c->fx[i] * c->fx[i] + c->fy[i] * c->fy[i] + c->fz[i] * c->fz[i]);
        }
    }
}

/* A (adhesion 30 Pa, w = 1: 30 Pa) rests on B (100 Pa, w = 0.2: 20 Pa)
 * under a 1 g pull off, held (1). Every vertex of either cloth lies over the
 * other's vertex, so each pairs with the faces round it and the pull on A
 * is, by the law in wetness.c, 1/2 max(30, 20) Pa (0.25 + 0.25) m^2 =
 * 7.5 N downward, and +7.5 N on B. Other combinations give other numbers:
 * each vertex's own adhesion times the larger wetness 16.25 N, the mean
 * adhesion 16.25 N. A is held flat over the flat, pinned B by symmetry, so
 * every pair's normal is vertical but for A's in-plane drift: measured,
 * the sideways force is 6e-8 of the pull, and the vertical part differs
 * from the pull by the square of that tilt; the tolerance is 1e-6 of the
 * pull. The sum of all the forces is zero to rounding: within 1e-14 of
 * their total (a few roundings of ~1e-16 per pair). */
static void force_at_rest(void)
{
    pair_def d = pair_def_default();
    d.gravity[2] = 9.81;
    d.wetness[0] = 1.0, d.wetness[1] = 0.2;
    d.adhesion[0] = 30.0, d.adhesion[1] = 100.0;
    wc_world *w = make_pair(&d);
    int bad = 0;
    for (int f = 0; f < 12; ++f) {
        advance_or_fail(w, 0);
        bad += scene_intersections(w);
    }
    double f[2][3], total;
    group_forces(w, f, &total);
    double expected = 0.5 * 30.0 * (SIZE * SIZE + SIZE * SIZE);
    double sum[3] = {f[0][0] + f[1][0], f[0][1] + f[1][1], f[0][2] + f[1][2]};
    double sum_len = sqrt(sum[0] * sum[0] + sum[1] * sum[1] + sum[2] * sum[2]);
    printf("force at rest after 0.5 s: on A (%.3g, %.3g, %.6f) N, on B (%.3g, %.3g, %.6f) N, closed form "
           "-/+%.4f N (relative error %.2e); sum %.3g N of total %.4f N; intersections %d\n",
           f[0][0], f[0][1], f[0][2], f[1][0], f[1][1], f[1][2], expected,
           fabs(-f[0][2] - expected) / expected, sum_len, total, bad);
    CHECK(fabs(-f[0][2] - expected) < 1e-6 * expected, "pull on A %.6f N, expected %.4f N", f[0][2],
          -expected);
    CHECK(fabs(f[1][2] - expected) < 1e-6 * expected, "pull on B %.6f N, expected %.4f N", f[1][2],
          expected);
    CHECK(sum_len <= 1e-14 * total, "the adhesion sums to %.3g N of %.3g N", sum_len, total);
    CHECK(bad == 0, "%d intersections", bad);
    wc_world_destroy(w);
}

/* ------------------------------------------------------------------------ */
/* 3. Momentum                                                              */
/* ------------------------------------------------------------------------ */

/* Total momentum sum m_i v_i of both cloths and the sum of |m_i v_i|. */
static void momentum(const wc_world *w, double p[3], double *abs_sum, double *per_cloth)
{
    p[0] = p[1] = p[2] = 0.0;
    *abs_sum = 0.0;
    for (int k = 0; k < 2; ++k) {
        const wc_cloth *c = w->cloths[k];
        int32_t n = c->particle_count;
        double *v = malloc(3 * (size_t)n * sizeof *v), q[3] = {0.0, 0.0, 0.0};
        wc_cloth_get_velocities(w, k, v, n);
        for (int32_t i = 0; i < n; ++i)
            for (int j = 0; j < 3; ++j) {
                q[j] += c->mass[i] * v[3 * i + j];
                *abs_sum += fabs(c->mass[i] * v[3 * i + j]);
            }
        for (int j = 0; j < 3; ++j) p[j] += q[j];
        per_cloth[k] = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
        free(v);
    }
}

/* No gravity, no air drag (the only force on a particle from outside the
 * pair), nothing pinned: A (w = 1) and B (w = 0.3) start at rest touching.
 * The adhesion pulls them together and the collision holds them apart;
 * both act in equal and opposite pairs (adhesion, Coulomb and wet friction,
 * the mass-weighted collision response), as do the links. So the total
 * momentum stays zero but for rounding: velocities come from positions of
 * ~0.25 m over steps of dt, so each carries an error of ~eps 0.25 / dt,
 * and the bound is the sum of m_i eps 0.25 / dt over the particles, times
 * 10 for the several roundings per step. Each cloth's momentum must be far
 * above that (else the check is vacuous). */
static void momentum_kept(void)
{
    pair_def d = pair_def_default();
    d.wetness[0] = 1.0, d.wetness[1] = 0.3;
    d.pin_lower = 0, d.air_drag = 0.0;
    wc_world *w = make_pair(&d);
    /* a kick upward on A's middle row: A rises there and is pulled back */
    double v[3 * PER];
    memset(v, 0, sizeof v);
    for (int i = 0; i < PER; ++i)
        if (i / N_SIDE == N_SIDE / 2) v[3 * i + 2] = 0.5;
    wc_cloth_set_velocities(w, 0, v, PER);
    double p0[3], abs0, each0[2];
    momentum(w, p0, &abs0, each0);
    double worst = 0.0, bound = 0.0, each_max = 0.0;
    int bad = 0, stuck_steps = 0;
    for (int f = 0; f < 6; ++f) {
        advance_or_fail(w, 0);
        bad += scene_intersections(w);
        double p[3], abs_sum, each[2];
        momentum(w, p, &abs_sum, each);
        double dp = sqrt((p[0] - p0[0]) * (p[0] - p0[0]) + (p[1] - p0[1]) * (p[1] - p0[1]) +
                         (p[2] - p0[2]) * (p[2] - p0[2]));
        worst = fmax(worst, dp);
        each_max = fmax(each_max, fmin(each[0], each[1]));
        double dt = 1.0 / 24 / wc_world_last_substeps(w), mass = 0.0;
        for (int k = 0; k < 2; ++k)
            for (int32_t i = 0; i < w->cloths[k]->particle_count; ++i) mass += w->cloths[k]->mass[i];
        bound = fmax(bound, 10.0 * mass * DBL_EPSILON * 0.25 / dt);
        stuck_steps += wc_world_get_stats(w).stuck_particles > 0;
    }
    printf("momentum, two free touching wet cloths, 0.25 s: total changed by at most %.3g kg m/s "
           "(rounding bound %.3g), each cloth's at least %.3g; frames with stuck particles %d of 6; "
           "intersections %d\n",
           worst, bound, each_max, stuck_steps, bad);
    CHECK(worst <= bound, "total momentum changed by %.3g kg m/s (bound %.3g)", worst, bound);
    CHECK(each_max > 1e6 * bound, "each cloth's momentum %.3g: the check is vacuous", each_max);
    CHECK(stuck_steps > 0, "the cloths never stuck");
    CHECK(bad == 0, "%d intersections", bad);
    wc_world_destroy(w);
}

/* ------------------------------------------------------------------------ */
/* 4. Threads                                                               */
/* ------------------------------------------------------------------------ */

/* Two 46 x 46 cloths of 2 m (2116 particles each, 4232 combined: above
 * WC_PARALLEL_MIN, so the combined pass's per-particle loops run in
 * parallel), both free and wet, no gravity, A kicked in a wave
 * v_z = 0.4 sin(9 x) cos(7 y) so parts of it leave B, are pulled back and
 * stick again: 100 steps at 0.9 of the stable step. Positions of both and
 * the stuck flags must be bitwise the same with 1, 2 and 4 threads. */
static uint64_t threads_run(int32_t threads, int *stuck, int *bad)
{
    enum { M = 46, NM = M * M };
    pair_def d = pair_def_default();
    d.wetness[0] = 1.0, d.wetness[1] = 0.5;
    d.pin_lower = 0, d.threads = threads, d.count = M, d.size = 2.0;
    wc_world *w = make_pair(&d);
    static double p[3 * NM], v[3 * NM];
    wc_cloth_get_positions(w, 0, p, NM);
    for (int i = 0; i < NM; ++i)
        v[3 * i] = v[3 * i + 1] = 0.0, v[3 * i + 2] = 0.4 * sin(9 * p[3 * i]) * cos(7 * p[3 * i + 1]);
    wc_cloth_set_velocities(w, 0, v, NM);
    *bad = 0;
    double dt = 0.9 * wc_world_stable_dt(w);
    for (int k = 0; k < 100; ++k) {
        wc_status s = wc_world_step(w, dt);
        CHECK(s == WC_OK, "step: %s", wc_world_last_error(w));
        if (k % 20 == 19) *bad += scene_intersections(w);
    }
    uint64_t h = scene_hash_positions(w, 0) ^ (scene_hash_positions(w, 1) * 31u);
    static uint8_t flags[2 * NM];
    wc_cloth_get_stuck(w, 0, flags, NM);
    wc_cloth_get_stuck(w, 1, flags + NM, NM);
    *stuck = 0;
    for (int i = 0; i < 2 * NM; ++i) {
        h = (h ^ flags[i]) * 1099511628211ull;
        *stuck += flags[i];
    }
    wc_world_destroy(w);
    return h;
}

static void thread_count(void)
{
    int stuck[3], bad[3];
    uint64_t h1 = threads_run(1, &stuck[0], &bad[0]), h2 = threads_run(2, &stuck[1], &bad[1]);
    uint64_t h4 = threads_run(4, &stuck[2], &bad[2]);
    printf("threads: two wet 46 x 46 cloths, A kicked off B, 100 steps: hashes %016llx %016llx %016llx "
           "(1, 2, 4 threads), %d stuck, intersections %d %d %d\n",
           (unsigned long long)h1, (unsigned long long)h2, (unsigned long long)h4, stuck[0], bad[0],
           bad[1], bad[2]);
    CHECK(stuck[0] > 500, "only %d stuck: the run does not exercise the adhesion", stuck[0]);
    CHECK(h1 == h2 && h1 == h4, "adhesion between cloths depends on the thread count");
    CHECK(bad[0] + bad[1] + bad[2] == 0, "intersections %d %d %d", bad[0], bad[1], bad[2]);
}

int main(void)
{
    hold();
    force_at_rest();
    momentum_kept();
    thread_count();
    return test_report("test_wet_cloths");
}
