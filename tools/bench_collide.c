/* Collision benchmark: the thesis' Table 3.2 scene and self-collision
 * scaling, each figure measured in this run.
 *
 *   build/tools/bench_collide [threads=1] [seconds=1.0] [size self_collision]
 *
 * With size and self_collision (0 or 1) given, only that one configuration
 * of the Table 3.2 scene runs (for profiling).
 *
 * Table 3.2 scene: an n x n grid cloth, 1 m wide, 0.6 m above the 114-vertex
 * UV sphere (16 segments x 8 rings, radius 0.3 m), falling onto it. Each
 * configuration runs for `seconds` of simulated time in frames of 1/24 s
 * with automatic substeps; steps per second = substeps taken / wall time.
 * The thesis drew one frame per step of its explicit integrator, so these
 * rows run Verlet, the thesis' integrator, at its automatic step, and its
 * fps compares with our steps per second step for step (a step of the
 * default implicit integrator covers several of them, 1/288 s against
 * Verlet's 1/2736 s at 400 particles, so its steps per second would not
 * compare).
 *
 * Self-collision, larger cloths: n x n cloths starting 1 cm above the
 * sphere (so in contact from the start at every size), self-collision on,
 * 2 frames; particle-steps per second. These and the resting cloths below
 * run the world's default integrator (the implicit one).
 *
 * Cost per particle-step against size: n x n cloths of the same link
 * length (1/63 m, so the same stable step at every size) lying on a ground
 * plate, every particle in contact, self-collision on and off; after 20
 * warm-up steps, 100 steps are timed. A flat column means the cost grows
 * linearly with the particle count. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "bench_util.h"
#include "wetcloth.h"


typedef struct result {
    double steps_per_second;
    double particle_steps_per_second;
    int64_t steps;
    int32_t intersections;
} result;

/* The Table 3.2 scene: the cloth starts `height` m above the sphere's
 * centre (0.6 in the thesis; the larger cloths start on the sphere). */
static result run_from(wc_integrator integrator, int size, int self_collision, int threads,
                       double seconds, double height)
{
    wc_world_def wd = wc_world_def_default();
    wd.integrator = integrator;
    wd.thread_count = threads;
    wd.adapt_threads = 0; /* measured at exactly this count */
    wc_world *w;
    wc_message m;
    bench_check(wc_world_create(&wd, &w, &m), NULL, m.text);
    bench_add_thesis_sphere(w);
    wc_grid_cloth_def g = wc_grid_cloth_def_default();
    g.count_u = g.count_v = size;
    g.center[2] = height;
    g.self_collision = self_collision;
    int32_t c;
    bench_check(wc_world_add_grid_cloth(w, &g, &c), w, "add cloth");
    int frames = (int)ceil(seconds * 24.0 - 1e-9);
    result r = {0, 0, 0, 0};
    double t0 = bench_now();
    for (int f = 0; f < frames; ++f) {
        bench_check(wc_world_advance(w, 1.0 / 24.0, 0), w, "advance");
        r.steps += wc_world_last_substeps(w);
    }
    double wall = bench_now() - t0;
    wc_intersection_counts counts;
    bench_check(wc_world_count_intersections(w, &counts), w, "count_intersections");
    r.intersections = counts.cloth_cloth + counts.cloth_collider;
    r.steps_per_second = (double)r.steps / wall;
    r.particle_steps_per_second = r.steps_per_second * size * size;
    wc_world_destroy(w);
    return r;
}

/* The Table 3.2 scene itself: Verlet, from 0.6 m. */
static result run(int size, int self_collision, int threads, double seconds)
{
    return run_from(WC_INTEGRATOR_VERLET, size, self_collision, threads, seconds, 0.6);
}

/* Particle-steps per second of an n x n cloth resting on the ground. */
static double resting(int size, int self_collision, int threads)
{
    double dt;
    wc_world *w = bench_resting_world(size, self_collision, threads, &dt);
    double t0 = bench_now();
    for (int k = 0; k < 100; ++k) bench_check(wc_world_step(w, dt), w, "step");
    double rate = 100.0 * size * size / (bench_now() - t0);
    bench_check_resting(w, size);
    wc_world_destroy(w);
    return rate;
}

int main(int argc, char **argv)
{
    int threads = argc > 1 ? atoi(argv[1]) : 1;
    double seconds = argc > 2 ? atof(argv[2]) : 1.0;
    if (threads < 1 || !(seconds > 0.0)) {
        fprintf(stderr, "usage: bench_collide [threads>=1] [seconds>0]\n");
        return 2;
    }
    if (argc > 4) {
        int size = atoi(argv[3]), self = atoi(argv[4]);
        if (size < 2 || (self != 0 && self != 1)) {
            fprintf(stderr, "usage: bench_collide threads seconds size>=2 self_collision(0|1)\n");
            return 2;
        }
        result r = run(size, self, threads, seconds);
        printf("%d particles, self-collision %s: %.0f steps/s, %.2f M particle-steps/s, %lld steps, "
               "%d intersections at end\n",
               size * size, self ? "on" : "off", r.steps_per_second, r.particle_steps_per_second / 1e6,
               (long long)r.steps, (int)r.intersections);
        return 0;
    }
    static const int sizes[3] = {10, 15, 20};
    static const int thesis_on[3] = {62, 15, 6}, thesis_off[3] = {142, 62, 35};
    printf("libwetcloth %s collision benchmark, %d thread(s), %.2f simulated s per run\n\n",
           wc_version_string(), threads, seconds);
    printf("Thesis Table 3.2 scene (grid cloth onto the 114-vertex sphere), Verlet at its automatic "
           "step, as the thesis stepped:\n\n");
    printf("| particles | self-collision | steps/s | thesis fps | ratio | intersections at end |\n");
    printf("|---|---|---|---|---|---|\n");
    for (int i = 0; i < 3; ++i)
        for (int self = 1; self >= 0; --self) {
            result r = run(sizes[i], self, threads, seconds);
            int thesis = self ? thesis_on[i] : thesis_off[i];
            printf("| %d | %s | %.0f | %d | %.0fx | %d |\n", sizes[i] * sizes[i], self ? "on" : "off",
                   r.steps_per_second, thesis, r.steps_per_second / thesis, (int)r.intersections);
        }
    printf("\nSelf-collision on, larger cloths, starting 1 cm above the sphere, 2 frames, the "
           "default integrator:\n\n");
    printf("| particles | particle-steps/s | steps/s | intersections at end |\n|---|---|---|---|\n");
    static const int big[3] = {64, 128, 256};
    for (int i = 0; i < 3; ++i) {
        /* 1 cm above the top of the sphere: in contact from the start, so
         * every size is timed while draping, for 2 frames */
        result r = run_from(wc_world_def_default().integrator, big[i], 1, threads, 2.0 / 24.0, 0.31);
        printf("| %d | %.2f M | %.0f | %d |\n", big[i] * big[i], r.particle_steps_per_second / 1e6,
               r.steps_per_second, (int)r.intersections);
    }
    printf("\nCost per particle-step against size: cloth resting on a ground plate, link length "
           "1/63 m, the default integrator at its stable step:\n\n");
    printf("| particles | self-collision off | ns per particle-step | self-collision on | ns per "
           "particle-step |\n|---|---|---|---|---|\n");
    static const int sizes_flat[5] = {64, 91, 128, 181, 256};
    for (int i = 0; i < 5; ++i) {
        double off = resting(sizes_flat[i], 0, threads), on = resting(sizes_flat[i], 1, threads);
        printf("| %d | %.2f M/s | %.0f | %.2f M/s | %.0f |\n", sizes_flat[i] * sizes_flat[i],
               off / 1e6, 1e9 / off, on / 1e6, 1e9 / on);
    }
    return 0;
}
