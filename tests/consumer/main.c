/* Uses libwetcloth through its public header only: creates a world, adds a
 * grid cloth, pins two corners, steps, reads the positions back and checks
 * that they are finite and that the cloth fell. Exit 0 on success. */
#include <wetcloth.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#ifndef CONSUMER_KIND
#define CONSUMER_KIND "pkg-config"
#endif

static int check(wc_status status, const wc_world *world, const char *what)
{
    if (status == WC_OK) return 1;
    fprintf(stderr, "consumer (%s): %s failed: %s: %s\n", CONSUMER_KIND, what,
            wc_status_name(status), world ? wc_world_last_error(world) : "");
    return 0;
}

int main(void)
{
    wc_world_def world_def = wc_world_def_default();
    wc_grid_cloth_def grid = wc_grid_cloth_def_default();
    wc_message message;
    wc_world *world = NULL;
    int32_t cloth = -1, count, i, pins[2];
    double *xyz = NULL, lowest = INFINITY;
    int ok = 0;

    if (wc_version() != WC_VERSION) {
        fprintf(stderr, "consumer: header version %d but library version %d (%s)\n",
                (int)WC_VERSION, (int)wc_version(), wc_version_string());
        return 1;
    }
    world_def.thread_count = 2;
    if (!check(wc_world_create(&world_def, &world, &message), NULL, "wc_world_create")) {
        fprintf(stderr, "  %s\n", message.text);
        return 1;
    }
    grid.count_u = 12;
    grid.count_v = 12;
    grid.center[2] = 1.0;
    if (!check(wc_world_add_grid_cloth(world, &grid, &cloth), world, "wc_world_add_grid_cloth"))
        goto done;
    count = wc_cloth_particle_count(world, cloth);
    pins[0] = 0;
    pins[1] = grid.count_u - 1;
    if (!check(wc_cloth_pin(world, cloth, pins, 2), world, "wc_cloth_pin")) goto done;
    for (i = 0; i < 6; ++i)
        if (!check(wc_world_advance(world, 1.0 / 24.0, 0), world, "wc_world_advance")) goto done;

    xyz = malloc(sizeof *xyz * 3 * (size_t)count);
    if (!xyz) goto done;
    if (!check(wc_cloth_get_positions(world, cloth, xyz, count), world, "wc_cloth_get_positions"))
        goto done;
    for (i = 0; i < 3 * count; ++i) {
        if (!isfinite(xyz[i])) {
            fprintf(stderr, "consumer: coordinate %d is not finite\n", (int)i);
            goto done;
        }
        if (i % 3 == 2 && xyz[i] < lowest) lowest = xyz[i];
    }
    if (!(lowest < 0.9)) {
        fprintf(stderr, "consumer: the cloth did not fall (lowest z %g)\n", lowest);
        goto done;
    }
    printf("consumer (%s): libwetcloth %s, %d particles, %.3f s simulated, "
           "%d substeps/frame, lowest z %.3f m\n",
           CONSUMER_KIND, wc_version_string(), (int)count, wc_world_time(world),
           (int)wc_world_last_substeps(world), lowest);
    ok = 1;
done:
    free(xyz);
    wc_world_destroy(world);
    return ok ? 0 : 1;
}
