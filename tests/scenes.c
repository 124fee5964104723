#include "scenes.h"

#include "primitives.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846

int32_t scene_uv_sphere(double r, int32_t seg, int32_t rings, double *v, int32_t *t,
                        int32_t *triangle_count)
{
    int32_t n = 0, k = 0;
    v[0] = 0.0, v[1] = 0.0, v[2] = r;
    n = 1;
    for (int32_t j = 1; j < rings; ++j) {
        double polar = PI * j / rings;
        for (int32_t i = 0; i < seg; ++i, ++n) {
            double azimuth = 2.0 * PI * i / seg;
            v[3 * n] = r * sin(polar) * cos(azimuth);
            v[3 * n + 1] = r * sin(polar) * sin(azimuth);
            v[3 * n + 2] = r * cos(polar);
        }
    }
    v[3 * n] = 0.0, v[3 * n + 1] = 0.0, v[3 * n + 2] = -r;
    int32_t bottom = n++;
    for (int32_t i = 0; i < seg; ++i) {
        t[k++] = 0, t[k++] = 1 + i, t[k++] = 1 + (i + 1) % seg;
    }
    for (int32_t j = 0; j + 2 < rings; ++j)
        for (int32_t i = 0; i < seg; ++i) {
            int32_t a = 1 + j * seg + i, b = 1 + j * seg + (i + 1) % seg, c = a + seg, d = b + seg;
            t[k++] = a, t[k++] = c, t[k++] = b;
            t[k++] = b, t[k++] = c, t[k++] = d;
        }
    int32_t base = 1 + (rings - 2) * seg;
    for (int32_t i = 0; i < seg; ++i) {
        t[k++] = bottom, t[k++] = base + (i + 1) % seg, t[k++] = base + i;
    }
    *triangle_count = k / 3;
    return n;
}

wc_world *scene_world_from(const wc_world_def *def)
{
    wc_world *w = NULL;
    wc_message msg;
    if (wc_world_create(def, &w, &msg) != WC_OK) {
        fprintf(stderr, "wc_world_create: %s\n", msg.text);
        exit(1);
    }
    return w;
}

wc_world *scene_world(int32_t threads)
{
    wc_world_def def = wc_world_def_default();
    /* The scenes' criteria were measured with Verlet, the thesis' own
     * integrator and the reference the others are measured against; the
     * default (the implicit integrator) has tests of its own
     * (test_integrators.c). */
    def.integrator = WC_INTEGRATOR_VERLET;
    def.thread_count = threads;
    return scene_world_from(&def);
}

int32_t scene_add_grid(wc_world *w, const wc_grid_cloth_def *def)
{
    int32_t id = -1;
    if (wc_world_add_grid_cloth(w, def, &id) != WC_OK) {
        fprintf(stderr, "wc_world_add_grid_cloth: %s\n", wc_world_last_error(w));
        exit(1);
    }
    return id;
}

int32_t scene_add_thesis_sphere(wc_world *w, double radius)
{
    double v[3 * 114];
    int32_t t[3 * 224], nt, out = -1;
    wc_mesh_collider_def d = wc_mesh_collider_def_default();
    d.vertex_count = scene_uv_sphere(radius, 16, 8, v, t, &nt);
    d.vertices = v;
    d.triangles = t;
    d.triangle_count = nt;
    if (wc_world_add_mesh_collider(w, &d, &out) != WC_OK) {
        fprintf(stderr, "scene_add_thesis_sphere: %s\n", wc_world_last_error(w));
        exit(1);
    }
    return out;
}

void scene_plate_vertices(const double c[3], const double u[3], const double v[3], double size,
                          double out[12])
{
    static const double su[4] = {-0.5, 0.5, 0.5, -0.5}, sv[4] = {-0.5, -0.5, 0.5, 0.5};
    for (int i = 0; i < 4; ++i)
        for (int k = 0; k < 3; ++k) out[3 * i + k] = c[k] + size * (su[i] * u[k] + sv[i] * v[k]);
}

int32_t scene_add_plate(wc_world *w, const double c[3], const double u[3], const double v[3],
                        double size, double thickness)
{
    double verts[12];
    static const int32_t tris[6] = {0, 1, 2, 0, 2, 3};
    scene_plate_vertices(c, u, v, size, verts);
    wc_mesh_collider_def d = wc_mesh_collider_def_default();
    d.vertices = verts;
    d.vertex_count = 4;
    d.triangles = tris;
    d.triangle_count = 2;
    d.thickness = thickness;
    int32_t out = -1;
    if (wc_world_add_mesh_collider(w, &d, &out) != WC_OK) {
        fprintf(stderr, "scene_add_plate: %s\n", wc_world_last_error(w));
        exit(1);
    }
    return out;
}

uint64_t scene_hash_positions(const wc_world *w, int32_t cloth)
{
    int32_t n = wc_cloth_particle_count(w, cloth);
    double *p = malloc(3 * sizeof(double) * (size_t)n);
    wc_cloth_get_positions(w, cloth, p, n);
    uint64_t h = 1469598103934665603ull;
    const unsigned char *bytes = (const unsigned char *)p;
    for (size_t i = 0; i < 3 * sizeof(double) * (size_t)n; ++i) {
        h ^= bytes[i];
        h *= 1099511628211ull;
    }
    free(p);
    return h;
}

void scene_distances_to_mesh(const double *points, int32_t count, const double *vertices,
                             const int32_t *triangles, int32_t triangle_count, double *out)
{
    double bary[3];
    for (int32_t i = 0; i < count; ++i) {
        double best = INFINITY;
        for (int32_t k = 0; k < triangle_count; ++k) {
            const int32_t *c = triangles + 3 * (size_t)k;
            double d = wci_point_triangle_closest(points + 3 * (size_t)i, vertices + 3 * c[0],
                                                 vertices + 3 * c[1], vertices + 3 * c[2], bary);
            if (d < best) best = d;
        }
        out[i] = sqrt(best);
    }
}

int scene_count_near_sphere(const wc_world *w, int32_t cloth, double radius, double within)
{
    double v[3 * 114];
    int32_t t[3 * 224], nt, near = 0, n = wc_cloth_particle_count(w, cloth);
    double *p = malloc(3 * sizeof(double) * (size_t)n), *d = malloc(sizeof(double) * (size_t)n);
    if (!p || !d) {
        free(p), free(d);
        return -1;
    }
    scene_uv_sphere(radius, 16, 8, v, t, &nt);
    wc_cloth_get_positions(w, cloth, p, n);
    scene_distances_to_mesh(p, n, v, t, nt, d);
    for (int32_t i = 0; i < n; ++i) near += d[i] < within;
    free(p), free(d);
    return near;
}

int scene_intersections(const wc_world *w)
{
    wc_intersection_counts c;
    if (wc_world_count_intersections(w, &c) != WC_OK) {
        fprintf(stderr, "wc_world_count_intersections: %s\n", wc_world_last_error(w));
        return 1000000;
    }
    return c.cloth_cloth + c.cloth_collider;
}
