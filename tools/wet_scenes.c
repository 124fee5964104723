/* The thesis' wet-cloth scenes (its Fig. 3.2-3.7) plus self-adhesion, run as
 * tests/test_wet.c runs them, writing the states that tools/plot_scenes.py
 * draws into docs/images/.
 *
 *   build/tools/wet_scenes OUTPUT_DIR
 *   build/tools/wet_scenes --bending-sweep
 *
 * The second form prints, for bending stiffnesses from cotton (1e-5 N m)
 * up, the stuck fraction the spreading scene ends with (adhesion 40 and
 * 30 Pa) and the fold scene's height (docs/model.md, "Wetness and
 * bending", quotes it).
 *
 * Writes CSV files (header line, then one row per particle or per frame):
 *   wrap_{dry,wet}.csv          x,y,z,stuck   final state, 48 frames
 *   spreading.csv               frame and the stuck count of four runs
 *   spreading_{6,24,72}.csv     x,y,z,stuck   base run at those frames
 *   slack_{dry,wet}_{before,after}.csv   x,y,z,stuck
 *   fold_{dry,wet}.csv          x,y,z,stuck   final state
 *   self_{dry,wet}.csv          x,y,z,stuck   final state
 * Exit status 0 on success, 1 if a call failed, 2 for bad arguments. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"
#include "wetcloth.h"

#define PI 3.14159265358979323846

static const char *out_dir;

static wc_world *world(double gz)
{
    wc_world_def d = wc_world_def_default();
    d.thread_count = 1;
    d.gravity[2] = gz;
    wc_world *w = NULL;
    wc_message msg;
    if (wc_world_create(&d, &w, &msg) != WC_OK) {
        fprintf(stderr, "wet_scenes: %s\n", msg.text);
        exit(1);
    }
    return w;
}

static void plate_vertices(const double c[3], const double u[3], const double v[3], double size, double out[12])
{
    static const double su[4] = {-0.5, 0.5, 0.5, -0.5}, sv[4] = {-0.5, -0.5, 0.5, 0.5};
    for (int i = 0; i < 4; ++i)
        for (int k = 0; k < 3; ++k) out[3 * i + k] = c[k] + size * (su[i] * u[k] + sv[i] * v[k]);
}

static int32_t plate(wc_world *w, const double c[3], const double u[3], const double v[3], double size)
{
    double verts[12];
    static const int32_t tris[6] = {0, 1, 2, 0, 2, 3};
    plate_vertices(c, u, v, size, verts);
    wc_mesh_collider_def d = wc_mesh_collider_def_default();
    d.vertices = verts, d.vertex_count = 4, d.triangles = tris, d.triangle_count = 2;
    int32_t out;
    bench_check(wc_world_add_mesh_collider(w, &d, &out), w, "add plate");
    return out;
}

static int32_t grid(wc_world *w, const wc_grid_cloth_def *g)
{
    int32_t cl;
    bench_check(wc_world_add_grid_cloth(w, g, &cl), w, "add cloth");
    return cl;
}

static void advance(wc_world *w, double dt) { bench_check(wc_world_advance(w, dt, 0), w, "advance"); }

/* Writes a cloth's particles (x, y, z, stuck) to OUT_DIR/name. */
static void dump(const wc_world *w, int32_t cl, const char *name)
{
    int32_t n = wc_cloth_particle_count(w, cl);
    double *p = malloc(3 * sizeof *p * (size_t)n);
    uint8_t *stuck = malloc((size_t)n);
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", out_dir, name);
    FILE *f = fopen(path, "w");
    if (!p || !stuck || !f) {
        fprintf(stderr, "wet_scenes: cannot write %s\n", path);
        exit(1);
    }
    bench_check(wc_cloth_get_positions(w, cl, p, n), w, "positions");
    bench_check(wc_cloth_get_stuck(w, cl, stuck, n), w, "stuck");
    fprintf(f, "x,y,z,stuck\n");
    for (int32_t i = 0; i < n; ++i) fprintf(f, "%.6f,%.6f,%.6f,%d\n", p[3 * i], p[3 * i + 1], p[3 * i + 2], stuck[i]);
    if (fclose(f) != 0) {
        fprintf(stderr, "wet_scenes: writing %s failed\n", path);
        exit(1);
    }
    free(p), free(stuck);
}

static int stuck_count(const wc_world *w, int32_t cl)
{
    uint8_t s[441];
    int32_t n = wc_cloth_particle_count(w, cl);
    bench_check(wc_cloth_get_stuck(w, cl, s, n), w, "stuck");
    int c = 0;
    for (int32_t i = 0; i < n; ++i) c += s[i];
    return c;
}

static void wrap(void)
{
    for (int wet = 0; wet < 2; ++wet) {
        wc_world *w = world(-9.81);
        bench_add_thesis_sphere(w);
        wc_grid_cloth_def g = wc_grid_cloth_def_default();
        g.count_u = g.count_v = 20, g.center[2] = 0.6, g.wetness = wet;
        int32_t cl = grid(w, &g);
        for (int f = 0; f < 48; ++f) advance(w, 1.0 / 24);
        dump(w, cl, wet ? "wrap_wet.csv" : "wrap_dry.csv");
        wc_world_destroy(w);
    }
}

static void spreading(void)
{
    const double adhesion[4] = {40, 80, 40, 40}, bend[4] = {5e-2, 5e-2, 1e-1, 1e-5};
    int counts[4][73];
    for (int k = 0; k < 4; ++k) {
        wc_world *w = world(0.0);
        wc_convex_collider_def d = wc_convex_collider_def_default();
        d.radius = 0.3;
        int32_t col;
        bench_check(wc_world_add_convex_collider(w, &d, &col), w, "add sphere");
        wc_grid_cloth_def g = wc_grid_cloth_def_default();
        g.count_u = g.count_v = 21, g.center[2] = 0.304, g.wetness = 1.0;
        g.material.adhesion = adhesion[k], g.material.bend_stiffness = bend[k];
        int32_t cl = grid(w, &g);
        counts[k][0] = 0;
        for (int f = 1; f <= 72; ++f) {
            advance(w, 1.0 / 24);
            counts[k][f] = stuck_count(w, cl);
            if (k == 0 && (f == 6 || f == 24 || f == 72)) {
                char name[64];
                snprintf(name, sizeof name, "spreading_%d.csv", f);
                dump(w, cl, name);
            }
        }
        wc_world_destroy(w);
    }
    char path[4096];
    snprintf(path, sizeof path, "%s/spreading.csv", out_dir);
    FILE *f = fopen(path, "w");
    if (!f) {
        fprintf(stderr, "wet_scenes: cannot write %s\n", path);
        exit(1);
    }
    fprintf(f, "frame,adhesion 40 Pa bending 5e-2,adhesion 80 Pa bending 5e-2,adhesion 40 Pa bending 1e-1,"
               "adhesion 40 Pa bending 1e-5 (default)\n");
    for (int fr = 0; fr <= 72; ++fr)
        fprintf(f, "%d,%d,%d,%d,%d\n", fr, counts[0][fr], counts[1][fr], counts[2][fr], counts[3][fr]);
    fclose(f);
}

static void slack(void)
{
    const int n = 16;
    const double alpha = 20.0 * PI / 180.0, out = 0.15, D = 0.15;
    const double normal[3] = {0.0, cos(alpha), sin(alpha)};
    for (int wet = 0; wet < 2; ++wet) {
        wc_world *w = world(-9.81);
        double c[3] = {0, 0, 0}, u[3] = {1, 0, 0}, v[3] = {0, -sin(alpha), cos(alpha)};
        plate(w, c, u, v, 4.0);
        wc_grid_cloth_def g = wc_grid_cloth_def_default();
        g.count_u = g.count_v = n;
        for (int k = 0; k < 3; ++k) g.center[k] = 0.004 * normal[k], g.axis_v[k] = v[k];
        g.wetness = wet;
        int32_t cl = grid(w, &g), top[16];
        for (int i = 0; i < n; ++i) top[i] = (n - 1) * n + i;
        bench_check(wc_cloth_pin(w, cl, top, n), w, "pin");
        double p[3 * 256], base[3 * 16], target[3 * 16];
        bench_check(wc_cloth_get_positions(w, cl, p, 256), w, "positions");
        for (int i = 0; i < n; ++i)
            for (int k = 0; k < 3; ++k) base[3 * i + k] = p[3 * top[i] + k];
        for (int f = 0; f < 48; ++f) {
            double s = f < 24 ? (f + 1.0) / 24 : 1.0;
            for (int i = 0; i < n; ++i)
                for (int k = 0; k < 3; ++k) target[3 * i + k] = base[3 * i + k] + s * out * normal[k];
            bench_check(wc_cloth_set_pin_targets(w, cl, target, n), w, "pin targets");
            advance(w, 1.0 / 24);
        }
        dump(w, cl, wet ? "slack_wet_before.csv" : "slack_dry_before.csv");
        for (int f = 0; f < 36; ++f) {
            double s = f < 12 ? (f + 1.0) / 12 : 1.0;
            for (int i = 0; i < n; ++i) {
                for (int k = 0; k < 3; ++k) target[3 * i + k] = base[3 * i + k] + out * normal[k];
                target[3 * i] += s * D;
            }
            bench_check(wc_cloth_set_pin_targets(w, cl, target, n), w, "pin targets");
            advance(w, 1.0 / 24);
        }
        dump(w, cl, wet ? "slack_wet_after.csv" : "slack_dry_after.csv");
        wc_world_destroy(w);
    }
}

static void fold(void)
{
    const double D = 0.1, size = 2.0;
    for (int wet = 0; wet < 2; ++wet) {
        wc_world *w = world(-9.81);
        double u[3] = {1, 0, 0}, v[3] = {0, 1, 0}, centers[2][3] = {{-size / 2, 0, 0}, {size / 2, 0, 0}};
        int32_t plates[2];
        for (int k = 0; k < 2; ++k) plates[k] = plate(w, centers[k], u, v, size);
        wc_grid_cloth_def g = wc_grid_cloth_def_default();
        g.count_u = 21, g.count_v = 5, g.size_u = 1.0, g.size_v = 0.2, g.center[2] = 0.004;
        g.material.bend_stiffness = 5e-2;
        g.wetness = wet;
        int32_t cl = grid(w, &g);
        double p[3 * 105];
        bench_check(wc_cloth_get_positions(w, cl, p, 105), w, "positions");
        for (int i = 0; i < 105; ++i)
            if (fabs(p[3 * i]) < 0.15) p[3 * i + 2] += 0.02 * 0.5 * (1.0 + cos(PI * p[3 * i] / 0.15));
        bench_check(wc_cloth_set_positions(w, cl, p, 105), w, "set positions");
        for (int f = 0; f < 24; ++f) {
            double s = f < 12 ? (f + 1.0) / 12 : 1.0;
            for (int k = 0; k < 2; ++k) {
                double c[3] = {centers[k][0] + (k ? -s * D : s * D), 0, 0}, verts[12];
                plate_vertices(c, u, v, size, verts);
                bench_check(wc_collider_set_vertices(w, plates[k], verts, 4), w, "move plate");
            }
            advance(w, 1.0 / 24);
        }
        dump(w, cl, wet ? "fold_wet.csv" : "fold_dry.csv");
        wc_world_destroy(w);
    }
}

static void self_adhesion(void)
{
    for (int wet = 0; wet < 2; ++wet) {
        wc_world *w = world(+9.81); /* the pull: 1 g upward */
        wc_grid_cloth_def g = wc_grid_cloth_def_default();
        g.count_u = 21, g.count_v = 5, g.size_u = 1.0, g.size_v = 0.2, g.self_collision = 1;
        g.wetness = wet;
        int32_t cl = grid(w, &g), pins[105], pin_count = 0;
        double p[3 * 105];
        bench_check(wc_cloth_get_positions(w, cl, p, 105), w, "positions");
        for (int i = 0; i < 105; ++i) {
            int column = i % 21;
            double x = 0.05 * column;
            p[3 * i] = column <= 10 ? x - 0.5 : 0.5 - x;
            p[3 * i + 2] = column <= 10 ? 0.0 : 0.0045;
            if (column <= 10) pins[pin_count++] = i;
        }
        bench_check(wc_cloth_set_positions(w, cl, p, 105), w, "set positions");
        bench_check(wc_cloth_pin(w, cl, pins, pin_count), w, "pin");
        for (int f = 0; f < 12; ++f) advance(w, 1.0 / 24);
        dump(w, cl, wet ? "self_wet.csv" : "self_dry.csv");
        wc_world_destroy(w);
    }
}

/* Spreading scene (no output files): stuck fraction after 3 s. */
static double spread_fraction(double adhesion, double bend)
{
    wc_world *w = world(0.0);
    wc_convex_collider_def d = wc_convex_collider_def_default();
    d.radius = 0.3;
    int32_t col;
    bench_check(wc_world_add_convex_collider(w, &d, &col), w, "add sphere");
    wc_grid_cloth_def g = wc_grid_cloth_def_default();
    g.count_u = g.count_v = 21, g.center[2] = 0.304, g.wetness = 1.0;
    g.material.adhesion = adhesion, g.material.bend_stiffness = bend;
    int32_t cl = grid(w, &g);
    for (int f = 0; f < 72; ++f) advance(w, 1.0 / 24);
    double fraction = stuck_count(w, cl) / 441.0;
    wc_world_destroy(w);
    return fraction;
}

/* Fold scene (wet, no output files): highest particle at the end. */
static double fold_height(double bend)
{
    const double D = 0.1, size = 2.0;
    wc_world *w = world(-9.81);
    double u[3] = {1, 0, 0}, v[3] = {0, 1, 0}, centers[2][3] = {{-size / 2, 0, 0}, {size / 2, 0, 0}};
    int32_t plates[2];
    for (int k = 0; k < 2; ++k) plates[k] = plate(w, centers[k], u, v, size);
    wc_grid_cloth_def g = wc_grid_cloth_def_default();
    g.count_u = 21, g.count_v = 5, g.size_u = 1.0, g.size_v = 0.2, g.center[2] = 0.004;
    g.material.bend_stiffness = bend, g.wetness = 1.0;
    int32_t cl = grid(w, &g);
    double p[3 * 105], top = -INFINITY;
    bench_check(wc_cloth_get_positions(w, cl, p, 105), w, "positions");
    for (int i = 0; i < 105; ++i)
        if (fabs(p[3 * i]) < 0.15) p[3 * i + 2] += 0.02 * 0.5 * (1.0 + cos(PI * p[3 * i] / 0.15));
    bench_check(wc_cloth_set_positions(w, cl, p, 105), w, "set positions");
    for (int f = 0; f < 24; ++f) {
        double s = f < 12 ? (f + 1.0) / 12 : 1.0;
        for (int k = 0; k < 2; ++k) {
            double c[3] = {centers[k][0] + (k ? -s * D : s * D), 0, 0}, verts[12];
            plate_vertices(c, u, v, size, verts);
            bench_check(wc_collider_set_vertices(w, plates[k], verts, 4), w, "move plate");
        }
        advance(w, 1.0 / 24);
    }
    bench_check(wc_cloth_get_positions(w, cl, p, 105), w, "positions");
    for (int i = 0; i < 105; ++i) top = fmax(top, p[3 * i + 2]);
    wc_world_destroy(w);
    return top;
}

static void bending_sweep(void)
{
    const double bend[] = {1e-5, 1e-4, 5e-4, 1e-3, 3e-3, 1e-2, 2e-2, 5e-2, 1e-1};
    printf("| bending (N m) | sqrt(B / 40 Pa) (mm) | spreading: stuck fraction, 40 Pa | 30 Pa | fold: highest "
           "particle (m) |\n|---|---|---|---|---|\n");
    for (size_t k = 0; k < sizeof bend / sizeof bend[0]; ++k) {
        printf("| %g | %.1f | %.3f | %.3f | %.4f |\n", bend[k], 1e3 * sqrt(bend[k] / 40.0),
               spread_fraction(40.0, bend[k]), spread_fraction(30.0, bend[k]), fold_height(bend[k]));
        fflush(stdout);
    }
}

int main(int argc, char **argv)
{
    if (argc == 2 && strcmp(argv[1], "--bending-sweep") == 0) {
        bending_sweep();
        return 0;
    }
    if (argc != 2) {
        fprintf(stderr, "usage: wet_scenes OUTPUT_DIR | --bending-sweep\n");
        return 2;
    }
    out_dir = argv[1];
    wrap();
    spreading();
    slack();
    fold();
    self_adhesion();
    printf("wrote the scenes to %s\n", out_dir);
    return 0;
}
