/* Determinism: the same input gives bitwise the same output for
 * any number of threads, and for repeated runs.
 *
 * Scene: a 64 x 64 cloth (4096 particles: above WC_PARALLEL_MIN, so the
 * per-particle loops run in parallel too, not only the ~16k-link loops),
 * crumpled by a random perturbation from a fixed seed so that many bend
 * links are compressed, the two top corners pinned, default material
 * (damping and drag on), 500 steps at half the stable step. A hash
 * (64-bit FNV-1a) of the bytes of all positions and velocities is compared.
 *
 * Then the same with the applied forces on (applied.c): an air velocity
 * and an external force density that differ from particle to particle,
 * and one particle in seven soft-pinned with its own stiffness, for each
 * integrator (Verlet 500 steps, XPBD and the implicit one 40). */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "test_util.h"
#include "wetcloth.h"

#define N_SIDE 64
#define STEPS 500

static uint64_t fnv1a(uint64_t h, const void *data, size_t size)
{
    const unsigned char *p = data;
    for (size_t i = 0; i < size; ++i) {
        h ^= p[i];
        h *= 1099511628211ULL;
    }
    return h;
}

/* Small fixed generator (xorshift64*), so the start does not depend on the
 * C library's rand(). Uniform in [-1, 1). */
static double next_uniform(uint64_t *state)
{
    *state ^= *state >> 12;
    *state ^= *state << 25;
    *state ^= *state >> 27;
    uint64_t r = *state * 2685821657736338717ULL;
    return (double)(r >> 11) / 9007199254740992.0 * 2.0 - 1.0;
}

typedef struct run_result {
    uint64_t hash;
    int32_t compressed_bend; /* bend links shorter than rest at the start */
    double bend_energy;
} run_result;

/* Wind, a force field and soft pins, all varying over the cloth. */
static void apply_forces(wc_world *w, int32_t id, int32_t n)
{
    double *u = malloc(3 * (size_t)n * sizeof *u), *p = malloc(3 * (size_t)n * sizeof *p);
    int32_t *idx = malloc((size_t)n * sizeof *idx);
    double *stiffness = malloc((size_t)n * sizeof *stiffness);
    int32_t soft = 0;
    for (int32_t i = 0; i < n; ++i) {
        u[3 * i] = 1.0 + 0.5 * sin(0.1 * i), u[3 * i + 1] = cos(0.07 * i), u[3 * i + 2] = 0.2;
        p[3 * i] = 0.3 * cos(0.05 * i), p[3 * i + 1] = -0.2, p[3 * i + 2] = 0.4 * sin(0.03 * i);
        /* the hard-pinned corners, 4032 and 4095, are multiples of 7 */
        if (i % 7 == 3) idx[soft] = i, stiffness[soft++] = 20.0 + (i % 13);
    }
    CHECK(wc_cloth_set_air_velocity(w, id, u, n) == WC_OK, "air: %s", wc_world_last_error(w));
    CHECK(wc_cloth_set_external_forces(w, id, p, n) == WC_OK, "forces: %s", wc_world_last_error(w));
    CHECK(wc_cloth_pin_soft(w, id, idx, stiffness, soft) == WC_OK, "pin_soft: %s",
          wc_world_last_error(w));
    free(u), free(p), free(idx), free(stiffness);
}

static run_result run_with(int32_t threads, uint64_t seed, wc_integrator integrator, int applied,
                           int steps)
{
    run_result r = {14695981039346656037ULL, 0, 0.0};
    wc_world_def wd = wc_world_def_default();
    wd.thread_count = threads;
    wd.adapt_threads = 0; /* exactly this many (test_thread_tuner: changing counts) */
    wd.integrator = integrator;
    wc_world *w = NULL;
    wc_message msg;
    if (wc_world_create(&wd, &w, &msg) != WC_OK) {
        CHECK(0, "world: %s", msg.text);
        return r;
    }
    wc_grid_cloth_def def = wc_grid_cloth_def_default();
    def.count_u = def.count_v = N_SIDE;
    int32_t id = -1;
    CHECK(wc_world_add_grid_cloth(w, &def, &id) == WC_OK, "grid: %s", wc_world_last_error(w));
    int32_t n = N_SIDE * N_SIDE;
    double *x = malloc(3 * (size_t)n * sizeof *x), *v = malloc(3 * (size_t)n * sizeof *v);
    wc_cloth_get_positions(w, id, x, n);
    /* Crumple: each coordinate moved by up to 0.4 of the spacing. */
    const double spacing = 1.0 / (N_SIDE - 1);
    uint64_t state = seed;
    for (int32_t k = 0; k < 3 * n; ++k) x[k] += 0.4 * spacing * next_uniform(&state);
    CHECK(wc_cloth_set_positions(w, id, x, n) == WC_OK, "set_positions: %s", wc_world_last_error(w));

    /* Bend links compressed at the start (so the buckling path is used). */
    int32_t nb = wc_cloth_link_count(w, id, WC_LINK_BEND);
    int32_t *pairs = malloc(2 * (size_t)nb * sizeof *pairs);
    double *rest = malloc((size_t)nb * sizeof *rest);
    wc_cloth_get_links(w, id, WC_LINK_BEND, pairs, rest, nb);
    for (int32_t e = 0; e < nb; ++e) {
        const double *p = x + 3 * (size_t)pairs[2 * e], *q = x + 3 * (size_t)pairs[2 * e + 1];
        double d = sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) +
                        (p[2] - q[2]) * (p[2] - q[2]));
        r.compressed_bend += d < rest[e];
    }
    wc_energy e;
    wc_cloth_get_energy(w, id, &e);
    r.bend_energy = e.bend;

    int32_t pins[2] = {(N_SIDE - 1) * N_SIDE, N_SIDE * N_SIDE - 1};
    CHECK(wc_cloth_pin(w, id, pins, 2) == WC_OK, "pin: %s", wc_world_last_error(w));
    if (applied) apply_forces(w, id, n);
    const double dt = 0.5 * wc_world_stable_dt(w);
    for (int s = 0; s < steps; ++s)
        if (wc_world_step(w, dt) != WC_OK) {
            CHECK(0, "threads %d, step %d: %s", threads, s, wc_world_last_error(w));
            break;
        }
    wc_cloth_get_positions(w, id, x, n);
    wc_cloth_get_velocities(w, id, v, n);
    int finite = 1;
    for (int32_t k = 0; k < 3 * n; ++k) finite &= isfinite(x[k]) && isfinite(v[k]);
    CHECK(finite, "threads %d: non-finite state", threads);
    r.hash = fnv1a(r.hash, x, 3 * (size_t)n * sizeof *x);
    r.hash = fnv1a(r.hash, v, 3 * (size_t)n * sizeof *v);
    free(pairs);
    free(rest);
    free(x);
    free(v);
    wc_world_destroy(w);
    return r;
}

static run_result run(int32_t threads, uint64_t seed)
{
    return run_with(threads, seed, WC_INTEGRATOR_VERLET, 0, STEPS);
}

/* The applied forces for one integrator: the same hash for 1, 2 and 4
 * threads, and not the hash without them. */
static void applied_forces(wc_integrator integrator, const char *name, int steps, uint64_t seed)
{
    run_result plain = run_with(1, seed, integrator, 0, steps);
    run_result one = run_with(1, seed, integrator, 1, steps);
    printf("applied forces, %s, %d steps: threads 1: hash %016llx (without them %016llx)", name,
           steps, (unsigned long long)one.hash, (unsigned long long)plain.hash);
    CHECK(one.hash != plain.hash, "%s: the applied forces changed nothing", name);
    int32_t counts[2] = {2, 4};
    for (int i = 0; i < 2; ++i) {
        run_result r = run_with(counts[i], seed, integrator, 1, steps);
        printf(", threads %d: %016llx", counts[i], (unsigned long long)r.hash);
        CHECK(r.hash == one.hash, "%s, applied forces, threads %d: hash %016llx differs from %016llx",
              name, counts[i], (unsigned long long)r.hash, (unsigned long long)one.hash);
    }
    printf("\n");
}

int main(void)
{
    const uint64_t seed = 0x5eed1234abcdULL;
    run_result one = run(1, seed);
    printf("threads 1: hash %016llx (%d of the bend links compressed at the start, bend energy "
           "%.3e J)\n",
           (unsigned long long)one.hash, one.compressed_bend, one.bend_energy);
    CHECK(one.compressed_bend > 1000 && one.bend_energy > 0.0,
          "the start is not crumpled enough to exercise the bend links (%d compressed)",
          one.compressed_bend);
    int32_t counts[3] = {2, 4, 1};
    for (int i = 0; i < 3; ++i) {
        run_result r = run(counts[i], seed);
        printf("threads %d: hash %016llx%s\n", counts[i], (unsigned long long)r.hash,
               counts[i] == 1 ? " (repeat run)" : "");
        CHECK(r.hash == one.hash, "threads %d: hash %016llx differs from %016llx", counts[i],
              (unsigned long long)r.hash, (unsigned long long)one.hash);
    }
    /* The hash does see the state: another seed gives another hash. */
    run_result other = run(1, seed + 1);
    printf("other seed: hash %016llx\n", (unsigned long long)other.hash);
    CHECK(other.hash != one.hash, "hash insensitive to the start");
    applied_forces(WC_INTEGRATOR_VERLET, "verlet", STEPS, seed);
    applied_forces(WC_INTEGRATOR_XPBD, "xpbd", 40, seed);
    applied_forces(WC_INTEGRATOR_IMPLICIT, "implicit", 40, seed);
    return test_report("test_determinism");
}
