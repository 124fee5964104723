/* Thread scaling: particle-steps per second of a cloth resting on
 * a ground plate (bench_util's resting scene: link length 1/63 m, every
 * particle in contact), 32^2 to 512^2 particles (1k to 262k), self-collision
 * off and on, for each thread count given, all measured in this run.
 *
 *   build/tools/bench_threads [steps=50] [threads ...=1 2]
 *
 * Each configuration takes 20 warm-up steps and then `steps` timed steps of
 * the stable step; the speed-up is against the 1-thread figure of the same
 * run (1 is always measured first). The positions after the timed steps
 * must be bitwise the same for every thread count (the library's
 * determinism promise); the program exits non-zero if they are not. Last,
 * the slope of log(wall time per step) against log(particles) per thread
 * count: 1 is linear cost. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"
#include "wetcloth.h"

#define MAX_THREADS 16
#define SIZES 5

static const int size_of[SIZES] = {32, 64, 128, 256, 512};

/* FNV-1a over the bits of every position. */
static uint64_t hash_positions(const wc_world *w, int size)
{
    int32_t n = size * size;
    double *x = malloc(sizeof(double) * 3 * (size_t)n);
    if (!x) exit(1);
    bench_check(wc_cloth_get_positions(w, 0, x, n), w, "positions");
    uint64_t h = 1469598103934665603u;
    const unsigned char *b = (const unsigned char *)x;
    for (size_t i = 0; i < sizeof(double) * 3 * (size_t)n; ++i) h = (h ^ b[i]) * 1099511628211u;
    free(x);
    return h;
}

typedef struct measure {
    double rate;   /* particle-steps per second */
    uint64_t hash; /* of the positions at the end */
} measure;

static measure run(int size, int self_collision, int threads, int steps)
{
    double dt;
    wc_world *w = bench_resting_world(size, self_collision, threads, &dt);
    double t0 = bench_now();
    for (int k = 0; k < steps; ++k) bench_check(wc_world_step(w, dt), w, "step");
    measure m = {(double)steps * size * size / (bench_now() - t0), hash_positions(w, size)};
    bench_check_resting(w, size);
    wc_world_destroy(w);
    return m;
}

/* Least-squares slope of log(seconds per step) against log(particles). */
static double slope(const double rate[SIZES])
{
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (int i = 0; i < SIZES; ++i) {
        double n = (double)size_of[i] * size_of[i];
        double x = log(n), y = log(n / rate[i]);
        sx += x, sy += y, sxx += x * x, sxy += x * y;
    }
    return (SIZES * sxy - sx * sy) / (SIZES * sxx - sx * sx);
}

int main(int argc, char **argv)
{
    int steps = argc > 1 ? atoi(argv[1]) : 50;
    int threads[MAX_THREADS + 1] = {1, 2}, count = 2;
    if (argc > 2) {
        count = 1; /* 1 first, always: the speed-ups are against it */
        for (int a = 2; a < argc && count <= MAX_THREADS; ++a) {
            int t = atoi(argv[a]);
            if (t < 1 || t > 1024) {
                fprintf(stderr, "bench_threads: thread count %s is not in 1 .. 1024\n", argv[a]);
                return 2;
            }
            if (t != 1) threads[count++] = t;
        }
    }
    if (steps < 1) {
        fprintf(stderr, "usage: bench_threads [steps>=1] [threads ...]\n");
        return 2;
    }
    printf("libwetcloth %s thread scaling: cloth resting on a plate, %d timed steps\n\n",
           wc_version_string(), steps);
    printf("| particles | self-collision | threads | M particle-steps/s | speed-up | same bits as 1 "
           "thread |\n|---|---|---|---|---|---|\n");
    static double rate[2][MAX_THREADS + 1][SIZES];
    int all_same = 1;
    for (int self = 0; self <= 1; ++self)
        for (int i = 0; i < SIZES; ++i) {
            measure one = {0, 0};
            for (int k = 0; k < count; ++k) {
                measure m = run(size_of[i], self, threads[k], steps);
                if (k == 0) one = m;
                int same = m.hash == one.hash;
                all_same &= same;
                rate[self][k][i] = m.rate;
                printf("| %d | %s | %d | %.2f | %.2fx | %s |\n", size_of[i] * size_of[i],
                       self ? "on" : "off", threads[k], m.rate / 1e6, m.rate / one.rate,
                       same ? "yes" : "NO");
                fflush(stdout);
            }
        }
    printf("\nSlope of log(wall time per step) against log(particles), %d to %d particles:\n\n"
           "| threads | self-collision off | self-collision on |\n|---|---|---|\n",
           size_of[0] * size_of[0], size_of[SIZES - 1] * size_of[SIZES - 1]);
    for (int k = 0; k < count; ++k)
        printf("| %d | %.3f | %.3f |\n", threads[k], slope(rate[0][k]), slope(rate[1][k]));
    if (!all_same) {
        fprintf(stderr, "bench_threads: positions differ between thread counts\n");
        return 1;
    }
    return 0;
}
