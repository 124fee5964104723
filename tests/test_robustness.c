/* Regressions found by fuzzing (tests/fuzz): each case is what a
 * fuzz input reduced to, checked in the normal and the sanitizer builds. */
#include <math.h>
#include <string.h>
#include <time.h>

#include "collider.h"
#include "grid.h"
#include "primitives.h"
#include "test_util.h"
#include "wetcloth.h"
#include "world.h"

static wc_world *world(void)
{
    wc_world_def def = wc_world_def_default();
    def.thread_count = 1;
    wc_world *w = NULL;
    wc_message msg;
    CHECK(wc_world_create(&def, &w, &msg) == WC_OK, "world: %s", msg.text);
    return w;
}

/* wc_cloth_set_pin_targets with no pins and count 0 is a valid no-op (it
 * passed a NULL destination to memcpy: undefined behaviour). */
static void pin_targets_without_pins(void)
{
    wc_world *w = world();
    wc_grid_cloth_def g = wc_grid_cloth_def_default();
    g.count_u = g.count_v = 4;
    int32_t c;
    CHECK(wc_world_add_grid_cloth(w, &g, &c) == WC_OK, "grid: %s", wc_world_last_error(w));
    double none[3] = {0.0, 0.0, 0.0};
    CHECK(wc_cloth_set_pin_targets(w, c, none, 0) == WC_OK, "no pins, no targets: %s",
          wc_world_last_error(w));
    CHECK(wc_cloth_set_pin_targets(w, c, none, 1) == WC_ERROR_INVALID_ARGUMENT,
          "one target for no pins must be refused");
    CHECK(wc_world_last_error(w)[0] != '\0', "and say why");
    wc_world_destroy(w);
}

/* The broadphase grid takes NaN boxes (positions of a step that is going
 * non-finite, caught after collision) and boxes spanning the whole double
 * range (their cell count overflowed int64) without undefined behaviour,
 * and a query still finds what it overlaps. */
static void grid_awkward_boxes(void)
{
    double boxes[4 * 6] = {
        0.0, 0.0, 0.0, 0.1, 0.1, 0.1,                         /* ordinary */
        NAN, NAN, NAN, NAN, NAN, NAN,                         /* NaN */
        -1e300, -1e300, -1e300, 1e300, 1e300, 1e300,          /* everything */
        -INFINITY, 0.0, 0.0, INFINITY, 0.05, 0.05,            /* infinite */
    };
    wc_grid g;
    memset(&g, 0, sizeof g);
    CHECK(wci_grid_update(&g, boxes, 4, 0.1) == WC_OK, "build");
    int32_t found[8];
    double q[6] = {0.05, 0.05, 0.05, 0.06, 0.06, 0.06};
    int32_t n = wci_grid_query(&g, q, found, 8);
    CHECK(n == 3 && found[0] == 0 && found[1] == 2 && found[2] == 3,
          "query finds the ordinary, the everything and the infinite box (%d found)", (int)n);
    double huge[6] = {-1e300, -1e300, -1e300, 1e300, 1e300, 1e300};
    n = wci_grid_query(&g, huge, found, 8);
    CHECK(n == 3, "a query over everything finds the 3 boxes that are not NaN (%d)", (int)n);
    double nan_box[6] = {NAN, NAN, NAN, NAN, NAN, NAN};
    n = wci_grid_query(&g, nan_box, found, 8);
    CHECK(n >= 0 && n <= 4, "a NaN query returns a count (%d)", (int)n);
    wci_grid_destroy(&g);
}

/* An empty box (min above max on an axis: the box of triangle corners whose
 * coordinates there were all NaN) among ordinary ones: its negative cell
 * span went into the entry count, and the other items' cells were written
 * past the end of the entries (heap overflow under ASan; found by
 * fuzzing). It covers no cell and no query finds it; an empty query box
 * finds nothing, without visiting the cells of its other axes. */
static void grid_empty_box(void)
{
    double boxes[5 * 6] = {
        0.0, 0.0, 0.0, 0.1, 0.1, 0.1,
        0.05, 0.0, INFINITY, 0.3, 0.1, -INFINITY, /* empty along z */
        0.2, 0.2, 0.2, 0.3, 0.3, 0.3,
        0.0, 0.0, 0.0, 0.35, 0.35, 0.35,
        INFINITY, 0.0, 0.0, -INFINITY, 0.1, 0.1, /* empty along x */
    };
    wc_grid g;
    memset(&g, 0, sizeof g);
    CHECK(wci_grid_update(&g, boxes, 5, 0.1) == WC_OK, "build");
    int32_t found[8];
    double everything[6] = {-10.0, -10.0, -10.0, 10.0, 10.0, 10.0};
    int32_t n = wci_grid_query(&g, everything, found, 8);
    CHECK(n == 3 && found[0] == 0 && found[1] == 2 && found[2] == 3,
          "a query over everything finds the three boxes that are not empty (%d found)", (int)n);
    double q[6] = {0.21, 0.21, 0.21, 0.22, 0.22, 0.22};
    n = wci_grid_query(&g, q, found, 8);
    CHECK(n == 2 && found[0] == 2 && found[1] == 3, "a small query finds boxes 2 and 3 (%d found)", (int)n);
    /* empty along x, the whole double range along y and z: the query
     * looped over 2e9 x 2e9 cells of y and z (a fuzz input's timeout) */
    double empty_query[6] = {INFINITY, -1e300, -1e300, -INFINITY, 1e300, 1e300};
    n = wci_grid_query(&g, empty_query, found, 8);
    CHECK(n == 0, "an empty query finds nothing (%d found)", (int)n);
    wci_grid_destroy(&g);
    double wide_empty[6] = {INFINITY, -1e300, -1e300, -INFINITY, 1e300, 1e300};
    memset(&g, 0, sizeof g);
    CHECK(wci_grid_update(&g, wide_empty, 1, 0.1) == WC_OK, "build with an empty box spanning y and z");
    n = wci_grid_query(&g, everything, found, 8);
    CHECK(n == 0, "the empty box is found (%d)", (int)n);
    wci_grid_destroy(&g);
}

/* A mesh collider moved from near the most negative double to near the
 * largest: across the substeps its vertices were current + (target -
 * current) * share, the difference overflowed, and they became NaN, which
 * stayed in the collider after the step (found by fuzzing; their empty
 * boxes then overflowed the grid above). Every substep's vertices are
 * finite now, and the usual interpolation keeps its bits. */
static void collider_across_the_doubles(void)
{
    CHECK(wc_lerp(-1.5e308, 1.5e308, 0.5) == 0.0 && wc_lerp(-1.5e308, 1.5e308, 0.25) == -0.75e308,
          "lerp across the doubles: %g, %g", wc_lerp(-1.5e308, 1.5e308, 0.5),
          wc_lerp(-1.5e308, 1.5e308, 0.25));
    CHECK(wc_lerp(0.1, 0.7, 0.3) == 0.1 + (0.7 - 0.1) * 0.3, "lerp changed its bits");
    wc_world *w = world();
    double v[9] = {-1.5e308, 0.0, 0.0, -1.5e308, 1.0, 0.0, -1.5e308, 0.0, 1.0};
    int32_t tri[3] = {0, 1, 2}, id;
    wc_mesh_collider_def d = wc_mesh_collider_def_default();
    d.vertices = v;
    d.vertex_count = 3;
    d.triangles = tri;
    d.triangle_count = 1;
    CHECK(wc_world_add_mesh_collider(w, &d, &id) == WC_OK, "collider: %s", wc_world_last_error(w));
    for (int k = 0; k < 9; k += 3) v[k] = 1.5e308;
    CHECK(wc_collider_set_vertices(w, id, v, 3) == WC_OK, "move: %s", wc_world_last_error(w));
    wc_collider *c = w->colliders[id];
    int bad = 0;
    for (int step = 1; step <= 4; ++step) {
        CHECK(wci_collider_begin_step(c, step / 4.0) == WC_OK, "begin step %d", step);
        for (int k = 0; k < 9; ++k) bad += !isfinite(c->next[k]);
    }
    CHECK(bad == 0, "%d collider coordinates not finite across the substeps", bad);
    wc_world_destroy(w);
}

/* Wicking over a link far shorter than the rest of the cloth: with 1e-6 m
 * next to 0.5 m it needed about 1e9 diffusion substeps, and the step did
 * not end in minutes; with 1e-9 m the count overflowed int (undefined).
 * It now takes at most 64 and the wetness stays in [0, 1]. */
static void wicking_tiny_link(double side)
{
    wc_world *w = world();
    /* two triangles: one of 0.5 m, one of `side`, well shaped */
    double v[3 * 6] = {0.0, 0.0, 0.0, 0.5, 0.0, 0.0, 0.0, 0.5, 0.0,
                       1.0, 1.0, 0.0, 1.0 + side, 1.0, 0.0, 1.0, 1.0 + side, 0.0};
    int32_t f[6] = {0, 1, 2, 3, 4, 5};
    wc_mesh_cloth_def d = wc_mesh_cloth_def_default();
    d.vertices = v;
    d.vertex_count = 6;
    d.faces = f;
    d.face_count = 2;
    d.material.wicking = 1.0;
    d.material.stretch_stiffness = 0.0; /* gravity alone: the step is stable */
    d.material.bend_stiffness = 0.0;
    int32_t c;
    wc_status s = wc_world_add_mesh_cloth(w, &d, &c);
    CHECK(s == WC_OK, "cloth with a triangle of %g m: %s", side, wc_world_last_error(w));
    if (s == WC_OK) {
        int32_t n = wc_cloth_particle_count(w, c);
        double wet[6] = {1.0, 0.0, 0.5, 0.0, 1.0, 0.25};
        CHECK(wc_cloth_set_wetness(w, c, wet, n) == WC_OK, "wetness: %s", wc_world_last_error(w));
        clock_t start = clock();
        for (int k = 0; k < 3; ++k) {
            wc_status st = wc_world_step(w, 1e-4);
            CHECK(st == WC_OK, "step %d: %s", k, wc_world_last_error(w));
        }
        double seconds = (double)(clock() - start) / CLOCKS_PER_SEC;
        CHECK(seconds < 5.0, "links of %g m: 3 steps took %.1f s", side, seconds);
        double out[6];
        CHECK(wc_cloth_get_wetness(w, c, out, n) == WC_OK, "get wetness");
        for (int32_t i = 0; i < n; ++i)
            CHECK(isfinite(out[i]) && out[i] >= 0.0 && out[i] <= 1.0, "wetness %d is %g", (int)i,
                  out[i]);
    }
    wc_world_destroy(w);
}

/* Mesh colliders and moving colliders: each bad argument gets its status
 * and a message naming the problem, and adds or moves nothing. */
static void expect(wc_world *w, wc_status got, wc_status want, const char *call, const char *needle)
{
    CHECK(got == want, "%s: status %s, expected %s", call, wc_status_name(got), wc_status_name(want));
    const char *m = wc_world_last_error(w);
    CHECK(m[0] != '\0' && strstr(m, needle), "%s: message \"%s\" should name \"%s\"", call, m, needle);
}

static void collider_bad_input(void)
{
    wc_world *w = world();
    double v[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    int32_t t[3] = {0, 1, 2};
    wc_mesh_collider_def good = wc_mesh_collider_def_default();
    good.vertices = v;
    good.vertex_count = 3;
    good.triangles = t;
    good.triangle_count = 1;
    int32_t id = -1;
    wc_mesh_collider_def d = good;
    d.vertex_count = 2;
    expect(w, wc_world_add_mesh_collider(w, &d, &id), WC_ERROR_INVALID_ARGUMENT, "2 vertices", "vertex_count");
    d = good;
    d.triangle_count = 0;
    expect(w, wc_world_add_mesh_collider(w, &d, &id), WC_ERROR_INVALID_ARGUMENT, "0 triangles", "triangle_count");
    d = good;
    d.vertices = NULL;
    expect(w, wc_world_add_mesh_collider(w, &d, &id), WC_ERROR_INVALID_ARGUMENT, "NULL vertices", "vertices");
    expect(w, wc_world_add_mesh_collider(w, NULL, &id), WC_ERROR_INVALID_ARGUMENT, "NULL def", "def");
    expect(w, wc_world_add_mesh_collider(w, &good, NULL), WC_ERROR_INVALID_ARGUMENT, "NULL out", "out_collider");
    double vn[9] = {0, 0, 0, 1, 0, 0, 0, NAN, 0};
    d = good;
    d.vertices = vn;
    expect(w, wc_world_add_mesh_collider(w, &d, &id), WC_ERROR_INVALID_ARGUMENT, "NaN vertex", "vertex 2");
    int32_t tb[3] = {0, 1, 3}, tn[3] = {0, -1, 2};
    d = good;
    d.triangles = tb;
    expect(w, wc_world_add_mesh_collider(w, &d, &id), WC_ERROR_INVALID_ARGUMENT, "index 3", "uses vertex 3");
    d.triangles = tn;
    expect(w, wc_world_add_mesh_collider(w, &d, &id), WC_ERROR_INVALID_ARGUMENT, "index -1", "uses vertex -1");
    d = good;
    d.thickness = -1.0;
    expect(w, wc_world_add_mesh_collider(w, &d, &id), WC_ERROR_INVALID_ARGUMENT, "thickness", "thickness");
    d = good;
    d.friction = NAN;
    expect(w, wc_world_add_mesh_collider(w, &d, &id), WC_ERROR_INVALID_ARGUMENT, "friction", "friction");
    CHECK(wc_world_collider_count(w) == 0 && id == -1, "a refused collider was added");

    int32_t mesh, sphere;
    CHECK(wc_world_add_mesh_collider(w, &good, &mesh) == WC_OK, "good mesh: %s", wc_world_last_error(w));
    wc_convex_collider_def c = wc_convex_collider_def_default();
    CHECK(wc_world_add_convex_collider(w, &c, &sphere) == WC_OK, "sphere: %s", wc_world_last_error(w));
    double moved[9] = {0, 0, 1, 1, 0, 1, 0, 1, NAN};
    expect(w, wc_collider_set_vertices(w, mesh, moved, 2), WC_ERROR_INVALID_ARGUMENT, "2 of 3 vertices", "3");
    expect(w, wc_collider_set_vertices(w, mesh, NULL, 3), WC_ERROR_INVALID_ARGUMENT, "NULL vertices", "NULL");
    expect(w, wc_collider_set_vertices(w, mesh, moved, 3), WC_ERROR_INVALID_ARGUMENT, "NaN vertex", "finite");
    expect(w, wc_collider_set_vertices(w, 7, moved, 3), WC_ERROR_NOT_FOUND, "collider 7", "7");
    expect(w, wc_collider_set_vertices(w, -1, moved, 3), WC_ERROR_NOT_FOUND, "collider -1", "-1");
    double pos[3] = {0, 0, 0}, rot[4] = {1, 0, 0, 0}, zero[4] = {0, 0, 0, 0}, nan3[3] = {0, NAN, 0};
    expect(w, wc_collider_set_transform(w, sphere, nan3, rot), WC_ERROR_INVALID_ARGUMENT, "NaN position", "position");
    expect(w, wc_collider_set_transform(w, sphere, pos, zero), WC_ERROR_INVALID_ARGUMENT, "zero quaternion", "rotation");
    expect(w, wc_collider_set_transform(w, sphere, NULL, rot), WC_ERROR_INVALID_ARGUMENT, "NULL position", "NULL");
    expect(w, wc_collider_set_transform(w, 9, pos, rot), WC_ERROR_NOT_FOUND, "collider 9", "9");
    CHECK(wc_world_collider_count(w) == 2, "collider count changed");
    wc_world_destroy(w);
}

/* A cloth cut through the middle of a box, a particle at its centre: for
 * points near the centre libccd's EPA ran on rounding to the full support
 * budget, each call ~0.1 s in ccdPtNearest (a fuzz input took 5 s for 12
 * steps; this scene 1.2 s, now 0.007 s with the EPA budget of convex.c).
 * Checked here: every particle leaves the box, finite. */
static void cloth_through_box_centre(void)
{
    wc_world *w = world();
    wc_convex_collider_def b = wc_convex_collider_def_default();
    b.shape = WC_SHAPE_BOX;
    b.half_extents[0] = b.half_extents[1] = b.half_extents[2] = 0.5;
    int32_t id;
    CHECK(wc_world_add_convex_collider(w, &b, &id) == WC_OK, "box: %s", wc_world_last_error(w));
    wc_grid_cloth_def g = wc_grid_cloth_def_default();
    g.count_u = g.count_v = 5;
    g.size_u = g.size_v = 0.5;
    g.center[2] = 0.0;
    CHECK(wc_world_add_grid_cloth(w, &g, &id) == WC_OK, "cloth: %s", wc_world_last_error(w));
    for (int s = 0; s < 12; ++s)
        CHECK(wc_world_step(w, 1e-3) == WC_OK, "step %d: %s", s, wc_world_last_error(w));
    double x[75];
    CHECK(wc_cloth_get_positions(w, 0, x, 25) == WC_OK, "positions");
    int inside = 0;
    for (int i = 0; i < 25; ++i) {
        CHECK(isfinite(x[3 * i]) && isfinite(x[3 * i + 1]) && isfinite(x[3 * i + 2]),
              "particle %d not finite", i);
        inside += fabs(x[3 * i]) < 0.5 && fabs(x[3 * i + 1]) < 0.5 && fabs(x[3 * i + 2]) < 0.5;
    }
    CHECK(inside == 0, "%d of 25 particles still inside the box", inside);
    wc_world_destroy(w);
}

int main(void)
{
    collider_bad_input();
    cloth_through_box_centre();
    pin_targets_without_pins();
    grid_awkward_boxes();
    grid_empty_box();
    collider_across_the_doubles();
    wicking_tiny_link(1e-6);
    wicking_tiny_link(1e-9);
    return test_report("test_robustness");
}
