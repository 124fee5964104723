/* Bad input (docs/robustness.md): every invalid argument gives its status and a
 * message that names the problem, and changes nothing: after each failed
 * call the world is compared bitwise with a twin world that never saw the
 * call, and both are stepped on to show that the hidden state (velocities,
 * pins) is unchanged too. A step that would go non-finite keeps the state
 * before it. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "test_util.h"
#include "wetcloth.h"

#define SIDE 8
#define COUNT (SIDE * SIDE)

static const double DT = 1e-4;

/* The world under test (a) and its twin (b): same scene, same calls, except
 * the failing ones. */
static wc_world *wa, *wb;
static int32_t ca, cb;

static wc_world *make_world(int32_t *cloth)
{
    wc_world_def def = wc_world_def_default();
    def.thread_count = 1;
    wc_world *w = NULL;
    wc_message msg;
    CHECK(wc_world_create(&def, &w, &msg) == WC_OK, "world: %s", msg.text);
    wc_grid_cloth_def g = wc_grid_cloth_def_default();
    g.count_u = g.count_v = SIDE;
    CHECK(wc_world_add_grid_cloth(w, &g, cloth) == WC_OK, "grid: %s", wc_world_last_error(w));
    int32_t pins[2] = {COUNT - SIDE, COUNT - 1};
    CHECK(wc_cloth_pin(w, *cloth, pins, 2) == WC_OK, "pin: %s", wc_world_last_error(w));
    /* some motion, so that velocities and history matter */
    for (int s = 0; s < 20; ++s) wc_world_step(w, DT);
    return w;
}

/* Both worlds hold bitwise the same positions and velocities, and still do
 * after a step. */
static void check_twins(const char *after)
{
    double xa[3 * COUNT], xb[3 * COUNT], va[3 * COUNT], vb[3 * COUNT];
    for (int round = 0; round < 2; ++round) {
        CHECK(wc_cloth_get_positions(wa, ca, xa, COUNT) == WC_OK, "get a");
        CHECK(wc_cloth_get_positions(wb, cb, xb, COUNT) == WC_OK, "get b");
        CHECK(wc_cloth_get_velocities(wa, ca, va, COUNT) == WC_OK, "vel a");
        CHECK(wc_cloth_get_velocities(wb, cb, vb, COUNT) == WC_OK, "vel b");
        CHECK(memcmp(xa, xb, sizeof xa) == 0 && memcmp(va, vb, sizeof va) == 0,
              "after %s: state differs from the untouched twin%s", after,
              round ? " after one more step" : "");
        CHECK(wc_world_time(wa) == wc_world_time(wb), "after %s: time %.17g vs %.17g", after,
              wc_world_time(wa), wc_world_time(wb));
        CHECK(wc_cloth_pin_count(wa, ca) == wc_cloth_pin_count(wb, cb), "after %s: pin count", after);
        CHECK(wc_cloth_stable_dt(wa, ca) == wc_cloth_stable_dt(wb, cb),
              "after %s: stable step %.17g vs %.17g", after, wc_cloth_stable_dt(wa, ca),
              wc_cloth_stable_dt(wb, cb));
        if (round == 0) {
            CHECK(wc_world_step(wa, DT) == WC_OK, "after %s: world a does not step: %s", after,
                  wc_world_last_error(wa));
            CHECK(wc_world_step(wb, DT) == WC_OK, "twin step");
        }
    }
}

/* status and message of a failed call on world a */
static void expect(wc_status got, wc_status want, const char *call, const char *needle1,
                   const char *needle2)
{
    const char *msg = wc_world_last_error(wa);
    printf("%-44s -> %-26s \"%s\"\n", call, wc_status_name(got), msg);
    CHECK(got == want, "%s returned %s, expected %s", call, wc_status_name(got), wc_status_name(want));
    CHECK(msg && strlen(msg) > 0, "%s: empty message", call);
    if (needle1) CHECK(strstr(msg, needle1) != NULL, "%s: message \"%s\" lacks \"%s\"", call, msg, needle1);
    if (needle2) CHECK(strstr(msg, needle2) != NULL, "%s: message \"%s\" lacks \"%s\"", call, msg, needle2);
    check_twins(call);
}

/* ------------------------------------------------------------------------ */

static void test_world_def(void)
{
    static const struct {
        const char *field;
        int which;
    } cases[] = {{"gravity", 0}, {"thread_count", 1}, {"substep_safety", 2}, {"max_substeps", 3},
                 {"substep_safety", 4}, {"thread_count", 5}, {"max_substeps", 6}};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        wc_world_def def = wc_world_def_default();
        switch (cases[i].which) {
        case 0: def.gravity[1] = NAN; break;
        case 1: def.thread_count = -1; break;
        case 2: def.substep_safety = 0.0; break;
        case 3: def.max_substeps = 0; break;
        case 4: def.substep_safety = 1.5; break;
        case 5: def.thread_count = 1025; break;
        case 6: def.max_substeps = 10000001; break;
        }
        wc_world *w = (wc_world *)&def; /* must be overwritten with NULL */
        wc_message msg;
        wc_status s = wc_world_create(&def, &w, &msg);
        printf("world_def.%-36s -> %-26s \"%s\"\n", cases[i].field, wc_status_name(s), msg.text);
        CHECK(s == WC_ERROR_INVALID_ARGUMENT, "world_def case %d accepted", cases[i].which);
        CHECK(w == NULL, "out_world not NULL after failure");
        CHECK(strstr(msg.text, cases[i].field) != NULL, "message \"%s\" lacks \"%s\"", msg.text,
              cases[i].field);
        wc_world_destroy(s == WC_OK ? w : NULL);
    }
    wc_message msg;
    wc_world *w = NULL;
    CHECK(wc_world_create(NULL, &w, &msg) == WC_ERROR_INVALID_ARGUMENT && w == NULL &&
              strstr(msg.text, "def") != NULL,
          "NULL def: \"%s\"", msg.text);
    wc_world_def def = wc_world_def_default();
    CHECK(wc_world_create(&def, NULL, &msg) == WC_ERROR_INVALID_ARGUMENT &&
              strstr(msg.text, "out_world") != NULL,
          "NULL out_world: \"%s\"", msg.text);
    CHECK(wc_world_create(&def, NULL, NULL) == WC_ERROR_INVALID_ARGUMENT, "NULL out_world, NULL msg");
}

static void test_null_world(void)
{
    /* No world to hold a message: only the status. None may crash. */
    double xyz[3 * COUNT];
    int32_t id;
    wc_grid_cloth_def g = wc_grid_cloth_def_default();
    CHECK(wc_world_step(NULL, DT) == WC_ERROR_INVALID_ARGUMENT, "step(NULL)");
    CHECK(wc_world_advance(NULL, DT, 1) == WC_ERROR_INVALID_ARGUMENT, "advance(NULL)");
    CHECK(wc_world_add_grid_cloth(NULL, &g, &id) == WC_ERROR_INVALID_ARGUMENT, "add(NULL)");
    CHECK(wc_cloth_get_positions(NULL, 0, xyz, COUNT) == WC_ERROR_INVALID_ARGUMENT, "get(NULL)");
    CHECK(wc_cloth_particle_count(NULL, 0) == 0, "count(NULL)");
    CHECK(wc_world_cloth_count(NULL) == 0, "cloth_count(NULL)");
    CHECK(wc_world_last_error(NULL) != NULL, "last_error(NULL)");
    int32_t idx[1] = {0};
    double stiffness[1] = {1.0};
    CHECK(wc_cloth_pin_soft(NULL, 0, idx, stiffness, 1) == WC_ERROR_INVALID_ARGUMENT, "pin_soft(NULL)");
    CHECK(wc_cloth_set_air_velocity(NULL, 0, xyz, COUNT) == WC_ERROR_INVALID_ARGUMENT, "air(NULL)");
    CHECK(wc_cloth_set_external_forces(NULL, 0, xyz, COUNT) == WC_ERROR_INVALID_ARGUMENT, "forces(NULL)");
    wc_world_destroy(NULL);
}

/* wc_struct_size: what a binding compares its struct layouts against. Every
 * struct with a body in wetcloth.h is listed (the Python binding's test
 * checks all of those it declares); unknown names and NULL give 0. */
static void test_struct_sizes(void)
{
    const struct {
        const char *name;
        size_t size;
    } known[] = {
        {"wc_message", sizeof(wc_message)},
        {"wc_world_def", sizeof(wc_world_def)},
        {"wc_material", sizeof(wc_material)},
        {"wc_mesh_cloth_def", sizeof(wc_mesh_cloth_def)},
        {"wc_grid_cloth_def", sizeof(wc_grid_cloth_def)},
        {"wc_cloth_view", sizeof(wc_cloth_view)},
        {"wc_energy", sizeof(wc_energy)},
        {"wc_mesh_collider_def", sizeof(wc_mesh_collider_def)},
        {"wc_convex_collider_def", sizeof(wc_convex_collider_def)},
        {"wc_step_stats", sizeof(wc_step_stats)},
        {"wc_intersection_counts", sizeof(wc_intersection_counts)},
    };
    for (size_t k = 0; k < sizeof known / sizeof known[0]; ++k)
        CHECK(wc_struct_size(known[k].name) == (int64_t)known[k].size, "%s: %lld, sizeof %zu",
              known[k].name, (long long)wc_struct_size(known[k].name), known[k].size);
    CHECK(wc_struct_size(NULL) == 0, "NULL name");
    CHECK(wc_struct_size("wc_world") == 0, "an opaque handle has no size");
    CHECK(wc_struct_size("wc_world_def ") == 0, "a name must match exactly");
    CHECK(wc_struct_size("") == 0, "empty name");
}

static void test_null_arguments(void)
{
    int32_t id = -1;
    wc_grid_cloth_def g = wc_grid_cloth_def_default();
    wc_mesh_cloth_def m = wc_mesh_cloth_def_default();
    expect(wc_world_add_grid_cloth(wa, NULL, &id), WC_ERROR_INVALID_ARGUMENT, "add_grid_cloth(def NULL)", "def", NULL);
    expect(wc_world_add_grid_cloth(wa, &g, NULL), WC_ERROR_INVALID_ARGUMENT, "add_grid_cloth(out NULL)", "out_cloth", NULL);
    expect(wc_world_add_mesh_cloth(wa, NULL, &id), WC_ERROR_INVALID_ARGUMENT, "add_mesh_cloth(def NULL)", "def", NULL);
    double v3[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    int32_t f3[3] = {0, 1, 2};
    m.vertex_count = 3, m.face_count = 1, m.face_size = 3;
    m.vertices = NULL, m.faces = f3;
    expect(wc_world_add_mesh_cloth(wa, &m, &id), WC_ERROR_INVALID_ARGUMENT, "mesh vertices NULL", "vertices", NULL);
    m.vertices = v3, m.faces = NULL;
    expect(wc_world_add_mesh_cloth(wa, &m, &id), WC_ERROR_INVALID_ARGUMENT, "mesh faces NULL", "faces", NULL);
    expect(wc_cloth_get_positions(wa, ca, NULL, COUNT), WC_ERROR_INVALID_ARGUMENT, "get_positions(NULL)", "NULL", NULL);
    expect(wc_cloth_set_positions(wa, ca, NULL, COUNT), WC_ERROR_INVALID_ARGUMENT, "set_positions(NULL)", "NULL", NULL);
    expect(wc_cloth_set_velocities(wa, ca, NULL, COUNT), WC_ERROR_INVALID_ARGUMENT, "set_velocities(NULL)", "NULL", NULL);
    expect(wc_cloth_pin(wa, ca, NULL, 1), WC_ERROR_INVALID_ARGUMENT, "pin(NULL)", "NULL", NULL);
    expect(wc_cloth_set_pin_targets(wa, ca, NULL, 2), WC_ERROR_INVALID_ARGUMENT, "set_pin_targets(NULL)", "NULL", NULL);
    expect(wc_cloth_get_view(wa, ca, NULL), WC_ERROR_INVALID_ARGUMENT, "get_view(NULL)", "NULL", NULL);
    expect(wc_cloth_get_energy(wa, ca, NULL), WC_ERROR_INVALID_ARGUMENT, "get_energy(NULL)", "NULL", NULL);
    expect(wc_cloth_get_triangles(wa, ca, NULL, 1000), WC_ERROR_INVALID_ARGUMENT, "get_triangles(NULL)", "NULL", NULL);
}

static void test_material(void)
{
    static const struct {
        const char *field;
        double value;
    } cases[] = {
        {"density", 0.0},          {"density", -1.0},          {"density", NAN},
        {"density", 1e4},          {"density", INFINITY},      {"stretch_stiffness", -1.0},
        {"stretch_stiffness", NAN}, {"stretch_stiffness", 2e9}, {"bend_stiffness", -1e-6},
        {"bend_stiffness", NAN},   {"bend_stiffness", 1e4},    {"stretch_damping", -0.1},
        {"stretch_damping", 1.5},  {"stretch_damping", NAN},   {"air_drag", -1.0},
        {"air_drag", NAN},         {"air_drag", 1e5},          {"wet_grip", -1.0},
        {"wet_grip", NAN},         {"wet_grip", 2e6},
    };
    int32_t id = -1;
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        wc_grid_cloth_def g = wc_grid_cloth_def_default();
        g.count_u = g.count_v = 4;
        wc_material *mat = &g.material;
        if (!strcmp(cases[i].field, "density")) mat->density = cases[i].value;
        if (!strcmp(cases[i].field, "stretch_stiffness")) mat->stretch_stiffness = cases[i].value;
        if (!strcmp(cases[i].field, "bend_stiffness")) mat->bend_stiffness = cases[i].value;
        if (!strcmp(cases[i].field, "stretch_damping")) mat->stretch_damping = cases[i].value;
        if (!strcmp(cases[i].field, "air_drag")) mat->air_drag = cases[i].value;
        if (!strcmp(cases[i].field, "wet_grip")) mat->wet_grip = cases[i].value;
        char call[80];
        snprintf(call, sizeof call, "material.%s = %g", cases[i].field, cases[i].value);
        expect(wc_world_add_grid_cloth(wa, &g, &id), WC_ERROR_INVALID_ARGUMENT, call, cases[i].field, NULL);
        /* the same material through the mesh path */
        double v3[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
        int32_t f3[3] = {0, 1, 2};
        wc_mesh_cloth_def m = wc_mesh_cloth_def_default();
        m.vertices = v3, m.vertex_count = 3, m.faces = f3, m.face_count = 1, m.face_size = 3;
        m.material = g.material;
        expect(wc_world_add_mesh_cloth(wa, &m, &id), WC_ERROR_INVALID_ARGUMENT, call, cases[i].field, NULL);
    }
    /* A value just past a bound must not print as the bound ("must be in
     * [0, 0.99] but is 0.99"): 0.99 kept as a 32-bit float, as Blender keeps
     * its properties, is 0.99000000953674316. */
    wc_grid_cloth_def g = wc_grid_cloth_def_default();
    g.count_u = g.count_v = 4;
    g.material.wet_softening = (double)0.99f;
    expect(wc_world_add_grid_cloth(wa, &g, &id), WC_ERROR_INVALID_ARGUMENT, "material.wet_softening = 0.99f",
           "0.99] but is 0.99000000953674316", NULL);
    CHECK(wc_world_cloth_count(wa) == 1, "a failed add created a cloth (%d)", wc_world_cloth_count(wa));
}

static void test_grid_def(void)
{
    int32_t id = -1;
    wc_grid_cloth_def g = wc_grid_cloth_def_default();
    g.count_u = 1;
    expect(wc_world_add_grid_cloth(wa, &g, &id), WC_ERROR_INVALID_ARGUMENT, "grid count_u = 1", "count_u", NULL);
    g = wc_grid_cloth_def_default();
    g.count_v = 1;
    expect(wc_world_add_grid_cloth(wa, &g, &id), WC_ERROR_INVALID_ARGUMENT, "grid count_v = 1", "count_v", NULL);
    g = wc_grid_cloth_def_default();
    g.axis_u[0] = 2.0;
    expect(wc_world_add_grid_cloth(wa, &g, &id), WC_ERROR_INVALID_ARGUMENT, "grid axis_u = (2,0,0)", "axis_u", "unit");
    g = wc_grid_cloth_def_default();
    g.axis_v[0] = 0.6, g.axis_v[1] = 0.8; /* unit, not perpendicular */
    expect(wc_world_add_grid_cloth(wa, &g, &id), WC_ERROR_INVALID_ARGUMENT, "grid axes not perpendicular", "perpendicular", NULL);
    g = wc_grid_cloth_def_default();
    g.axis_v[1] = NAN;
    expect(wc_world_add_grid_cloth(wa, &g, &id), WC_ERROR_INVALID_ARGUMENT, "grid axis_v NaN", "axis_v", NULL);
    g = wc_grid_cloth_def_default();
    g.size_u = 0.0;
    expect(wc_world_add_grid_cloth(wa, &g, &id), WC_ERROR_INVALID_ARGUMENT, "grid size_u = 0", "size_u", NULL);
    g = wc_grid_cloth_def_default();
    g.center[2] = INFINITY;
    expect(wc_world_add_grid_cloth(wa, &g, &id), WC_ERROR_INVALID_ARGUMENT, "grid center inf", "center", NULL);
    g = wc_grid_cloth_def_default();
    CHECK(g.collide_with_cloths == 1, "grid collide_with_cloths defaults to %d", (int)g.collide_with_cloths);
    g.collide_with_cloths = 2;
    expect(wc_world_add_grid_cloth(wa, &g, &id), WC_ERROR_INVALID_ARGUMENT, "grid collide_with_cloths = 2",
           "grid_cloth_def.collide_with_cloths", "0 or 1");
    wc_mesh_cloth_def m = wc_mesh_cloth_def_default();
    CHECK(m.collide_with_cloths == 1, "mesh collide_with_cloths defaults to %d", (int)m.collide_with_cloths);
    static const double tri[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    static const int32_t face[3] = {0, 1, 2};
    m.vertices = tri, m.vertex_count = 3, m.faces = face, m.face_count = 1;
    m.collide_with_cloths = -1;
    expect(wc_world_add_mesh_cloth(wa, &m, &id), WC_ERROR_INVALID_ARGUMENT, "mesh collide_with_cloths = -1",
           "mesh_cloth_def.collide_with_cloths", "-1");
    CHECK(id == -1, "out_cloth written on failure (%d)", id);
}

/* A 20 x 20 vertex triangle mesh (400 vertices, 722 faces). */
static double mesh_v[3 * 400];
static int32_t mesh_f[3 * 722];

static void build_mesh(void)
{
    for (int j = 0; j < 20; ++j)
        for (int i = 0; i < 20; ++i) {
            mesh_v[3 * (j * 20 + i)] = 0.05 * i;
            mesh_v[3 * (j * 20 + i) + 1] = 0.05 * j;
            mesh_v[3 * (j * 20 + i) + 2] = 0.0;
        }
    int k = 0;
    for (int j = 0; j < 19; ++j)
        for (int i = 0; i < 19; ++i) {
            int a = j * 20 + i;
            mesh_f[k++] = a, mesh_f[k++] = a + 1, mesh_f[k++] = a + 21;
            mesh_f[k++] = a, mesh_f[k++] = a + 21, mesh_f[k++] = a + 20;
        }
}

static wc_status add_mesh(const double *v, int32_t nv, const int32_t *f, int32_t nf, int32_t fs)
{
    wc_mesh_cloth_def m = wc_mesh_cloth_def_default();
    m.vertices = v, m.vertex_count = nv, m.faces = f, m.face_count = nf, m.face_size = fs;
    int32_t id = -1;
    wc_status s = wc_world_add_mesh_cloth(wa, &m, &id);
    CHECK(s == WC_OK || id == -1, "out_cloth written on failure");
    return s;
}

static void test_mesh_def(void)
{
    build_mesh();
    CHECK(add_mesh(mesh_v, 400, mesh_f, 722, 3) == WC_OK, "valid 400-vertex mesh refused: %s",
          wc_world_last_error(wa));
    /* keep the twin in step: it gets the same valid cloth */
    {
        wc_mesh_cloth_def m = wc_mesh_cloth_def_default();
        m.vertices = mesh_v, m.vertex_count = 400, m.faces = mesh_f, m.face_count = 722, m.face_size = 3;
        int32_t id;
        CHECK(wc_world_add_mesh_cloth(wb, &m, &id) == WC_OK, "twin mesh");
    }
    int32_t cloths = wc_world_cloth_count(wa);

    static int32_t f[3 * 722];
    memcpy(f, mesh_f, sizeof f);
    f[3 * 17 + 1] = 912;
    expect(add_mesh(mesh_v, 400, f, 722, 3), WC_ERROR_INVALID_ARGUMENT, "face 17 uses vertex 912", "face 17", "912");
    CHECK(strstr(wc_world_last_error(wa), "400") != NULL, "message lacks the vertex count");
    memcpy(f, mesh_f, sizeof f);
    f[3 * 5] = -7;
    expect(add_mesh(mesh_v, 400, f, 722, 3), WC_ERROR_INVALID_ARGUMENT, "face 5 uses vertex -7", "face 5", "-7");
    memcpy(f, mesh_f, sizeof f);
    f[3 * 9 + 2] = -1;
    expect(add_mesh(mesh_v, 400, f, 722, 3), WC_ERROR_INVALID_ARGUMENT, "-1 in a triangle mesh", "face 9", "-1");
    memcpy(f, mesh_f, sizeof f);
    f[3 * 11 + 2] = f[3 * 11];
    expect(add_mesh(mesh_v, 400, f, 722, 3), WC_ERROR_INVALID_ARGUMENT, "face 11 uses a vertex twice", "face 11", "twice");

    /* vertex_count, face_count, face_size */
    expect(add_mesh(mesh_v, 2, mesh_f, 1, 3), WC_ERROR_INVALID_ARGUMENT, "vertex_count = 2", "vertex_count", NULL);
    expect(add_mesh(mesh_v, 400, mesh_f, 0, 3), WC_ERROR_INVALID_ARGUMENT, "face_count = 0", "face_count", NULL);
    expect(add_mesh(mesh_v, 400, mesh_f, 100, 5), WC_ERROR_INVALID_ARGUMENT, "face_size = 5", "face_size", NULL);

    /* NaN vertex */
    static double v[3 * 400];
    memcpy(v, mesh_v, sizeof v);
    v[3 * 7 + 1] = NAN;
    expect(add_mesh(v, 400, mesh_f, 722, 3), WC_ERROR_INVALID_ARGUMENT, "vertex 7 is NaN", "vertex 7", NULL);

    /* Degenerate (collinear) face: face 1 = (1, 3, 4) on a line. */
    double dv[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 2, 0, 0, 3, 0, 0};
    int32_t df[6] = {0, 1, 2, 1, 3, 4};
    expect(add_mesh(dv, 5, df, 2, 3), WC_ERROR_INVALID_ARGUMENT, "face 1 collinear", "face 1", "degenerate");
    /* Coinciding vertices make a degenerate face too. */
    double cv[9] = {0, 0, 0, 1, 1, 1, 1, 1, 1};
    int32_t cf[3] = {0, 1, 2};
    expect(add_mesh(cv, 3, cf, 1, 3), WC_ERROR_INVALID_ARGUMENT, "face 0 with coinciding vertices", "face 0", NULL);

    /* Vertex in no face: 4 vertices, one triangle. */
    double nv[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 5, 5, 5};
    expect(add_mesh(nv, 4, cf, 1, 3), WC_ERROR_INVALID_ARGUMENT, "vertex 3 in no face", "vertex 3", "no face");

    /* face_size 4: -1 only allowed last */
    double qv[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    int32_t qf[8] = {0, 1, 2, 3, 0, 2, -1, 3};
    expect(add_mesh(qv, 4, qf, 2, 4), WC_ERROR_INVALID_ARGUMENT, "face 1 = (0, 2, -1, 3)", "face 1", "-1");
    int32_t qf2[8] = {0, 1, 2, 3, 0, 1, 2, 4};
    expect(add_mesh(qv, 4, qf2, 2, 4), WC_ERROR_INVALID_ARGUMENT, "face 1 uses vertex 4 of 4", "face 1", "4");
    CHECK(wc_world_cloth_count(wa) == cloths, "a failed mesh add changed the cloth count");
}

static void test_pins(void)
{
    int32_t bad_range[2] = {1, 500};
    expect(wc_cloth_pin(wa, ca, bad_range, 2), WC_ERROR_INVALID_ARGUMENT, "pin {1, 500}", "indices[1]", "500");
    int32_t negative[1] = {-3};
    expect(wc_cloth_pin(wa, ca, negative, 1), WC_ERROR_INVALID_ARGUMENT, "pin {-3}", "indices[0]", "-3");
    int32_t dup[3] = {3, 5, 3};
    expect(wc_cloth_pin(wa, ca, dup, 3), WC_ERROR_INVALID_ARGUMENT, "pin {3, 5, 3}", "indices[2]", "repeated");
    int32_t already[2] = {4, COUNT - 1};
    expect(wc_cloth_pin(wa, ca, already, 2), WC_ERROR_INVALID_ARGUMENT, "pin {4, 63} (63 pinned)", "indices[1]", "already pinned");
    expect(wc_cloth_pin(wa, ca, dup, -1), WC_ERROR_INVALID_ARGUMENT, "pin count -1", "count", NULL);
    /* None of the rejected lists left a mark: 3, 4 and 5 can be pinned now
     * (on both worlds, which stay twins). */
    int32_t ok[3] = {3, 4, 5};
    CHECK(wc_cloth_pin(wa, ca, ok, 3) == WC_OK, "pin {3,4,5} after rejections: %s", wc_world_last_error(wa));
    CHECK(wc_cloth_pin(wb, cb, ok, 3) == WC_OK, "twin pin");
    CHECK(wc_cloth_pin_count(wa, ca) == 5, "pin count %d", wc_cloth_pin_count(wa, ca));
    check_twins("pinning 3, 4, 5");

    double targets[3 * 6] = {0};
    expect(wc_cloth_set_pin_targets(wa, ca, targets, 6), WC_ERROR_INVALID_ARGUMENT, "set_pin_targets count 6 of 5", "count", "5");
    expect(wc_cloth_set_pin_targets(wa, ca, targets, 4), WC_ERROR_INVALID_ARGUMENT, "set_pin_targets count 4 of 5", "count", "5");
    targets[7] = NAN;
    expect(wc_cloth_set_pin_targets(wa, ca, targets, 5), WC_ERROR_INVALID_ARGUMENT, "set_pin_targets NaN", "finite", NULL);
}

/* Soft pins share the pin list and its checks, and add their stiffness.
 * Both twins get soft pins 10 and 11 first, so that a failed call must
 * also leave existing soft pins (their springs pull in every later step)
 * as they were. */
static void test_soft_pins(void)
{
    int32_t first[2] = {10, 11};
    double first_stiffness[2] = {50.0, 80.0};
    CHECK(wc_cloth_pin_soft(wa, ca, first, first_stiffness, 2) == WC_OK, "pin_soft: %s", wc_world_last_error(wa));
    CHECK(wc_cloth_pin_soft(wb, cb, first, first_stiffness, 2) == WC_OK, "twin pin_soft");
    check_twins("soft-pinning 10, 11");
    double s3[3] = {10.0, 10.0, 10.0};
    int32_t bad_range[2] = {1, 500};
    expect(wc_cloth_pin_soft(wa, ca, bad_range, s3, 2), WC_ERROR_INVALID_ARGUMENT, "pin_soft {1, 500}", "indices[1]", "500");
    int32_t negative[1] = {-3};
    expect(wc_cloth_pin_soft(wa, ca, negative, s3, 1), WC_ERROR_INVALID_ARGUMENT, "pin_soft {-3}", "indices[0]", "-3");
    int32_t dup[3] = {20, 21, 20};
    expect(wc_cloth_pin_soft(wa, ca, dup, s3, 3), WC_ERROR_INVALID_ARGUMENT, "pin_soft {20, 21, 20}", "indices[2]", "repeated");
    int32_t hard[2] = {22, COUNT - 1};
    expect(wc_cloth_pin_soft(wa, ca, hard, s3, 2), WC_ERROR_INVALID_ARGUMENT, "pin_soft {22, 63} (63 pinned)", "indices[1] = 63", "already pinned");
    int32_t soft[2] = {22, 11};
    expect(wc_cloth_pin_soft(wa, ca, soft, s3, 2), WC_ERROR_INVALID_ARGUMENT, "pin_soft {22, 11} (11 soft)", "indices[1] = 11", "already pinned (soft pin");
    expect(wc_cloth_pin(wa, ca, soft, 2), WC_ERROR_INVALID_ARGUMENT, "pin {22, 11} (11 soft)", "indices[1] = 11", "already pinned (soft pin");
    expect(wc_cloth_pin_soft(wa, ca, dup, s3, -1), WC_ERROR_INVALID_ARGUMENT, "pin_soft count -1", "count", NULL);
    expect(wc_cloth_pin_soft(wa, ca, dup, NULL, 2), WC_ERROR_INVALID_ARGUMENT, "pin_soft stiffness NULL", "stiffness", "NULL");
    expect(wc_cloth_pin_soft(wa, ca, NULL, s3, 2), WC_ERROR_INVALID_ARGUMENT, "pin_soft indices NULL", "NULL", NULL);
    const double bad_stiffness[] = {0.0, -5.0, NAN, INFINITY, 1.5e8};
    const char *shown[] = {"is 0", "is -5", "is nan", "is inf", "is 1.5e+08"};
    for (int k = 0; k < 5; ++k) {
        int32_t idx[3] = {20, 21, 22};
        double stiff[3] = {10.0, 10.0, 10.0};
        stiff[2] = bad_stiffness[k];
        char call[64];
        snprintf(call, sizeof call, "pin_soft stiffness[2] = %g", bad_stiffness[k]);
        expect(wc_cloth_pin_soft(wa, ca, idx, stiff, 3), WC_ERROR_INVALID_ARGUMENT, call,
               "stiffness[2] (for particle 22)", shown[k]);
    }
    /* none of the rejected lists left a mark: 20, 21, 22 can be soft-pinned now */
    int32_t ok[3] = {20, 21, 22};
    CHECK(wc_cloth_pin_soft(wa, ca, ok, s3, 3) == WC_OK, "pin_soft {20, 21, 22} after rejections: %s", wc_world_last_error(wa));
    CHECK(wc_cloth_pin_soft(wb, cb, ok, s3, 3) == WC_OK, "twin pin_soft");
    CHECK(wc_cloth_pin_count(wa, ca) == 10, "pin count %d (5 hard, 5 soft)", wc_cloth_pin_count(wa, ca));
    check_twins("soft-pinning 20, 21, 22");
    /* the largest stiffness is allowed */
    int32_t last = 30;
    double most = 1e8;
    CHECK(wc_cloth_pin_soft(wa, ca, &last, &most, 1) == WC_OK && wc_cloth_pin_soft(wb, cb, &last, &most, 1) == WC_OK,
          "stiffness 1e8: %s", wc_world_last_error(wa));
    double targets[3 * 12] = {0};
    expect(wc_cloth_set_pin_targets(wa, ca, targets, 10), WC_ERROR_INVALID_ARGUMENT, "set_pin_targets count 10 of 11 (soft too)", "count", "11");
}

/* Air velocity and external force densities: the count, finiteness and
 * length of every vector checked before anything changes. The twins get
 * a valid field first, so that a failed call must keep it as it was. */
static void test_fields(void)
{
    double u[3 * COUNT], p[3 * COUNT];
    for (int32_t k = 0; k < 3 * COUNT; ++k) u[k] = 0.5 + 0.01 * k, p[k] = -0.2 + 0.003 * k;
    CHECK(wc_cloth_set_air_velocity(wa, ca, u, COUNT) == WC_OK && wc_cloth_set_air_velocity(wb, cb, u, COUNT) == WC_OK,
          "air: %s", wc_world_last_error(wa));
    CHECK(wc_cloth_set_external_forces(wa, ca, p, COUNT) == WC_OK && wc_cloth_set_external_forces(wb, cb, p, COUNT) == WC_OK,
          "forces: %s", wc_world_last_error(wa));
    check_twins("setting air velocity and external forces");

    double bad[3 * (COUNT + 1)];
    memcpy(bad, u, sizeof u);
    expect(wc_cloth_set_air_velocity(wa, ca, bad, COUNT - 1), WC_ERROR_INVALID_ARGUMENT, "air count 63", "count", "64");
    expect(wc_cloth_set_air_velocity(wa, ca, bad, COUNT + 1), WC_ERROR_INVALID_ARGUMENT, "air count 65", "count", "64");
    expect(wc_cloth_set_air_velocity(wa, ca, bad, 0), WC_ERROR_INVALID_ARGUMENT, "air count 0 (not NULL)", "count", "64");
    expect(wc_cloth_set_air_velocity(wa, ca, NULL, COUNT), WC_ERROR_INVALID_ARGUMENT, "air NULL, count 64", "NULL", "count 0 clears");
    bad[3 * 7 + 1] = NAN;
    expect(wc_cloth_set_air_velocity(wa, ca, bad, COUNT), WC_ERROR_INVALID_ARGUMENT, "air NaN", "velocity_xyz[22] (y of particle 7)", "finite");
    bad[3 * 7 + 1] = -INFINITY;
    expect(wc_cloth_set_air_velocity(wa, ca, bad, COUNT), WC_ERROR_INVALID_ARGUMENT, "air -inf", "particle 7", "-inf");
    memcpy(bad, u, sizeof u);
    bad[3 * 60] = 8000.0, bad[3 * 60 + 1] = 7000.0; /* each below 1e4, together 10630 m/s */
    expect(wc_cloth_set_air_velocity(wa, ca, bad, COUNT), WC_ERROR_INVALID_ARGUMENT, "air 10630 m/s", "particle 60", "at most 10000 m/s");

    memcpy(bad, p, sizeof p);
    expect(wc_cloth_set_external_forces(wa, ca, bad, COUNT - 1), WC_ERROR_INVALID_ARGUMENT, "forces count 63", "count", "64");
    expect(wc_cloth_set_external_forces(wa, ca, NULL, 5), WC_ERROR_INVALID_ARGUMENT, "forces NULL, count 5", "NULL", NULL);
    bad[3 * 12 + 2] = INFINITY;
    expect(wc_cloth_set_external_forces(wa, ca, bad, COUNT), WC_ERROR_INVALID_ARGUMENT, "forces inf", "force_per_area_xyz[38] (z of particle 12)", "finite");
    memcpy(bad, p, sizeof p);
    bad[3 * 40 + 2] = -2e6;
    expect(wc_cloth_set_external_forces(wa, ca, bad, COUNT), WC_ERROR_INVALID_ARGUMENT, "forces 2e6 N/m^2", "particle 40", "at most 1e+06 N/m^2");

    /* the limits themselves are allowed; clearing gives still air and no
     * force again, on both twins */
    memcpy(bad, u, sizeof u);
    bad[0] = 1e4, bad[1] = bad[2] = 0.0;
    CHECK(wc_cloth_set_air_velocity(wa, ca, bad, COUNT) == WC_OK && wc_cloth_set_air_velocity(wb, cb, bad, COUNT) == WC_OK,
          "air at 1e4 m/s: %s", wc_world_last_error(wa));
    CHECK(wc_cloth_set_air_velocity(wa, ca, NULL, 0) == WC_OK && wc_cloth_set_air_velocity(wb, cb, NULL, 0) == WC_OK &&
              wc_cloth_set_external_forces(wa, ca, NULL, 0) == WC_OK && wc_cloth_set_external_forces(wb, cb, NULL, 0) == WC_OK,
          "clearing: %s", wc_world_last_error(wa));
    check_twins("clearing the fields");
}

static void test_arrays(void)
{
    double xyz[3 * (COUNT + 1)];
    expect(wc_cloth_get_positions(wa, ca, xyz, COUNT - 1), WC_ERROR_INVALID_ARGUMENT, "get_positions count 63", "count", "64");
    expect(wc_cloth_get_positions(wa, ca, xyz, COUNT + 1), WC_ERROR_INVALID_ARGUMENT, "get_positions count 65", "count", "64");
    float xf[3 * COUNT];
    expect(wc_cloth_get_positions_f32(wa, ca, xf, 10), WC_ERROR_INVALID_ARGUMENT, "get_positions_f32 count 10", "count", NULL);
    CHECK(wc_cloth_get_positions(wa, ca, xyz, COUNT) == WC_OK, "get");
    expect(wc_cloth_set_positions(wa, ca, xyz, COUNT - 1), WC_ERROR_INVALID_ARGUMENT, "set_positions count 63", "count", NULL);
    xyz[3 * 20 + 2] = INFINITY;
    expect(wc_cloth_set_positions(wa, ca, xyz, COUNT), WC_ERROR_INVALID_ARGUMENT, "set_positions inf", "finite", "20");
    double vel[3 * COUNT] = {0};
    vel[5] = NAN;
    expect(wc_cloth_set_velocities(wa, ca, vel, COUNT), WC_ERROR_INVALID_ARGUMENT, "set_velocities NaN", "finite", NULL);
    expect(wc_cloth_get_velocities(wa, ca, vel, 3), WC_ERROR_INVALID_ARGUMENT, "get_velocities count 3", "count", NULL);
    int32_t pairs[2];
    expect(wc_cloth_get_links(wa, ca, WC_LINK_STRETCH, pairs, NULL, 1), WC_ERROR_INVALID_ARGUMENT, "get_links capacity 1", "capacity", NULL);
    expect(wc_cloth_get_links(wa, ca, (wc_link_kind)7, pairs, NULL, 1), WC_ERROR_INVALID_ARGUMENT, "get_links kind 7", "kind", NULL);
    int32_t tri[3];
    expect(wc_cloth_get_triangles(wa, ca, tri, 1), WC_ERROR_INVALID_ARGUMENT, "get_triangles capacity 1", "capacity", NULL);
}

static void test_unknown_cloth(void)
{
    double xyz[3 * COUNT];
    int32_t idx[1] = {0};
    int32_t pairs[2];
    int32_t tri[3];
    wc_energy e;
    wc_cloth_view v;
    int32_t bad[2] = {5, -1};
    for (int b = 0; b < 2; ++b) {
        int32_t c = bad[b];
        char num[16];
        snprintf(num, sizeof num, "cloth %d", (int)c);
        expect(wc_cloth_get_positions(wa, c, xyz, COUNT), WC_ERROR_NOT_FOUND, "get_positions(unknown)", num, NULL);
        expect(wc_cloth_set_positions(wa, c, xyz, COUNT), WC_ERROR_NOT_FOUND, "set_positions(unknown)", num, NULL);
        expect(wc_cloth_get_velocities(wa, c, xyz, COUNT), WC_ERROR_NOT_FOUND, "get_velocities(unknown)", num, NULL);
        expect(wc_cloth_set_velocities(wa, c, xyz, COUNT), WC_ERROR_NOT_FOUND, "set_velocities(unknown)", num, NULL);
        expect(wc_cloth_pin(wa, c, idx, 1), WC_ERROR_NOT_FOUND, "pin(unknown)", num, NULL);
        expect(wc_cloth_unpin_all(wa, c), WC_ERROR_NOT_FOUND, "unpin_all(unknown)", num, NULL);
        expect(wc_cloth_set_pin_targets(wa, c, xyz, 2), WC_ERROR_NOT_FOUND, "set_pin_targets(unknown)", num, NULL);
        double stiffness[1] = {1.0};
        expect(wc_cloth_pin_soft(wa, c, idx, stiffness, 1), WC_ERROR_NOT_FOUND, "pin_soft(unknown)", num, NULL);
        expect(wc_cloth_set_air_velocity(wa, c, xyz, COUNT), WC_ERROR_NOT_FOUND, "set_air_velocity(unknown)", num, NULL);
        expect(wc_cloth_set_air_velocity(wa, c, NULL, 0), WC_ERROR_NOT_FOUND, "set_air_velocity(unknown, clear)", num, NULL);
        expect(wc_cloth_set_external_forces(wa, c, xyz, COUNT), WC_ERROR_NOT_FOUND, "set_external_forces(unknown)", num, NULL);
        expect(wc_cloth_get_links(wa, c, WC_LINK_BEND, pairs, NULL, 1), WC_ERROR_NOT_FOUND, "get_links(unknown)", num, NULL);
        expect(wc_cloth_get_triangles(wa, c, tri, 1), WC_ERROR_NOT_FOUND, "get_triangles(unknown)", num, NULL);
        expect(wc_cloth_get_view(wa, c, &v), WC_ERROR_NOT_FOUND, "get_view(unknown)", num, NULL);
        expect(wc_cloth_get_energy(wa, c, &e), WC_ERROR_NOT_FOUND, "get_energy(unknown)", num, NULL);
        CHECK(wc_cloth_particle_count(wa, c) == 0 && wc_cloth_pin_count(wa, c) == 0 &&
                  wc_cloth_link_count(wa, c, WC_LINK_STRETCH) == 0 && wc_cloth_triangle_count(wa, c) == 0,
              "counts of unknown cloth %d not zero", (int)c);
    }
}

static void test_step_arguments(void)
{
    const double bad_dt[] = {0.0, -1.0, NAN, 100.0, INFINITY, -INFINITY};
    for (size_t i = 0; i < sizeof bad_dt / sizeof bad_dt[0]; ++i) {
        char call[64];
        snprintf(call, sizeof call, "step dt = %g", bad_dt[i]);
        expect(wc_world_step(wa, bad_dt[i]), WC_ERROR_INVALID_ARGUMENT, call, "dt", NULL);
        snprintf(call, sizeof call, "advance frame_dt = %g", bad_dt[i]);
        expect(wc_world_advance(wa, bad_dt[i], 1), WC_ERROR_INVALID_ARGUMENT, call, "frame_dt", NULL);
    }
    expect(wc_world_advance(wa, DT, -1), WC_ERROR_INVALID_ARGUMENT, "advance substeps -1", "substeps", NULL);
    expect(wc_world_advance(wa, DT, 100001), WC_ERROR_INVALID_ARGUMENT, "advance substeps 100001", "substeps", NULL);

    /* Automatic substeps beyond max_substeps: an error, not a silent cap. */
    wc_world_def def = wc_world_def_default();
    def.max_substeps = 3;
    wc_world *w = NULL;
    CHECK(wc_world_create(&def, &w, NULL) == WC_OK, "world");
    wc_grid_cloth_def g = wc_grid_cloth_def_default();
    int32_t id;
    CHECK(wc_world_add_grid_cloth(w, &g, &id) == WC_OK, "grid");
    double before[3 * 32 * 32], after[3 * 32 * 32];
    wc_cloth_get_positions(w, id, before, 32 * 32);
    wc_status s = wc_world_advance(w, 1.0, 0);
    printf("%-44s -> %-26s \"%s\"\n", "advance 1 s with max_substeps 3", wc_status_name(s), wc_world_last_error(w));
    CHECK(s == WC_ERROR_INVALID_ARGUMENT, "advance beyond max_substeps returned %s", wc_status_name(s));
    CHECK(strstr(wc_world_last_error(w), "max_substeps") != NULL, "message lacks max_substeps");
    wc_cloth_get_positions(w, id, after, 32 * 32);
    CHECK(memcmp(before, after, sizeof before) == 0 && wc_world_time(w) == 0.0, "failed advance moved the cloth");
    wc_world_destroy(w);
}

/* ------------------------------------------------------------------------ */
/* Non-finite steps                                                          */
/* ------------------------------------------------------------------------ */

static int all_finite(const double *x, int32_t n)
{
    for (int32_t k = 0; k < 3 * n; ++k)
        if (!isfinite(x[k])) return 0;
    return 1;
}

/* A stiff, crumpled cloth stepped far above its stable step: each step
 * either succeeds with finite positions or returns WC_ERROR_NON_FINITE and
 * leaves positions, velocities and time as they were. */
static void test_huge_step(void)
{
    wc_world_def def = wc_world_def_default();
    def.thread_count = 1;
    wc_world *w = NULL;
    CHECK(wc_world_create(&def, &w, NULL) == WC_OK, "world");
    wc_grid_cloth_def g = wc_grid_cloth_def_default();
    g.count_u = g.count_v = 16;
    g.material.stretch_stiffness = 1e9;
    g.material.bend_stiffness = 1.0;
    int32_t id;
    CHECK(wc_world_add_grid_cloth(w, &g, &id) == WC_OK, "grid: %s", wc_world_last_error(w));
    const int32_t n = 256;
    double x[3 * 256], before[3 * 256], vbefore[3 * 256], v[3 * 256];
    wc_cloth_get_positions(w, id, x, n);
    for (int32_t k = 0; k < 3 * n; ++k) x[k] += 0.01 * sin(12.9898 * k); /* fixed crumple */
    wc_cloth_set_positions(w, id, x, n);
    int32_t corner = 0;
    wc_cloth_pin(w, id, &corner, 1);
    double dt = 1000.0 * wc_world_stable_dt(w);
    int ok_steps = 0, failed = 0;
    for (int s = 0; s < 200 && !failed; ++s) {
        wc_cloth_get_positions(w, id, before, n);
        wc_cloth_get_velocities(w, id, vbefore, n);
        double t = wc_world_time(w);
        wc_status st = wc_world_step(w, dt);
        wc_cloth_get_positions(w, id, x, n);
        CHECK(all_finite(x, n), "step %d left non-finite positions (%s)", s, wc_status_name(st));
        if (st == WC_OK) {
            ++ok_steps;
            continue;
        }
        failed = 1;
        printf("huge step: dt = %.3g s (1000 x stable %.3g s): %d good steps, then %s: \"%s\"\n", dt,
               wc_world_stable_dt(w), ok_steps, wc_status_name(st), wc_world_last_error(w));
        CHECK(st == WC_ERROR_NON_FINITE, "huge step returned %s", wc_status_name(st));
        wc_cloth_get_velocities(w, id, v, n);
        CHECK(memcmp(x, before, sizeof x) == 0, "failed step changed positions");
        CHECK(memcmp(v, vbefore, sizeof v) == 0, "failed step changed velocities");
        CHECK(wc_world_time(w) == t, "failed step advanced time");
        CHECK(strstr(wc_world_last_error(w), "particle") != NULL, "message does not name the particle");
    }
    if (!failed) printf("huge step: dt = %.3g s: 200 steps, all finite\n", dt);
    wc_world_destroy(w);
}

/* A step that fails must not drop pending pin targets ("on anything but
 * WC_OK the call changed nothing"). One particle gets a velocity of 1e308
 * m/s: a step of 10 s overflows it (non-finite), one of 1e-3 s does not.
 * The pin target set before the failed step must still be reached by the
 * next good one. Damping and drag off, so the huge velocity only enters
 * through x + v dt. */
static void test_failed_step_keeps_pin_targets(void)
{
    wc_world_def def = wc_world_def_default();
    def.thread_count = 1;
    wc_world *w = NULL;
    CHECK(wc_world_create(&def, &w, NULL) == WC_OK, "world");
    wc_grid_cloth_def g = wc_grid_cloth_def_default();
    g.count_u = g.count_v = 4;
    g.material.stretch_damping = 0.0;
    g.material.air_drag = 0.0;
    int32_t id;
    CHECK(wc_world_add_grid_cloth(w, &g, &id) == WC_OK, "grid");
    int32_t pin = 0;
    CHECK(wc_cloth_pin(w, id, &pin, 1) == WC_OK, "pin");
    double v[3 * 16] = {0}, x[3 * 16], before[3 * 16];
    v[3 * 15 + 2] = 1e308;
    CHECK(wc_cloth_set_velocities(w, id, v, 16) == WC_OK, "set_velocities");
    wc_cloth_get_positions(w, id, before, 16);
    double target[3] = {before[0] + 0.01, before[1] - 0.02, before[2] + 0.03};
    CHECK(wc_cloth_set_pin_targets(w, id, target, 1) == WC_OK, "targets");
    wc_status s = wc_world_step(w, 10.0);
    printf("overflowing step: %s \"%s\"\n", wc_status_name(s), wc_world_last_error(w));
    CHECK(s == WC_ERROR_NON_FINITE, "10 s step with v = 1e308 returned %s", wc_status_name(s));
    CHECK(strstr(wc_world_last_error(w), "particle 15") != NULL, "message does not name particle 15");
    wc_cloth_get_positions(w, id, x, 16);
    CHECK(memcmp(x, before, sizeof x) == 0, "failed step changed positions");
    s = wc_world_step(w, 1e-3);
    CHECK(s == WC_OK, "small step after the failure: %s", wc_world_last_error(w));
    wc_cloth_get_positions(w, id, x, 16);
    CHECK(all_finite(x, 16), "non-finite after a good step");
    printf("pin after the failed step and a good one: (%.6f, %.6f, %.6f), target (%.6f, %.6f, %.6f)\n",
           x[0], x[1], x[2], target[0], target[1], target[2]);
    CHECK(x[0] == target[0] && x[1] == target[1] && x[2] == target[2],
          "the failed step dropped the pin target: pin at (%g, %g, %g), target (%g, %g, %g)", x[0],
          x[1], x[2], target[0], target[1], target[2]);
    wc_world_destroy(w);
}

int main(void)
{
    wa = make_world(&ca);
    wb = make_world(&cb);
    check_twins("creation");
    test_world_def();
    test_null_world();
    test_struct_sizes();
    test_null_arguments();
    test_material();
    test_grid_def();
    test_mesh_def();
    test_pins();
    test_soft_pins();
    test_fields();
    test_arrays();
    test_unknown_cloth();
    test_step_arguments();
    wc_world_destroy(wa);
    wc_world_destroy(wb);
    test_huge_step();
    test_failed_step_keeps_pin_targets();
    return test_report("test_bad_input");
}
