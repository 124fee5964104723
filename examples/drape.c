/* drape: the libwetcloth demo.
 *
 * A 1 m x 1 m cotton cloth of 32 x 32 particles starts flat and level, 1 m
 * above the ground, held by its two corners at y = +0.5 m. It falls, swings
 * and drapes for two simulated seconds at 24 frames per second, with the
 * substep count chosen from the stable time step. The final mesh is written
 * as a Wavefront OBJ.
 *
 *   drape [OUTPUT.obj [SECONDS]]      (defaults: drape.obj, 2)
 *
 * Exit status 0 on success, 1 if a call failed (its message is printed),
 * 2 for bad arguments.
 */
#include <wetcloth.h>

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "replace_file.h"

#define GRID_N 32
#define FPS 24

static int ok(wc_status status, const wc_world *world, const char *call)
{
    if (status == WC_OK) return 1;
    fprintf(stderr, "drape: %s failed (%s): %s\n", call, wc_status_name(status),
            world ? wc_world_last_error(world) : "");
    return 0;
}

/* Writes positions and triangles as OBJ to `path`, through a temporary file
 * in the same folder that is renamed over `path` only once it is complete. */
static int write_obj(const char *path, const double *xyz, int32_t vertex_count,
                     const int32_t *tris, int32_t tri_count, double seconds)
{
    size_t len = strlen(path);
    char *tmp = malloc(len + 32);
    FILE *f;
    int32_t i;
    int good;

    if (!tmp) {
        fprintf(stderr, "drape: out of memory\n");
        return 0;
    }
    /* A name unlikely to clash with another run writing the same file. */
    sprintf(tmp, "%s.%lx.tmp", path,
            ((unsigned long)time(NULL) ^ (unsigned long)clock() ^ (unsigned long)(size_t)&f) & 0xffffffUL);
    f = fopen(tmp, "w");
    if (!f) {
        fprintf(stderr, "drape: cannot create %s: %s\n", tmp, strerror(errno));
        free(tmp);
        return 0;
    }
    fprintf(f, "# libwetcloth %s drape demo, %d x %d particles, t = %.3f s\n",
            wc_version_string(), GRID_N, GRID_N, seconds);
    fprintf(f, "# units: metres, z up\no drape\n");
    for (i = 0; i < vertex_count; ++i)
        fprintf(f, "v %.9g %.9g %.9g\n", xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
    for (i = 0; i < tri_count; ++i)
        fprintf(f, "f %ld %ld %ld\n", (long)tris[3 * i] + 1, (long)tris[3 * i + 1] + 1,
                (long)tris[3 * i + 2] + 1);
    good = !ferror(f);
    if (fclose(f) != 0) good = 0;
    if (!good) {
        fprintf(stderr, "drape: writing %s failed: %s\n", tmp, strerror(errno));
        remove(tmp);
        free(tmp);
        return 0;
    }
    if (replace_file(tmp, path) != 0) {
        fprintf(stderr, "drape: cannot rename %s to %s: %s\n", tmp, path, strerror(errno));
        remove(tmp);
        free(tmp);
        return 0;
    }
    free(tmp);
    return 1;
}

int main(int argc, char **argv)
{
    const char *out_path = "drape.obj";
    double seconds = 2.0;
    wc_world_def world_def = wc_world_def_default();
    wc_grid_cloth_def grid = wc_grid_cloth_def_default();
    wc_message message;
    wc_world *world = NULL;
    int32_t cloth = -1, count = 0, tri_count = 0, frames, frame, pins[2];
    int32_t total_substeps = 0;
    double *xyz = NULL;
    int32_t *tris = NULL;
    double lowest = INFINITY, highest = -INFINITY;
    int status = 1, i;

    if (argc > 1 && (strcmp(argv[1], "-h") == 0 || strcmp(argv[1], "--help") == 0)) {
        printf("usage: %s [OUTPUT.obj [SECONDS]]   (defaults: drape.obj, 2)\n", argv[0]);
        return 0;
    }
    if (argc > 3) {
        fprintf(stderr, "usage: %s [OUTPUT.obj [SECONDS]]\n", argv[0]);
        return 2;
    }
    if (argc > 1) out_path = argv[1];
    if (argc > 2) {
        char *end = NULL;
        seconds = strtod(argv[2], &end);
        if (end == argv[2] || *end != '\0' || !(seconds > 0.0) || seconds > 3600.0) {
            fprintf(stderr, "drape: SECONDS must be a number in (0, 3600], got '%s'\n", argv[2]);
            return 2;
        }
    }
    frames = (int32_t)ceil(seconds * FPS - 1e-9);
    if (frames < 1) frames = 1;

    printf("libwetcloth %s: drape demo, %d x %d cloth, %.2f s at %d fps\n",
           wc_version_string(), GRID_N, GRID_N, frames / (double)FPS, FPS);

    if (!ok(wc_world_create(&world_def, &world, &message), NULL, "wc_world_create")) {
        fprintf(stderr, "  %s\n", message.text);
        return 1;
    }

    /* Level cloth in the plane z = 1 (the default material is cotton). */
    grid.count_u = GRID_N;
    grid.count_v = GRID_N;
    grid.size_u = 1.0;
    grid.size_v = 1.0;
    grid.center[0] = 0.0;
    grid.center[1] = 0.0;
    grid.center[2] = 1.0;
    if (!ok(wc_world_add_grid_cloth(world, &grid, &cloth), world, "wc_world_add_grid_cloth"))
        goto done;
    count = wc_cloth_particle_count(world, cloth);

    /* Pin the two corners of the last row (j = GRID_N - 1, at y = +0.5). */
    pins[0] = (GRID_N - 1) * GRID_N;
    pins[1] = GRID_N * GRID_N - 1;
    if (!ok(wc_cloth_pin(world, cloth, pins, 2), world, "wc_cloth_pin")) goto done;

    printf("%d particles, %d stretch links, %d bend links, %d pinned\n", (int)count,
           (int)wc_cloth_link_count(world, cloth, WC_LINK_STRETCH),
           (int)wc_cloth_link_count(world, cloth, WC_LINK_BEND),
           (int)wc_cloth_pin_count(world, cloth));
    printf("stable dt %.3g s (safety %.2f): substeps chosen per frame automatically\n",
           wc_world_stable_dt(world), world_def.substep_safety);

    for (frame = 1; frame <= frames; ++frame) {
        if (!ok(wc_world_advance(world, 1.0 / FPS, 0), world, "wc_world_advance")) {
            fprintf(stderr, "  at frame %d, t = %.4f s\n", (int)frame, wc_world_time(world));
            goto done;
        }
        total_substeps += wc_world_last_substeps(world);
        if (frame == 1 || frame % FPS == 0 || frame == frames) {
            wc_energy e;
            if (!ok(wc_cloth_get_energy(world, cloth, &e), world, "wc_cloth_get_energy"))
                goto done;
            printf("frame %3d  t = %5.3f s  substeps %4d  kinetic %.3e J  stretch %.3e J"
                   "  bend %.3e J\n",
                   (int)frame, wc_world_time(world), (int)wc_world_last_substeps(world),
                   e.kinetic, e.stretch, e.bend);
        }
    }

    xyz = malloc(sizeof *xyz * 3 * (size_t)count);
    tri_count = wc_cloth_triangle_count(world, cloth);
    tris = malloc(sizeof *tris * 3 * (size_t)(tri_count > 0 ? tri_count : 1));
    if (!xyz || !tris) {
        fprintf(stderr, "drape: out of memory\n");
        goto done;
    }
    if (!ok(wc_cloth_get_positions(world, cloth, xyz, count), world, "wc_cloth_get_positions"))
        goto done;
    if (!ok(wc_cloth_get_triangles(world, cloth, tris, tri_count), world,
            "wc_cloth_get_triangles"))
        goto done;
    for (i = 0; i < 3 * count; ++i) {
        if (!isfinite(xyz[i])) {
            fprintf(stderr, "drape: coordinate %d of the result is not finite\n", i);
            goto done;
        }
        if (i % 3 == 2) {
            if (xyz[i] < lowest) lowest = xyz[i];
            if (xyz[i] > highest) highest = xyz[i];
        }
    }
    printf("done: %d frames, %d substeps in all, cloth spans z = %.3f .. %.3f m\n", (int)frames,
           (int)total_substeps, lowest, highest);

    if (!write_obj(out_path, xyz, count, tris, tri_count, wc_world_time(world))) goto done;
    printf("wrote %s (%d vertices, %d triangles)\n", out_path, (int)count, (int)tri_count);
    status = 0;

done:
    free(tris);
    free(xyz);
    wc_world_destroy(world);
    return status;
}
