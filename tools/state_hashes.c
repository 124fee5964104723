/* Bitwise record of scenes where cloths collide with cloths: prints an
 * FNV-1a hash of every cloth's positions after every frame, for 1, 2 and 4
 * threads, so that two builds (a change of data layout, say) can be compared
 * by diffing their output. Public API only, so the same source builds
 * against any version of the library.
 *
 *   state_hashes             every scene, every thread count
 *   state_hashes bench N F   N cloths of 50 x 50 stacked within the
 *                            thickness, falling onto the thesis' solid: ms
 *                            per frame over F frames, 1 thread (the pass
 *                            between cloths runs every step) */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench_util.h"
#include "wetcloth.h"

typedef struct scene {
    const char *name;
    int cloths, side, frames, self_collision, sphere;
    double wetness;
    wc_integrator integrator;
    /// Index of a cloth that does not collide with cloths, or -1.
    int loner;
    /// Frame after which one more cloth is added on top, or -1.
    int add_after;
} scene;

static uint64_t fnv(uint64_t h, const void *bytes, size_t n)
{
    const unsigned char *p = bytes;
    for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
    return h;
}

static uint64_t world_hash(const wc_world *w)
{
    uint64_t h = 1469598103934665603ull;
    for (int32_t c = 0; c < wc_world_cloth_count(w); ++c) {
        int32_t n = wc_cloth_particle_count(w, c);
        double *x = malloc(3 * (size_t)n * sizeof *x);
        if (!x) exit(1);
        bench_check(wc_cloth_get_positions(w, c, x, n), w, "get positions");
        h = fnv(h, x, 3 * (size_t)n * sizeof *x);
        free(x);
    }
    return h;
}

/* Cloth k of a stack: 4 mm above the one below it (within the default 5 mm
 * thickness), turned a little so the grids do not lie vertex over vertex. */
static void add_cloth(wc_world *w, const scene *s, int k)
{
    wc_grid_cloth_def g = wc_grid_cloth_def_default();
    g.count_u = g.count_v = s->side;
    g.size_u = g.size_v = 0.8;
    double a = 0.1 * k;
    g.axis_u[0] = cos(a), g.axis_u[1] = sin(a), g.axis_u[2] = 0.0;
    g.axis_v[0] = -sin(a), g.axis_v[1] = cos(a), g.axis_v[2] = 0.0;
    g.center[0] = 0.02 * k;
    g.center[2] = 0.35 + 0.004 * k;
    g.self_collision = s->self_collision;
    g.wetness = s->wetness;
    g.collide_with_cloths = k != s->loner;
    int32_t id;
    bench_check(wc_world_add_grid_cloth(w, &g, &id), w, "add cloth");
}

static uint64_t run(const scene *s, int threads, int print)
{
    wc_world_def d = wc_world_def_default();
    d.thread_count = threads;
    d.integrator = s->integrator;
    wc_world *w;
    wc_message m;
    bench_check(wc_world_create(&d, &w, &m), NULL, m.text);
    if (s->sphere) bench_add_thesis_sphere(w);
    for (int k = 0; k < s->cloths; ++k) add_cloth(w, s, k);
    uint64_t all = 0;
    long cloth_contacts = 0;
    for (int f = 0; f < s->frames; ++f) {
        bench_check(wc_world_advance(w, 1.0 / 24, 0), w, "advance");
        cloth_contacts += wc_world_get_stats(w).cloth_contacts;
        uint64_t h = world_hash(w);
        all = all * 31u + h;
        if (print) printf("%s threads %d frame %d %016llx\n", s->name, threads, f, (unsigned long long)h);
        if (f == s->add_after) add_cloth(w, s, s->cloths);
    }
    if (print)
        printf("%s threads %d: cloth contacts in the last steps of the frames %ld\n", s->name,
               threads, cloth_contacts);
    wc_world_destroy(w);
    return all;
}

static void bench(int cloths, int frames)
{
    scene s = {"bench", cloths, 50, frames, 0, 1, 0.0, WC_INTEGRATOR_IMPLICIT, -1, -1};
    wc_world_def d = wc_world_def_default();
    d.thread_count = 1;
    d.adapt_threads = 0;
    wc_world *w;
    wc_message m;
    bench_check(wc_world_create(&d, &w, &m), NULL, m.text);
    bench_add_thesis_sphere(w);
    for (int k = 0; k < cloths; ++k) add_cloth(w, &s, k);
    bench_check(wc_world_advance(w, 1.0 / 24, 0), w, "advance"); /* warm-up */
    double t0 = bench_now();
    clock_t c0 = clock();
    for (int f = 0; f < frames; ++f) bench_check(wc_world_advance(w, 1.0 / 24, 0), w, "advance");
    double t = bench_now() - t0, cpu = (double)(clock() - c0) / CLOCKS_PER_SEC;
    printf("%d cloths of 50 x 50, 1 thread: %.2f ms per frame, %.2f ms CPU (%d frames, hash "
           "%016llx)\n", cloths, 1e3 * t / frames, 1e3 * cpu / frames, frames,
           (unsigned long long)world_hash(w));
    wc_world_destroy(w);
}

int main(int argc, char **argv)
{
    if (argc == 4 && !strcmp(argv[1], "bench")) {
        bench(atoi(argv[2]), atoi(argv[3]));
        return 0;
    }
    const wc_integrator imp = WC_INTEGRATOR_IMPLICIT, ver = WC_INTEGRATOR_VERLET;
    const scene scenes[] = {
        {"two-dry", 2, 12, 24, 0, 1, 0.0, imp, -1, -1},
        {"two-dry-self", 2, 12, 24, 1, 1, 0.0, imp, -1, -1},
        {"two-wet", 2, 12, 24, 0, 1, 1.0, imp, -1, -1},
        {"two-wet-self", 2, 12, 24, 1, 1, 1.0, imp, -1, -1},
        {"two-wet-verlet", 2, 10, 4, 0, 1, 1.0, ver, -1, -1},
        {"three-dry", 3, 12, 24, 0, 1, 0.0, imp, -1, -1},
        {"three-dry-self", 3, 12, 24, 1, 1, 0.0, imp, -1, -1},
        {"three-wet", 3, 12, 24, 0, 1, 1.0, imp, -1, -1},
        {"three-wet-self", 3, 12, 24, 1, 1, 1.0, imp, -1, -1},
        /* the middle one does not collide with cloths: the two others
         * collide with each other through it */
        {"three-loner", 3, 12, 24, 1, 1, 0.5, imp, 1, -1},
        /* a cloth added after 8 frames: the arrays grow mid-run */
        {"two-then-three", 2, 12, 24, 1, 1, 1.0, imp, -1, 8},
        {"thesis-drape", 1, 20, 48, 0, 1, 0.0, imp, -1, -1},
        {"thesis-drape-wet-self", 1, 20, 48, 1, 1, 1.0, imp, -1, -1},
    };
    for (size_t k = 0; k < sizeof scenes / sizeof scenes[0]; ++k) {
        const int threads[3] = {1, 2, 4};
        uint64_t first = 0;
        for (int t = 0; t < 3; ++t) {
            uint64_t h = run(&scenes[k], threads[t], 1);
            if (t == 0) first = h;
            else if (h != first) printf("%s: %d threads differ from 1\n", scenes[k].name, threads[t]);
        }
    }
    return 0;
}
