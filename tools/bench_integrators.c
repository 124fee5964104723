/* The three integrators on the thesis drape: wall time per simulated frame
 * against error, by the project's error protocol (docs/benchmarks.md).
 *
 *   build/tools/bench_integrators [options]
 *     seconds=0.5        simulated time (frames of 1/24 s)
 *     threads=1          OpenMP threads (at most, with adapt=1)
 *     adapt=1            the world's adapt_threads (the library's default): a
 *                        step may run on fewer threads when measured faster;
 *                        0 runs exactly `threads`
 *     sizes=20,101       n of the n x n grid cloths (101^2 = 10,201 particles,
 *                        the size of Blender's figures below)
 *     self=0,1           self-collision off, on
 *     integrators=verlet,xpbd,implicit
 *     steps=2,3,5,8,12,20,30,50   substeps per frame swept for xpbd and
 *                        implicit (Verlet runs at its automatic count, the
 *                        fewest it is stable at)
 *     target=0.01        error bound of the summary
 *     stop=1             stop a sweep at the first setting within target
 *     tolerance=1        the implicit integrator's solve tolerance, m/s^2
 *                        (wc_world_def.implicit_tolerance; default the
 *                        library's); its references at 8x the steps always
 *                        solve to round-off (tolerance 0), so the error
 *                        column includes what the tolerance costs
 *     reference=1        0: time the runs only, without the references at 8x
 *                        the steps and without Verlet's run (error and vs
 *                        verlet print as nan, no summary): for comparing the
 *                        cost of two builds of the library
 *
 * Scene: an n x n grid cloth (default cotton), 1 m wide, 0.6 m above the
 * 114-vertex UV sphere (radius 0.3 m), falling onto it.
 *
 * Error: RMS over particles and frames of the distance between the
 * run and a reference run of the same scene and integrator at an 8x smaller
 * step, at the same frame times, divided by the cloth's size (1 m). The
 * column "vs verlet" is the same measure against Verlet at its automatic
 * step, to show where the large-step integrators' answer lies.
 *
 * Cost: wall milliseconds per simulated frame (one run each; the machine may
 * be shared: report its load). Blender's cloth on the same scene (bpy
 * 4.5.4, quality 5, this machine): 9.9 / 11.4 ms per frame at 400 particles
 * (self-collision off / on), 220 / 2752 at 10,201; "x blender" divides those
 * by ours for the sizes they were measured at. The summary picks, per
 * integrator, the cheapest setting within the target and compares it with
 * Blender's (target: 10x less time) and Verlet's (5x less). */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench_util.h"
#include "wetcloth.h"

#define MAX_LIST 32

typedef struct options {
    double seconds, target, tolerance;
    int threads, adapt, stop, reference;
    int sizes[MAX_LIST], size_count;
    int selfs[MAX_LIST], self_count;
    int integrators[MAX_LIST], integrator_count;
    int steps[MAX_LIST], step_count;
} options;

/* One run: its positions at every frame end, its cost and its phases. */
typedef struct run_result {
    int substeps, frames, failed;
    double ms_per_frame;
    double cpu_ms_per_frame; /* process CPU time: less sensitive to a shared machine */
    double phase_ms[3]; /* forces, integration, collisions; per frame */
    double solver_iterations; /* implicit: CG iterations per substep */
    double *positions;  /* frames x 3 n, caller frees */
    int32_t n;
} run_result;

static const char *const NAMES[3] = {"verlet", "xpbd", "implicit"};

static wc_world *make_world(int size, int self, int integrator, int threads, int adapt,
                            double tolerance, int32_t *cloth)
{
    wc_world_def wd = wc_world_def_default();
    wd.thread_count = threads;
    wd.adapt_threads = adapt;
    wd.implicit_tolerance = tolerance;
    wd.integrator = (wc_integrator)integrator;
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
    bench_check(wc_world_add_grid_cloth(w, &g, cloth), w, "add cloth");
    return w;
}

/* CPU seconds of the whole process (all threads). */
static double cpu_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* substeps 0: the integrator's automatic count (its own stable step).
 * tolerance: the implicit integrator's (o->tolerance, or 0 for a reference). */
static run_result run(const options *o, int size, int self, int integrator, int substeps,
                      double tolerance)
{
    int32_t cl;
    wc_world *w = make_world(size, self, integrator, o->threads, o->adapt, tolerance, &cl);
    run_result r;
    memset(&r, 0, sizeof r);
    r.frames = (int)lround(o->seconds * 24);
    r.n = wc_cloth_particle_count(w, cl);
    r.positions = calloc((size_t)r.frames * 3 * (size_t)r.n, sizeof *r.positions);
    if (!r.positions) exit(1);
    double wall = 0.0, cpu = 0.0;
    for (int f = 0; f < r.frames; ++f) {
        double t0 = bench_now(), c0 = cpu_now();
        wc_status s = wc_world_advance(w, 1.0 / 24, substeps);
        wall += bench_now() - t0;
        cpu += cpu_now() - c0;
        if (s != WC_OK) {
            r.failed = 1;
            break;
        }
        wc_step_stats st = wc_world_get_stats(w);
        r.phase_ms[0] += 1e3 * st.force_seconds;
        r.phase_ms[1] += 1e3 * st.integrate_seconds;
        r.phase_ms[2] += 1e3 * st.collide_seconds;
        r.solver_iterations += (double)st.solver_iterations;
        wc_cloth_get_positions(w, cl, r.positions + (size_t)f * 3 * (size_t)r.n, r.n);
    }
    r.substeps = wc_world_last_substeps(w);
    r.ms_per_frame = 1e3 * wall / r.frames;
    r.cpu_ms_per_frame = 1e3 * cpu / r.frames;
    for (int k = 0; k < 3; ++k) r.phase_ms[k] /= r.frames;
    r.solver_iterations /= (double)r.frames * r.substeps;
    wc_world_destroy(w);
    return r;
}

/* The project's error protocol: RMS distance over particles and frames / cloth size (1 m). */
static double rms_error(const run_result *a, const run_result *b)
{
    if (a->failed || b->failed) return NAN;
    double sum = 0.0;
    size_t len = (size_t)a->frames * 3 * (size_t)a->n;
    for (size_t i = 0; i < len; ++i) {
        double d = a->positions[i] - b->positions[i];
        sum += d * d;
    }
    return sqrt(sum / ((double)a->frames * a->n)) / 1.0;
}

/* Blender's ms per frame on the same scene, measured through bpy 4.5 on the
 * development machine (docs/benchmarks.md), 0 where not measured. */
static double blender_ms(int size, int self)
{
    if (size == 20) return self ? 11.4 : 9.9;
    if (size == 101) return self ? 2752.0 : 220.0;
    return 0.0;
}

typedef struct best {
    int found, substeps;
    double ms, cpu_ms, error;
} best;

static void print_row(int size, int self, int integrator, const run_result *r, double error,
                      double vs_verlet)
{
    double blender = blender_ms(size, self);
    printf("%-9d %-4s %-9s %8d %10.2f %8.2f %7.2f %7.2f %7.2f %10.2e %10.2e", size * size,
           self ? "on" : "off", NAMES[integrator], r->substeps, r->ms_per_frame,
           r->cpu_ms_per_frame, r->phase_ms[0],
           r->phase_ms[1], r->phase_ms[2], error, vs_verlet);
    if (blender > 0.0)
        printf(" %9.2f", blender / r->ms_per_frame);
    else
        printf(" %9s", "-");
    printf(" %8.1f", r->solver_iterations);
    printf("%s\n", r->failed ? "  FAILED (non-finite step)" : "");
    fflush(stdout);
}

/* Runs one integrator on one scene: Verlet at its automatic count, the others
 * over o->steps; each against its own run at 8x the substeps. */
static best sweep(const options *o, int size, int self, int integrator, const run_result *verlet)
{
    best b = {0, 0, 0.0, 0.0, 0.0};
    int counts[MAX_LIST], count = 0;
    if (integrator == 0) {
        counts[count++] = 0;
    } else {
        for (int k = 0; k < o->step_count; ++k) counts[count++] = o->steps[k];
    }
    for (int k = 0; k < count; ++k) {
        /* Verlet's run at its automatic count is the one passed in */
        int reuse = integrator == 0 && verlet;
        run_result r = reuse ? *verlet : run(o, size, self, integrator, counts[k], o->tolerance);
        run_result ref;
        memset(&ref, 0, sizeof ref);
        if (o->reference) ref = run(o, size, self, integrator, 8 * r.substeps, 0.0);
        double error = o->reference ? rms_error(&r, &ref) : NAN;
        double vs_verlet = verlet ? rms_error(&r, verlet) : NAN;
        print_row(size, self, integrator, &r, error, vs_verlet);
        if (!r.failed && error <= o->target && (!b.found || r.ms_per_frame < b.ms)) {
            b.found = 1, b.substeps = r.substeps, b.ms = r.ms_per_frame, b.error = error;
            b.cpu_ms = r.cpu_ms_per_frame;
        }
        if (!reuse) free(r.positions);
        free(ref.positions);
        if (b.found && o->stop) break;
    }
    return b;
}

/* A number option's value, or exit 2 naming the option: atof would take
 * "1e" or "abc" as 0 and run a benchmark nobody asked for. */
static double number(const char *key, const char *text)
{
    char *end;
    double v = strtod(text, &end);
    if (end == text || *end || !isfinite(v)) {
        fprintf(stderr, "%s: expected a number, found '%s'\n", key, text);
        exit(2);
    }
    return v;
}

static int integer(const char *key, const char *text)
{
    char *end;
    long v = strtol(text, &end, 10);
    if (end == text || *end || v < 0 || v > 1000000) {
        fprintf(stderr, "%s: expected a whole number in [0, 1000000], found '%s'\n", key, text);
        exit(2);
    }
    return (int)v;
}

static int parse_list(const char *key, const char *text, int *out, int is_integrator)
{
    int count = 0;
    char buf[512];
    snprintf(buf, sizeof buf, "%s", text);
    for (char *tok = strtok(buf, ","); tok && count < MAX_LIST; tok = strtok(NULL, ",")) {
        if (is_integrator) {
            int k = 0;
            while (k < 3 && strcmp(tok, NAMES[k])) ++k;
            if (k == 3) {
                fprintf(stderr, "%s: unknown integrator '%s'\n", key, tok);
                exit(2);
            }
            out[count++] = k;
        } else {
            out[count++] = integer(key, tok);
        }
    }
    return count;
}

static options parse(int argc, char **argv)
{
    options o;
    memset(&o, 0, sizeof o);
    o.seconds = 0.5, o.threads = 1, o.target = 0.01, o.stop = 1, o.reference = 1, o.adapt = 1;
    o.tolerance = wc_world_def_default().implicit_tolerance;
    o.size_count = parse_list("sizes", "20,101", o.sizes, 0);
    o.self_count = parse_list("self", "0,1", o.selfs, 0);
    o.integrator_count = parse_list("integrators", "verlet,xpbd,implicit", o.integrators, 1);
    o.step_count = parse_list("steps", "2,3,5,8,12,20,30,50", o.steps, 0);
    for (int i = 1; i < argc; ++i) {
        const char *eq = strchr(argv[i], '=');
        if (!eq) {
            fprintf(stderr, "arguments are key=value (see tools/bench_integrators.c): %s\n", argv[i]);
            exit(2);
        }
        char key[32];
        snprintf(key, sizeof key, "%.*s", (int)(eq - argv[i]), argv[i]);
        const char *v = eq + 1;
        if (!strcmp(key, "seconds")) o.seconds = number(key, v);
        else if (!strcmp(key, "threads")) o.threads = integer(key, v);
        else if (!strcmp(key, "adapt")) o.adapt = integer(key, v);
        else if (!strcmp(key, "target")) o.target = number(key, v);
        else if (!strcmp(key, "stop")) o.stop = integer(key, v);
        else if (!strcmp(key, "reference")) o.reference = integer(key, v);
        else if (!strcmp(key, "tolerance")) o.tolerance = number(key, v);
        else if (!strcmp(key, "sizes")) o.size_count = parse_list(key, v, o.sizes, 0);
        else if (!strcmp(key, "self")) o.self_count = parse_list(key, v, o.selfs, 0);
        else if (!strcmp(key, "integrators")) o.integrator_count = parse_list(key, v, o.integrators, 1);
        else if (!strcmp(key, "steps")) o.step_count = parse_list(key, v, o.steps, 0);
        else {
            fprintf(stderr, "unknown option %s\n", argv[i]);
            exit(2);
        }
    }
    return o;
}

int main(int argc, char **argv)
{
    options o = parse(argc, argv);
    printf("thesis drape, %.2f s simulated (%d frames of 1/24 s), %d thread(s)%s, implicit "
           "tolerance %g m/s^2. error: RMS "
           "distance over particles and frames to the same integrator at 8x the substeps (solved "
           "to round-off), / 1 m; "
           "vs verlet: the same against Verlet at its automatic step. ms per simulated frame, "
           "its CPU time (cpu ms, all threads), the phases forces / integration / collisions (wall). x blender: Blender's ms per frame "
           "(measured through bpy) / ours. cg/step: the implicit integrator's conjugate-gradient iterations per substep.\n\n",
           o.seconds, (int)lround(o.seconds * 24), o.threads,
           o.adapt ? " at most (adapt=1)" : " exactly (adapt=0)", o.tolerance);
    printf("%-9s %-4s %-9s %8s %10s %8s %7s %7s %7s %10s %10s %9s %8s\n", "particles", "self",
           "integr.", "steps/fr", "ms/frame", "cpu ms", "force", "integr", "collide", "error", "vs verlet",
           "x blender", "cg/step");
    char summary[MAX_LIST * MAX_LIST * 3][200];
    int lines = 0;
    for (int s = 0; s < o.size_count; ++s)
        for (int si = 0; si < o.self_count; ++si) {
            int n = o.sizes[s], self = o.selfs[si];
            run_result verlet;
            memset(&verlet, 0, sizeof verlet);
            if (o.reference) verlet = run(&o, n, self, 0, 0, 0.0);
            best verlet_best = {0, 0, 0.0, 0.0, 0.0};
            for (int k = 0; k < o.integrator_count; ++k) {
                int integrator = o.integrators[k];
                best b = sweep(&o, n, self, integrator, o.reference ? &verlet : NULL);
                if (integrator == 0) verlet_best = b;
                double blender = blender_ms(n, self);
                if (!b.found) {
                    snprintf(summary[lines++], 200, "%-9d %-4s %-9s none within %.0e", n * n,
                             self ? "on" : "off", NAMES[integrator], o.target);
                    continue;
                }
                char vb[32] = "-", vv[32] = "-";
                if (blender > 0.0) snprintf(vb, sizeof vb, "%.2fx", blender / b.ms);
                if (verlet_best.found) snprintf(vv, sizeof vv, "%.2fx", verlet_best.ms / b.ms);
                snprintf(summary[lines++], 200, "%-9d %-4s %-9s %8d %10.2f %8.2f %10.2e %10s %10s",
                         n * n, self ? "on" : "off", NAMES[integrator], b.substeps, b.ms,
                         b.cpu_ms, b.error, vb, vv);
            }
            free(verlet.positions);
        }
    if (!o.reference) return 0; /* no errors: nothing to summarise */
    printf("\ncheapest setting with error <= %.0e (targets: 10x less time than Blender, 5x less "
           "than Verlet)\n",
           o.target);
    printf("%-9s %-4s %-9s %8s %10s %8s %10s %10s %10s\n", "particles", "self", "integr.",
           "steps/fr", "ms/frame", "cpu ms", "error", "x blender", "x verlet");
    for (int i = 0; i < lines; ++i) printf("%s\n", summary[i]);
    return 0;
}
