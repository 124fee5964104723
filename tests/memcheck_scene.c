/* A short full scene for valgrind memcheck (ctest memcheck_scene,
 * when valgrind is installed): a soaked, self-colliding 16 x 16 cloth with a
 * moving pinned corner falls onto the thesis sphere (mesh collider) beside
 * a box and a convex hull, plus a dry triangle-mesh cloth, for 0.1 s of
 * automatic substeps at 1/240 s frames, reading every output back. memcheck
 * must report 0 errors and 0 leaks (it runs with --error-exitcode). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "scenes.h"
#include "wetcloth.h"

#define SIDE 10
#define FRAMES 8

static void ok(wc_world *w, wc_status s, const char *what)
{
    if (s != WC_OK) {
        fprintf(stderr, "memcheck_scene: %s: %s\n", what, w ? wc_world_last_error(w) : "");
        exit(1);
    }
}

int main(void)
{
    wc_world_def def = wc_world_def_default();
    def.thread_count = 1; /* memcheck runs threads one at a time anyway */
    wc_world *w = NULL;
    wc_message msg;
    if (wc_world_create(&def, &w, &msg) != WC_OK) {
        fprintf(stderr, "memcheck_scene: %s\n", msg.text);
        return 1;
    }
    wc_grid_cloth_def g = wc_grid_cloth_def_default();
    g.count_u = g.count_v = SIDE;
    g.center[2] = 0.35;
    g.self_collision = 1;
    g.wetness = 1.0;
    g.material.wicking = 0.001;
    g.material.drying = 0.1;
    int32_t cloth, mesh_cloth, id;
    ok(w, wc_world_add_grid_cloth(w, &g, &cloth), "grid cloth");
    double v[3 * 4] = {-0.2, -0.2, 0.6, 0.2, -0.2, 0.6, 0.2, 0.2, 0.62, -0.2, 0.2, 0.6};
    int32_t f[4] = {0, 1, 2, 3};
    wc_mesh_cloth_def m = wc_mesh_cloth_def_default();
    m.vertices = v;
    m.vertex_count = 4;
    m.faces = f;
    m.face_count = 1;
    m.face_size = 4;
    ok(w, wc_world_add_mesh_cloth(w, &m, &mesh_cloth), "mesh cloth");
    scene_add_thesis_sphere(w, 0.3);
    wc_convex_collider_def box = wc_convex_collider_def_default();
    box.shape = WC_SHAPE_BOX;
    box.position[0] = 0.5;
    ok(w, wc_world_add_convex_collider(w, &box, &id), "box");
    static const double hull[] = {0, 0, 0, 0.2, 0, 0, 0, 0.2, 0, 0, 0, 0.2, 0.1, 0.1, 0.1};
    wc_convex_collider_def h = wc_convex_collider_def_default();
    h.shape = WC_SHAPE_CONVEX_HULL;
    h.points = hull;
    h.point_count = 5;
    h.position[0] = -0.6;
    ok(w, wc_world_add_convex_collider(w, &h, &id), "hull");
    int32_t pin = SIDE * SIDE - 1;
    ok(w, wc_cloth_pin(w, cloth, &pin, 1), "pin");

    static double xyz[3 * SIDE * SIDE];
    static double wet[SIDE * SIDE];
    static uint8_t flags[SIDE * SIDE];
    for (int frame = 0; frame < FRAMES; ++frame) {
        double target[3] = {0.5, 0.5, 0.35 + 0.002 * frame};
        ok(w, wc_cloth_set_pin_targets(w, cloth, target, 1), "pin target");
        double pos[3] = {0.5, 0.0, 0.001 * frame}, rot[4] = {1, 0, 0, 0};
        ok(w, wc_collider_set_transform(w, 1, pos, rot), "move box");
        ok(w, wc_world_advance(w, 1.0 / 240.0, 0), "advance");
        ok(w, wc_cloth_get_positions(w, cloth, xyz, SIDE * SIDE), "positions");
        ok(w, wc_cloth_get_wetness(w, cloth, wet, SIDE * SIDE), "wetness");
        ok(w, wc_cloth_get_stuck(w, cloth, flags, SIDE * SIDE), "stuck");
        for (int i = 0; i < 3 * SIDE * SIDE; ++i)
            if (!isfinite(xyz[i])) {
                fprintf(stderr, "memcheck_scene: non-finite position\n");
                return 1;
            }
    }
    wc_intersection_counts counts;
    ok(w, wc_world_count_intersections(w, &counts), "intersections");
    wc_step_stats st = wc_world_get_stats(w);
    printf("memcheck_scene: %.3f s simulated, %d substeps per frame, %d collider and %d cloth "
           "contacts, %d stuck\n", wc_world_time(w), (int)wc_world_last_substeps(w),
           (int)st.collider_contacts, (int)st.cloth_contacts, (int)st.stuck_particles);
    wc_world_destroy(w);
    return 0;
}
