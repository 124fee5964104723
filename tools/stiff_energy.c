/* The stiff-cloth energy scene of tests/test_integrators.c (a horizontal
 * 1 m cloth of 1e9 N/m pinned at two adjacent corners, falling and
 * swinging for 2 s at 24 frames per second) swept over cloth sizes, steps
 * per frame and the implicit integrator's solve tolerance: the largest
 * gain of kinetic + gravity + bending energy over its start, as a fraction
 * of m g (1 m), and the CG iterations per step. The test bounds the gain at
 * 1e-3 at one setting (20 x 20, 5 steps per frame, the default tolerance);
 * this shows how that setting's neighbours fare.
 *
 *   build/tools/stiff_energy [sizes=12,16,20,24] [steps=4,5,6,8]
 *                            [tolerances=0,1,8,32] [stiffness=1e9] [seconds=2]
 *
 * A cell over the test's bound is marked with '!'. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"
#include "wetcloth.h"

#define MAX_LIST 16

typedef struct list {
    double value[MAX_LIST];
    int count;
} list;

/* A comma-separated list of numbers, or exit 2 naming the option. */
static list parse_list(const char *key, const char *text)
{
    list l = {{0.0}, 0};
    const char *p = text;
    while (*p) {
        char *end;
        double v = strtod(p, &end);
        if (end == p || !isfinite(v) || l.count == MAX_LIST || (*end && *end != ',')) {
            fprintf(stderr, "%s: expected up to %d numbers separated by commas, found '%s'\n",
                    key, MAX_LIST, text);
            exit(2);
        }
        l.value[l.count++] = v;
        p = *end ? end + 1 : end;
    }
    if (l.count == 0) {
        fprintf(stderr, "%s: expected at least one number\n", key);
        exit(2);
    }
    return l;
}

static double mechanical_energy(const wc_world *w, int32_t cloth)
{
    wc_energy e;
    bench_check(wc_cloth_get_energy(w, cloth, &e), w, "energy");
    return e.kinetic + e.gravity + e.bend;
}

/* The largest energy gain / (m g * 1 m) over the run; *iterations per step. */
static double largest_gain(int n, int steps, double tolerance, double stiffness, double seconds,
                           double *iterations)
{
    wc_world_def def = wc_world_def_default();
    def.thread_count = 1;
    def.implicit_tolerance = tolerance;
    wc_world *w = NULL;
    wc_message msg;
    if (wc_world_create(&def, &w, &msg) != WC_OK) {
        fprintf(stderr, "wc_world_create: %s\n", msg.text);
        exit(1);
    }
    wc_grid_cloth_def g = wc_grid_cloth_def_default();
    g.count_u = g.count_v = n;
    g.material.stretch_stiffness = stiffness;
    int32_t cloth, pins[2] = {0, n - 1};
    bench_check(wc_world_add_grid_cloth(w, &g, &cloth), w, "cloth");
    bench_check(wc_cloth_pin(w, cloth, pins, 2), w, "pins");
    wc_cloth_view view;
    bench_check(wc_cloth_get_view(w, cloth, &view), w, "view");
    double mass = 0.0;
    for (int32_t i = 0; i < view.particle_count; ++i) mass += view.mass[i];
    double start = mechanical_energy(w, cloth), worst = -INFINITY;
    int frames = (int)lround(seconds * 24);
    long long solved = 0;
    for (int f = 0; f < frames; ++f) {
        bench_check(wc_world_advance(w, 1.0 / 24, steps), w, "advance");
        solved += wc_world_get_stats(w).solver_iterations;
        worst = fmax(worst, mechanical_energy(w, cloth) - start);
    }
    *iterations = (double)solved / ((double)frames * steps);
    wc_world_destroy(w);
    return worst / (mass * 9.81);
}

int main(int argc, char **argv)
{
    list sizes = parse_list("sizes", "12,16,20,24"), steps = parse_list("steps", "4,5,6,8");
    list tolerances = parse_list("tolerances", "0,1,8,32");
    double stiffness = 1e9, seconds = 2.0;
    for (int a = 1; a < argc; ++a) {
        const char *eq = strchr(argv[a], '=');
        if (!eq) {
            fprintf(stderr, "expected key=value, found '%s'\n", argv[a]);
            return 2;
        }
        size_t len = (size_t)(eq - argv[a]);
        const char *v = eq + 1;
        if (len == 5 && !strncmp(argv[a], "sizes", len)) sizes = parse_list("sizes", v);
        else if (len == 5 && !strncmp(argv[a], "steps", len)) steps = parse_list("steps", v);
        else if (len == 10 && !strncmp(argv[a], "tolerances", len))
            tolerances = parse_list("tolerances", v);
        else if (len == 9 && !strncmp(argv[a], "stiffness", len))
            stiffness = parse_list("stiffness", v).value[0];
        else if (len == 7 && !strncmp(argv[a], "seconds", len))
            seconds = parse_list("seconds", v).value[0];
        else {
            fprintf(stderr, "unknown option '%s'\n", argv[a]);
            return 2;
        }
    }
    printf("stiff cloth (%g N/m, pinned at two corners, %g s): largest energy gain / (m g 1 m), "
           "CG iterations per step in brackets, '!' over the test's bound 1e-3\n",
           stiffness, seconds);
    printf("%-6s %-6s", "size", "steps");
    for (int t = 0; t < tolerances.count; ++t) printf("  tolerance %-8g m/s^2", tolerances.value[t]);
    printf("\n");
    for (int a = 0; a < sizes.count; ++a)
        for (int b = 0; b < steps.count; ++b) {
            printf("%-6d %-6d", (int)sizes.value[a], (int)steps.value[b]);
            for (int t = 0; t < tolerances.count; ++t) {
                double iterations;
                double gain = largest_gain((int)sizes.value[a], (int)steps.value[b],
                                           tolerances.value[t], stiffness, seconds, &iterations);
                printf("  %+9.2e%s (%5.0f)      ", gain, gain > 1e-3 ? "!" : " ", iterations);
                fflush(stdout);
            }
            printf("\n");
        }
    return 0;
}
