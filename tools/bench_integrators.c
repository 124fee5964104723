/* The three integrators on the thesis drape: wall time per simulated second
 * against error, side by side in one run (issue 7).
 *
 *   build/tools/bench_integrators [seconds=1] [threads=1] [reference_factor=4] [sizes...=20 100]
 *
 * Scene: an n x n grid cloth (default cotton), 1 m wide, 0.6 m above the
 * 114-vertex UV sphere (radius 0.3 m), falling onto it for `seconds` in
 * frames of 1/24 s, self-collision off and on. Each integrator runs with
 * automatic substeps (its own stable step, wc_world_advance(.., 0)) and,
 * for the large-step integrators, also at 5 steps per frame (Blender's
 * default quality). The reference is Verlet at `reference_factor` times
 * its automatic substeps. Error: the largest and the mean distance of a
 * particle from the reference at the end, as a fraction of the cloth's
 * size (1 m). A run that fails (non-finite step) is reported as such.
 * Figures: wall seconds per simulated second (one run each; the machine
 * may be shared, see docs/benchmarks.md's header). */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench_util.h"
#include "wetcloth.h"


typedef struct run_result {
    double wall_per_second; /* wall s per simulated s */
    int substeps;           /* per frame (the last frame's) */
    int failed;
    double *positions;      /* 3 n^2, caller frees */
} run_result;

static const char *const NAMES[3] = {"verlet", "xpbd", "implicit"};

/* substeps < 0: -substeps times the automatic count of the first frame */
static run_result run(int size, int self, wc_integrator integrator, int substeps, double seconds,
                      int threads)
{
    wc_world_def wd = wc_world_def_default();
    wd.thread_count = threads;
    wd.integrator = integrator;
    wd.max_substeps = 10000000;
    wc_world *w = NULL;
    wc_message msg;
    if (wc_world_create(&wd, &w, &msg) != WC_OK) {
        fprintf(stderr, "wc_world_create: %s\n", msg.text);
        exit(1);
    }
    bench_add_thesis_sphere(w);
    wc_grid_cloth_def g = wc_grid_cloth_def_default();
    g.count_u = g.count_v = size;
    g.center[2] = 0.6;
    g.self_collision = self;
    int32_t cl;
    bench_check(wc_world_add_grid_cloth(w, &g, &cl), w, "add cloth");
    if (substeps < 0) substeps = -substeps * (int)ceil(1.0 / 24 / (wd.substep_safety * wc_world_stable_dt(w)));
    run_result r = {0.0, 0, 0, NULL};
    int frames = (int)lround(seconds * 24);
    double t0 = bench_now();
    for (int f = 0; f < frames; ++f) {
        if (wc_world_advance(w, 1.0 / 24, substeps) != WC_OK) {
            r.failed = 1;
            break;
        }
    }
    r.wall_per_second = (bench_now() - t0) / seconds;
    r.substeps = wc_world_last_substeps(w);
    int32_t n = wc_cloth_particle_count(w, cl);
    r.positions = malloc(3 * (size_t)n * sizeof *r.positions);
    wc_cloth_get_positions(w, cl, r.positions, n);
    wc_world_destroy(w);
    return r;
}

static void errors(const double *a, const double *b, int32_t n, double *worst, double *mean)
{
    *worst = 0.0, *mean = 0.0;
    for (int32_t i = 0; i < n; ++i) {
        double d = sqrt((a[3 * i] - b[3 * i]) * (a[3 * i] - b[3 * i]) +
                        (a[3 * i + 1] - b[3 * i + 1]) * (a[3 * i + 1] - b[3 * i + 1]) +
                        (a[3 * i + 2] - b[3 * i + 2]) * (a[3 * i + 2] - b[3 * i + 2]));
        *worst = fmax(*worst, d);
        *mean += d / n;
    }
}

int main(int argc, char **argv)
{
    double seconds = argc > 1 ? atof(argv[1]) : 1.0;
    int threads = argc > 2 ? atoi(argv[2]) : 1;
    int factor = argc > 3 ? atoi(argv[3]) : 4;
    int sizes[16] = {20, 100}, size_count = 2;
    if (argc > 4) {
        size_count = 0;
        for (int i = 4; i < argc && size_count < 16; ++i) sizes[size_count++] = atoi(argv[i]);
    }
    printf("thesis drape, %.2f s simulated at 24 fps, %d thread(s); reference: verlet at %d x its "
           "automatic substeps. error = distance from the reference at the end / cloth size (1 m)\n\n",
           seconds, threads, factor);
    printf("%-9s %-5s %-9s %-10s %12s %12s %11s %11s %10s\n", "particles", "self", "integrator",
           "steps", "substeps/fr", "wall s/sim s", "max error", "mean error", "vs verlet");
    for (int s = 0; s < size_count; ++s)
        for (int self = 0; self < 2; ++self) {
            int n = sizes[s];
            run_result ref = run(n, self, WC_INTEGRATOR_VERLET, -factor, seconds, threads);
            if (ref.failed) printf("reference failed for %d^2, self %d\n", n, self);
            double verlet_wall = 0.0;
            for (int k = 0; k < 3; ++k)
                for (int mode = 0; mode < 2; ++mode) {
                    if (k == 0 && mode == 1) continue;
                    int sub = mode == 0 ? 0 : 5;
                    run_result r = run(n, self, (wc_integrator)k, sub, seconds, threads);
                    double worst, mean;
                    errors(r.positions, ref.positions, n * n, &worst, &mean);
                    if (k == 0) verlet_wall = r.wall_per_second;
                    printf("%-9d %-5s %-9s %-10s %12d %12.3f %11.2e %11.2e %9.1fx%s\n", n * n,
                           self ? "on" : "off", NAMES[k], mode == 0 ? "automatic" : "5/frame",
                           r.substeps, r.wall_per_second, worst, mean,
                           verlet_wall / r.wall_per_second, r.failed ? "  (FAILED: non-finite)" : "");
                    fflush(stdout);
                    free(r.positions);
                }
            free(ref.positions);
        }
    return 0;
}
