/* Core benchmark: particle-steps per second of a crumpled cloth without
 * collisions, at 1 thread and at N threads, measured side by side in one run.
 *
 *   build/tools/bench_core [size=256] [steps=200] [threads=2] [repeats=3]
 *
 * The cloth starts shrunk to 70 % in its plane with random out-of-plane
 * noise (fixed seed), so every bend link is compressed and the buckling
 * force (the costly one: an inverse sinc per link) is active everywhere. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "bench_util.h"
#include "wetcloth.h"

static uint64_t rng_state = 0x9E3779B97F4A7C15ull;
static double uniform(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return (double)(rng_state >> 11) / 9007199254740992.0;
}

/* Seconds for `steps` steps of a size x size crumpled cloth on `threads`. */
static double run(int size, int steps, int threads, double *stable_dt, int32_t *bend_links)
{
    wc_world_def wd = wc_world_def_default();
    wd.thread_count = threads;
    wd.adapt_threads = 0; /* measured at exactly this count */
    wc_world *w;
    wc_message m;
    bench_check(wc_world_create(&wd, &w, &m), NULL, m.text);
    wc_grid_cloth_def g = wc_grid_cloth_def_default();
    g.count_u = g.count_v = size;
    int32_t c;
    bench_check(wc_world_add_grid_cloth(w, &g, &c), w, "add_grid_cloth");
    int32_t n = wc_cloth_particle_count(w, c);
    double *xyz = malloc(3 * sizeof(double) * (size_t)n);
    bench_check(wc_cloth_get_positions(w, c, xyz, n), w, "get_positions");
    double h = 1.0 / (size - 1);
    rng_state = 0x9E3779B97F4A7C15ull;
    for (int32_t i = 0; i < n; ++i) {
        xyz[3 * i] *= 0.7;
        xyz[3 * i + 1] *= 0.7;
        xyz[3 * i + 2] = 0.3 * h * (uniform() - 0.5);
    }
    bench_check(wc_cloth_set_positions(w, c, xyz, n), w, "set_positions");
    free(xyz);
    *stable_dt = wc_world_stable_dt(w);
    *bend_links = wc_cloth_link_count(w, c, WC_LINK_BEND);
    double dt = 0.9 * *stable_dt;
    bench_check(wc_world_step(w, dt), w, "warm-up step");
    double t0 = bench_now();
    for (int s = 0; s < steps; ++s) bench_check(wc_world_step(w, dt), w, "step");
    double t1 = bench_now();
    wc_world_destroy(w);
    return t1 - t0;
}

static double best_rate(int size, int steps, int threads, int repeats, double *stable_dt,
                        int32_t *bend_links)
{
    double best = 0.0;
    for (int r = 0; r < repeats; ++r) {
        double seconds = run(size, steps, threads, stable_dt, bend_links);
        double rate = (double)size * size * steps / seconds;
        if (rate > best) best = rate;
    }
    return best;
}

int main(int argc, char **argv)
{
    int size = argc > 1 ? atoi(argv[1]) : 256;
    int steps = argc > 2 ? atoi(argv[2]) : 200;
    int threads = argc > 3 ? atoi(argv[3]) : 2;
    int repeats = argc > 4 ? atoi(argv[4]) : 3;
    if (size < 2 || steps < 1 || threads < 1 || repeats < 1) {
        fprintf(stderr, "usage: bench_core [size>=2] [steps>=1] [threads>=1] [repeats>=1]\n");
        return 2;
    }
    double stable_dt;
    int32_t bend;
    printf("libwetcloth %s core benchmark: %d x %d cloth (%d particles), crumpled, no collisions\n",
           wc_version_string(), size, size, size * size);
    double one = best_rate(size, steps, 1, repeats, &stable_dt, &bend);
    double many = best_rate(size, steps, threads, repeats, &stable_dt, &bend);
    printf("bend links %d, stable dt %.3g s, %d steps, best of %d runs\n", (int)bend, stable_dt,
           steps, repeats);
    printf("| threads | particle-steps/s |\n|---|---|\n");
    printf("| 1 | %.2f M |\n| %d | %.2f M |\n", one / 1e6, threads, many / 1e6);
    printf("speedup %d threads / 1 thread: %.2fx\n", threads, many / one);
    return 0;
}
