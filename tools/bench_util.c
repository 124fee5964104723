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
