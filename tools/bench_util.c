#define _POSIX_C_SOURCE 200809L
#include "bench_util.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#define PI 3.14159265358979323846

double bench_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

void bench_check(wc_status s, const wc_world *w, const char *what)
{
    if (s == WC_OK) return;
    fprintf(stderr, "%s failed: %s: %s\n", what, wc_status_name(s), w ? wc_world_last_error(w) : "");
    exit(1);
}

void bench_add_thesis_sphere(wc_world *w)
{
    double v[3 * 114];
    int32_t t[3 * 224], n = 0, k = 0, seg = 16, rings = 8, col;
    v[0] = v[1] = 0.0, v[2] = 0.3, n = 1;
    for (int32_t j = 1; j < rings; ++j)
        for (int32_t i = 0; i < seg; ++i, ++n) {
            double polar = PI * j / rings, az = 2.0 * PI * i / seg;
            v[3 * n] = 0.3 * sin(polar) * cos(az);
            v[3 * n + 1] = 0.3 * sin(polar) * sin(az);
            v[3 * n + 2] = 0.3 * cos(polar);
        }
    v[3 * n] = v[3 * n + 1] = 0.0, v[3 * n + 2] = -0.3;
    int32_t bottom = n++, base = 1 + (rings - 2) * seg;
    for (int32_t i = 0; i < seg; ++i) t[k++] = 0, t[k++] = 1 + i, t[k++] = 1 + (i + 1) % seg;
    for (int32_t j = 0; j + 2 < rings; ++j)
        for (int32_t i = 0; i < seg; ++i) {
            int32_t a = 1 + j * seg + i, b = 1 + j * seg + (i + 1) % seg;
            t[k++] = a, t[k++] = a + seg, t[k++] = b;
            t[k++] = b, t[k++] = a + seg, t[k++] = b + seg;
        }
    for (int32_t i = 0; i < seg; ++i) t[k++] = bottom, t[k++] = base + (i + 1) % seg, t[k++] = base + i;
    wc_mesh_collider_def d = wc_mesh_collider_def_default();
    d.vertices = v, d.vertex_count = n, d.triangles = t, d.triangle_count = k / 3;
    bench_check(wc_world_add_mesh_collider(w, &d, &col), w, "add sphere");
}

static void add_ground(wc_world *w, double half)
{
    double v[12] = {-half, -half, 0, half, -half, 0, half, half, 0, -half, half, 0};
    int32_t t[6] = {0, 1, 2, 0, 2, 3}, col;
    wc_mesh_collider_def d = wc_mesh_collider_def_default();
    d.vertices = v, d.vertex_count = 4, d.triangles = t, d.triangle_count = 2;
    bench_check(wc_world_add_mesh_collider(w, &d, &col), w, "add ground");
}

wc_world *bench_resting_world(int size, int self_collision, int threads, double *out_dt)
{
    wc_world_def wd = wc_world_def_default();
    wd.thread_count = threads;
    wd.adapt_threads = 0; /* measured at exactly this count */
    wc_world *w;
    wc_message m;
    bench_check(wc_world_create(&wd, &w, &m), NULL, m.text);
    double width = (size - 1) / 63.0;
    add_ground(w, width);
    wc_grid_cloth_def g = wc_grid_cloth_def_default();
    g.count_u = g.count_v = size;
    g.size_u = g.size_v = width;
    g.center[2] = g.material.thickness * 1.01;
    g.self_collision = self_collision;
    int32_t c;
    bench_check(wc_world_add_grid_cloth(w, &g, &c), w, "add cloth");
    double dt = wc_world_stable_dt(w);
    for (int k = 0; k < 20; ++k) bench_check(wc_world_step(w, dt), w, "step");
    *out_dt = dt;
    return w;
}

void bench_check_resting(const wc_world *w, int size)
{
    if (wc_world_get_stats(w).collider_contacts < size * size / 2) {
        fprintf(stderr, "resting %dx%d: the cloth is not on the ground\n", size, size);
        exit(1);
    }
}
