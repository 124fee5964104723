/* Cost of wetness on the thesis drape scene, wet against dry, side by side
 * in one run.
 *
 *   build/tools/bench_wet [threads=1] [repeats=3] [sizes...=20]
 *
 * Scene: an n x n grid cloth (default material), 1 m wide, 0.6 m above the
 * 114-vertex UV sphere (16 segments x 8 rings, radius 0.3 m), falling onto
 * it for 2 s in frames of 1/24 s (the thesis' Fig. 3.2-3.4 and Table 3.2
 * scene). Configurations:
 *   plain  dry cloth whose material has every wet parameter zeroed;
 *   dry    dry cloth (w = 0) with the default wet material: must cost the
 *          same as plain (wetness off costs nothing);
 *   wet    soaked cloth (w = 1), default wet material: adhesion, spreading,
 *          wet friction, contact hold, stuck flags, wet mass and softening.
 * All three take the same steps: the substep count that automatic
 * substepping picks for the dry cloth, so "wet / dry" is the cost per step.
 * A soaked cloth is heavier and softer, so its own stable step is 1.69 x
 * longer and automatic substepping gives it 1.69 x fewer steps per frame:
 *   wet-auto  the soaked cloth with automatic substeps; "wet-auto / dry" is
 *             the cost per frame as a user sees it.
 * Per step, the wet cloth also costs more because more of it touches the
 * sphere (it wraps it: 262 particles in contact at the end against 45 dry,
 * and four times the feature-pass pushes per step), which is collision
 * work the dry cloth does not have. The wet code itself is a few per cent
 * of a wet step: `perf record` on the 20 x 20 wet run puts wci_wet_forces,
 * the contact hold (wci_wet_hold_contacts, mesh_nearest) and
 * wci_wet_mark_stuck at 3.2 % of its samples together.
 * The configurations run interleaved, `repeats` times each; the figure is
 * the fastest run of each (the least disturbed by other load), in
 * microseconds per step, and the ratio wet / dry of those. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "bench_util.h"
#include "wetcloth.h"

#define FRAMES 48

enum { PLAIN, DRY, WET, WET_AUTO, CONFIGS };
static const char *const names[CONFIGS] = {"plain", "dry", "wet", "wet-auto"};

static wc_world *scene(int size, int config, int threads, int32_t *cloth)
{
    wc_world_def wd = wc_world_def_default();
    wd.thread_count = threads;
    wd.adapt_threads = 0; /* measured at exactly this count */
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
    if (config == PLAIN) {
        g.material.adhesion = 0.0, g.material.spread = 0.0, g.material.wet_friction = 1.0;
        g.material.wet_mass_gain = 0.0, g.material.wet_softening = 0.0;
    }
    g.wetness = config >= WET ? 1.0 : 0.0;
    bench_check(wc_world_add_grid_cloth(w, &g, cloth), w, "add cloth");
    return w;
}

typedef struct result {
    double seconds;
    int64_t steps;
    int32_t contacts, stuck, intersections;
} result;

static result run(int size, int config, int threads, int32_t substeps)
{
    int32_t cloth;
    wc_world *w = scene(size, config, threads, &cloth);
    result r = {0.0, 0, 0, 0, 0};
    double t0 = bench_now();
    for (int f = 0; f < FRAMES; ++f) {
        bench_check(wc_world_advance(w, 1.0 / 24, substeps), w, "advance");
        r.steps += wc_world_last_substeps(w);
    }
    r.seconds = bench_now() - t0;
    wc_step_stats st = wc_world_get_stats(w);
    r.contacts = st.collider_contacts, r.stuck = st.stuck_particles;
    wc_intersection_counts ic;
    bench_check(wc_world_count_intersections(w, &ic), w, "count intersections");
    r.intersections = ic.cloth_cloth + ic.cloth_collider;
    wc_world_destroy(w);
    return r;
}

int main(int argc, char **argv)
{
    int threads = argc > 1 ? atoi(argv[1]) : 1, repeats = argc > 2 ? atoi(argv[2]) : 3;
    int default_sizes[1] = {20}, *sizes = default_sizes, size_count = 1;
    int given[16];
    if (argc > 3) {
        size_count = argc - 3 > 16 ? 16 : argc - 3;
        for (int k = 0; k < size_count; ++k) given[k] = atoi(argv[3 + k]);
        sizes = given;
    }
    if (threads < 1 || repeats < 1) {
        fprintf(stderr, "usage: bench_wet [threads>=1] [repeats>=1] [sizes...]\n");
        return 2;
    }
    printf("Thesis drape (n x n cloth onto the 114-vertex sphere, %d frames = %.1f s), %d thread%s,\n"
           "fastest of %d interleaved runs per configuration; plain, dry and wet take the same steps,\n"
           "wet-auto its own (automatic) substeps:\n\n",
           FRAMES, FRAMES / 24.0, threads, threads == 1 ? "" : "s", repeats);
    printf("| n x n | steps | plain us/step | dry us/step | wet us/step | dry / plain | wet / dry "
           "(per step) | wet-auto steps | wet-auto / dry (per frame) | wet: stuck, contacts at the end |\n");
    printf("|---|---|---|---|---|---|---|---|---|---|\n");
    for (int k = 0; k < size_count; ++k) {
        int size = sizes[k];
        int32_t cloth;
        wc_world *w = scene(size, DRY, threads, &cloth);
        int32_t substeps = (int32_t)ceil(1.0 / 24 / (wc_world_def_default().substep_safety * wc_world_stable_dt(w)));
        wc_world_destroy(w);
        double best[CONFIGS];
        result last[CONFIGS];
        for (int c = 0; c < CONFIGS; ++c) best[c] = INFINITY;
        for (int rep = 0; rep < repeats; ++rep)
            for (int c = 0; c < CONFIGS; ++c) {
                last[c] = run(size, c, threads, c == WET_AUTO ? 0 : substeps);
                if (last[c].seconds < best[c]) best[c] = last[c].seconds;
            }
        for (int c = 0; c < CONFIGS; ++c)
            if (last[c].intersections)
                fprintf(stderr, "note: %s %dx%d ends with %d intersecting triangle pairs (self-collision "
                        "is off in this scene)\n", names[c], size, size, last[c].intersections);
        double us = 1e6 / (double)last[DRY].steps;
        printf("| %d x %d | %lld | %.1f | %.1f | %.1f | %.3f | %.3f | %lld | %.3f | %d, %d of %d |\n", size,
               size, (long long)last[DRY].steps, best[PLAIN] * us, best[DRY] * us, best[WET] * us,
               best[DRY] / best[PLAIN], best[WET] / best[DRY], (long long)last[WET_AUTO].steps,
               best[WET_AUTO] / best[DRY], last[WET].stuck, last[WET].contacts, size * size);
        fflush(stdout);
    }
    return 0;
}
