/* wet_dry: the thesis' drape (its Fig. 3.2-3.4), dry and wet side by side.
 *
 * Two 20 x 20 cotton cloths, 1 m wide, fall from 0.6 m onto two copies of
 * the thesis' 114-vertex solid (a UV sphere of 16 segments x 8 rings,
 * radius 0.3 m), one at x = -0.8 m, one at x = +0.8 m. The left cloth is
 * dry; the right one is soaked (wetness 1) and otherwise identical, with
 * the default wet material. Two simulated seconds at 24 frames per second,
 * substeps chosen from the stable step. The dry cloth's lower edges stand
 * off the sphere; the wet one wraps it and sticks.
 *
 *   wet_dry [OUTPUT_PREFIX [SECONDS]]     (defaults: wet_dry, 2)
 *
 * Writes OUTPUT_PREFIX_dry.obj, OUTPUT_PREFIX_wet.obj (the cloths) and
 * OUTPUT_PREFIX_spheres.obj (both solids), and prints for each cloth the
 * particles within 1 cm of its sphere and the stuck count.
 * Exit status 0 on success, 1 if a call failed (its message is printed),
 * 2 for bad arguments.
 */
#include <wetcloth.h>

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "replace_file.h"

#define GRID_N 20
#define FPS 24
#define RADIUS 0.3
#define PI 3.14159265358979323846

static const double offsets[2] = {-0.8, 0.8};
static const char *const names[2] = {"dry", "wet"};

static int ok(wc_status status, const wc_world *world, const char *call)
{
    if (status == WC_OK) return 1;
    fprintf(stderr, "wet_dry: %s failed (%s): %s\n", call, wc_status_name(status),
            world ? wc_world_last_error(world) : "");
    return 0;
}

/* UV sphere around (cx, 0, 0): 2 + 7 * 16 = 114 vertices, 224 triangles. */
static int32_t uv_sphere(double cx, double *v, int32_t *t)
{
    int32_t n = 1, k = 0, seg = 16, rings = 8;
    v[0] = cx, v[1] = 0.0, v[2] = RADIUS;
    for (int32_t j = 1; j < rings; ++j)
        for (int32_t i = 0; i < seg; ++i, ++n) {
            double polar = PI * j / rings, az = 2.0 * PI * i / seg;
            v[3 * n] = cx + RADIUS * sin(polar) * cos(az);
            v[3 * n + 1] = RADIUS * sin(polar) * sin(az);
            v[3 * n + 2] = RADIUS * cos(polar);
        }
    v[3 * n] = cx, v[3 * n + 1] = 0.0, v[3 * n + 2] = -RADIUS;
    int32_t bottom = n++, base = 1 + (rings - 2) * seg;
    for (int32_t i = 0; i < seg; ++i) t[k++] = 0, t[k++] = 1 + i, t[k++] = 1 + (i + 1) % seg;
    for (int32_t j = 0; j + 2 < rings; ++j)
        for (int32_t i = 0; i < seg; ++i) {
            int32_t a = 1 + j * seg + i, b = 1 + j * seg + (i + 1) % seg;
            t[k++] = a, t[k++] = a + seg, t[k++] = b;
            t[k++] = b, t[k++] = a + seg, t[k++] = b + seg;
        }
    for (int32_t i = 0; i < seg; ++i) t[k++] = bottom, t[k++] = base + (i + 1) % seg, t[k++] = base + i;
    return k / 3;
}

/* Writes an OBJ (positions, 0-based triangles) to path.tmp, then renames it
 * over path, so a failed run never leaves half a file. */
static int write_obj(const char *path, const char *object, const double *xyz, int32_t vertex_count,
                     const int32_t *tris, int32_t tri_count)
{
    size_t len = strlen(path);
    char *tmp = malloc(len + 5);
    if (!tmp) {
        fprintf(stderr, "wet_dry: out of memory\n");
        return 0;
    }
    memcpy(tmp, path, len);
    memcpy(tmp + len, ".tmp", 5);
    FILE *f = fopen(tmp, "w");
    if (!f) {
        fprintf(stderr, "wet_dry: cannot create %s: %s\n", tmp, strerror(errno));
        free(tmp);
        return 0;
    }
    fprintf(f, "# libwetcloth %s wet_dry demo; units: metres, z up\no %s\n", wc_version_string(), object);
    for (int32_t i = 0; i < vertex_count; ++i)
        fprintf(f, "v %.6f %.6f %.6f\n", xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
    for (int32_t i = 0; i < tri_count; ++i)
        fprintf(f, "f %d %d %d\n", (int)tris[3 * i] + 1, (int)tris[3 * i + 1] + 1, (int)tris[3 * i + 2] + 1);
    int good = !ferror(f);
    good &= fclose(f) == 0;
    if (good && replace_file(tmp, path) != 0) {
        fprintf(stderr, "wet_dry: cannot rename %s to %s: %s\n", tmp, path, strerror(errno));
        good = 0;
    } else if (!good) {
        fprintf(stderr, "wet_dry: writing %s failed\n", tmp);
    }
    if (!good) remove(tmp);
    free(tmp);
    return good;
}

/* Distance from p to the surface of the faceted sphere, by brute force. */
static double distance_to_mesh(const double p[3], const double *v, const int32_t *t, int32_t nt)
{
    double best = INFINITY;
    for (int32_t k = 0; k < nt; ++k) {
        /* sample the closest point by projecting onto the plane and clamping
         * with barycentric coordinates (Ericson, Real-Time Collision
         * Detection, 5.1.5) */
        const double *a = v + 3 * t[3 * k], *b = v + 3 * t[3 * k + 1], *c = v + 3 * t[3 * k + 2];
        double ab[3], ac[3], ap[3], q[3];
        for (int i = 0; i < 3; ++i) ab[i] = b[i] - a[i], ac[i] = c[i] - a[i], ap[i] = p[i] - a[i];
        double d1 = ab[0] * ap[0] + ab[1] * ap[1] + ab[2] * ap[2];
        double d2 = ac[0] * ap[0] + ac[1] * ap[1] + ac[2] * ap[2];
        double bp[3], cp[3];
        for (int i = 0; i < 3; ++i) bp[i] = p[i] - b[i], cp[i] = p[i] - c[i];
        double d3 = ab[0] * bp[0] + ab[1] * bp[1] + ab[2] * bp[2];
        double d4 = ac[0] * bp[0] + ac[1] * bp[1] + ac[2] * bp[2];
        double d5 = ab[0] * cp[0] + ab[1] * cp[1] + ab[2] * cp[2];
        double d6 = ac[0] * cp[0] + ac[1] * cp[1] + ac[2] * cp[2];
        double vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
        if (d1 <= 0 && d2 <= 0) memcpy(q, a, sizeof q);
        else if (d3 >= 0 && d4 <= d3) memcpy(q, b, sizeof q);
        else if (d6 >= 0 && d5 <= d6) memcpy(q, c, sizeof q);
        else if (vc <= 0 && d1 >= 0 && d3 <= 0) for (int i = 0; i < 3; ++i) q[i] = a[i] + d1 / (d1 - d3) * ab[i];
        else if (vb <= 0 && d2 >= 0 && d6 <= 0) for (int i = 0; i < 3; ++i) q[i] = a[i] + d2 / (d2 - d6) * ac[i];
        else if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
            double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
            for (int i = 0; i < 3; ++i) q[i] = b[i] + w * (c[i] - b[i]);
        } else {
            double den = 1.0 / (va + vb + vc);
            for (int i = 0; i < 3; ++i) q[i] = a[i] + ab[i] * vb * den + ac[i] * vc * den;
        }
        double d = sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]));
        if (d < best) best = d;
    }
    return best;
}

int main(int argc, char **argv)
{
    const char *prefix = argc > 1 ? argv[1] : "wet_dry";
    double seconds = 2.0;
    if (argc > 2) {
        char *end;
        seconds = strtod(argv[2], &end);
        if (*end || !(seconds > 0.0 && seconds <= 60.0)) {
            fprintf(stderr, "wet_dry: SECONDS must be in (0, 60] but is '%s'\n", argv[2]);
            return 2;
        }
    }
    if (argc > 3) {
        fprintf(stderr, "usage: wet_dry [OUTPUT_PREFIX [SECONDS]]\n");
        return 2;
    }
    wc_world_def def = wc_world_def_default();
    wc_world *world = NULL;
    wc_message msg;
    if (wc_world_create(&def, &world, &msg) != WC_OK) {
        fprintf(stderr, "wet_dry: wc_world_create failed: %s\n", msg.text);
        return 1;
    }
    int status = 1;
    double sphere_v[2][3 * 114];
    int32_t sphere_t[2][3 * 224], nt = 0, cloth[2];
    for (int k = 0; k < 2; ++k) {
        nt = uv_sphere(offsets[k], sphere_v[k], sphere_t[k]);
        wc_mesh_collider_def d = wc_mesh_collider_def_default();
        d.vertices = sphere_v[k], d.vertex_count = 114, d.triangles = sphere_t[k], d.triangle_count = nt;
        int32_t col;
        if (!ok(wc_world_add_mesh_collider(world, &d, &col), world, "wc_world_add_mesh_collider")) goto done;
        wc_grid_cloth_def g = wc_grid_cloth_def_default();
        g.count_u = g.count_v = GRID_N;
        g.center[0] = offsets[k], g.center[2] = 0.6;
        g.wetness = k; /* 0: dry, 1: soaked */
        if (!ok(wc_world_add_grid_cloth(world, &g, &cloth[k]), world, "wc_world_add_grid_cloth")) goto done;
    }
    int frames = (int)ceil(seconds * FPS - 1e-9);
    for (int f = 0; f < frames; ++f)
        if (!ok(wc_world_advance(world, seconds / frames, 0), world, "wc_world_advance")) goto done;
    enum { N = GRID_N * GRID_N };
    double p[3 * N];
    int32_t tris[3 * 2 * (GRID_N - 1) * (GRID_N - 1)];
    int32_t tri_count = wc_cloth_triangle_count(world, cloth[0]);
    if (!ok(wc_cloth_get_triangles(world, cloth[0], tris, tri_count), world, "wc_cloth_get_triangles"))
        goto done;
    size_t plen = strlen(prefix);
    char *path = malloc(plen + 16);
    if (!path) goto done;
    for (int k = 0; k < 2; ++k) {
        uint8_t stuck[N];
        if (!ok(wc_cloth_get_positions(world, cloth[k], p, N), world, "wc_cloth_get_positions") ||
            !ok(wc_cloth_get_stuck(world, cloth[k], stuck, N), world, "wc_cloth_get_stuck")) {
            free(path);
            goto done;
        }
        int near = 0, stuck_count = 0;
        for (int i = 0; i < N; ++i) {
            near += distance_to_mesh(p + 3 * i, sphere_v[k], sphere_t[k], nt) < 0.01;
            stuck_count += stuck[i];
        }
        sprintf(path, "%s_%s.obj", prefix, names[k]);
        if (!write_obj(path, names[k], p, N, tris, tri_count)) {
            free(path);
            goto done;
        }
        printf("%s cloth: %d of %d particles within 1 cm of the sphere, %d stuck; wrote %s\n", names[k],
               near, N, stuck_count, path);
    }
    {
        double v[2 * 3 * 114];
        int32_t t[2 * 3 * 224];
        memcpy(v, sphere_v[0], sizeof sphere_v[0]);
        memcpy(v + 3 * 114, sphere_v[1], sizeof sphere_v[1]);
        for (int32_t i = 0; i < 3 * nt; ++i) t[i] = sphere_t[0][i], t[3 * nt + i] = sphere_t[1][i] + 114;
        sprintf(path, "%s_spheres.obj", prefix);
        if (!write_obj(path, "spheres", v, 2 * 114, t, 2 * nt)) {
            free(path);
            goto done;
        }
        printf("wrote %s (2 x 114 vertices, %d triangles), t = %.3f s\n", path, 2 * nt, wc_world_time(world));
    }
    free(path);
    status = 0;
done:
    wc_world_destroy(world);
    return status;
}
