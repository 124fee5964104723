/* Failure containment: every allocation of the library goes
 * through the hook of wc_set_allocator(), and this test makes each one fail
 * in turn, during world creation, while adding cloths, colliders, pins
 * (hard and soft) and the applied force fields (air velocity, external
 * forces),
 * and during steps that collide with mesh and convex colliders, self-collide,
 * collide two cloths with each other and stick wet cloth. Each failing call must return WC_ERROR_OUT_OF_MEMORY
 * with a message, free whatever it had allocated (the test tracks every
 * live block), change nothing (counts unchanged; a failing step keeps the
 * positions bitwise and the time), and the world must go on: retrying the
 * call succeeds, and the run ends bitwise where a run that never failed
 * does. All of it for each integrator: the large-step ones allocate their
 * buffers at their first step. */
#include <stdlib.h>
#include <string.h>

#include "scenes.h"
#include "test_util.h"
#include "wetcloth.h"

/* ------------------------------------------------------------------------ */
/* The tracking allocator                                                    */
/* ------------------------------------------------------------------------ */

static long g_calls;       /* allocation calls so far */
static long g_fail_at = -1; /* the call index that returns NULL, -1 none */
static int g_failed;       /* set when that call came */
static void **g_live;      /* blocks handed out and not freed */
static long g_live_count, g_live_cap;
static long g_bad_frees;   /* frees of blocks the hook never handed out */

static void *track_alloc(size_t size, void *user)
{
    (void)user;
    long index = g_calls++;
    if (index == g_fail_at) {
        g_failed = 1;
        return NULL;
    }
    if (size == 0) ++g_bad_frees; /* the library promises size >= 1 */
    void *p = malloc(size);
    if (!p) abort();
    if (g_live_count == g_live_cap) {
        g_live_cap = g_live_cap ? 2 * g_live_cap : 1024;
        g_live = realloc(g_live, (size_t)g_live_cap * sizeof *g_live);
        if (!g_live) abort();
    }
    g_live[g_live_count++] = p;
    return p;
}

static void track_free(void *memory, void *user)
{
    (void)user;
    /* newest first: most frees are of recent blocks */
    for (long i = g_live_count - 1; i >= 0; --i)
        if (g_live[i] == memory) {
            g_live[i] = g_live[--g_live_count];
            free(memory);
            return;
        }
    ++g_bad_frees;
}

static void fail_at(long index)
{
    g_fail_at = index;
    g_failed = 0;
}

/* ------------------------------------------------------------------------ */
/* The scene, built one call at a time                                       */
/* ------------------------------------------------------------------------ */

#define SIDE 10
#define STEPS 12
static const double DT = 2e-4;
static wc_integrator g_integrator; /* the one this round tests */
static const char *const INTEGRATOR_NAME[] = {"verlet", "xpbd", "implicit"};

typedef struct scene {
    wc_world *w;
    int32_t grid, mesh;
} scene;

static double sphere_v[3 * 200];
static int32_t sphere_t[3 * 400];
static int32_t sphere_nv, sphere_nt;

static const double hull_points[] = {0.0, 0.0, 0.0, 0.2, 0.0, 0.0, 0.0, 0.2, 0.0,
                                     0.0, 0.0, 0.2, 0.2, 0.2, 0.2};

/* Setup calls: each returns its status and (through *what) its name. */
static wc_status op(scene *s, int k, const char **what)
{
    switch (k) {
    case 0: {
        *what = "wc_world_create";
        wc_world_def def = wc_world_def_default();
        def.thread_count = 1;
        def.integrator = g_integrator;
        wc_message msg;
        memset(&msg, 'x', sizeof msg);
        wc_status st = wc_world_create(&def, &s->w, &msg);
        if (st) {
            CHECK(s->w == NULL, "failed world create left a world");
            CHECK(msg.text[0] != '\0' && strlen(msg.text) < sizeof msg.text,
                  "world create failed with status %d and no message", (int)st);
        }
        return st;
    }
    case 1: {
        *what = "wc_world_add_grid_cloth (self-collision, soaked)";
        wc_grid_cloth_def g = wc_grid_cloth_def_default();
        g.count_u = g.count_v = SIDE;
        g.size_u = g.size_v = 0.6;
        g.center[2] = 0.3 + 0.004; /* resting on the sphere from the start */
        g.self_collision = 1;
        g.wetness = 1.0;
        return wc_world_add_grid_cloth(s->w, &g, &s->grid);
    }
    case 2: {
        /* 4 mm over the grid cloth: within the thickness, so the two
         * cloths collide with each other (cloth_group.c) from the first
         * step, and its allocations fail in turn too */
        *what = "wc_world_add_mesh_cloth (triangles, on the grid cloth)";
        double v[3 * 4] = {-0.3, -0.3, 0.308, 0.3, -0.3, 0.308, 0.3, 0.3, 0.308, -0.3, 0.3, 0.308};
        int32_t f[6] = {0, 1, 2, 0, 2, 3};
        wc_mesh_cloth_def m = wc_mesh_cloth_def_default();
        m.vertices = v;
        m.vertex_count = 4;
        m.faces = f;
        m.face_count = 2;
        m.self_collision = 1;
        m.wetness = 0.5;
        return wc_world_add_mesh_cloth(s->w, &m, &s->mesh);
    }
    case 3: {
        *what = "wc_world_add_mesh_collider (sphere)";
        wc_mesh_collider_def c = wc_mesh_collider_def_default();
        c.vertices = sphere_v;
        c.vertex_count = sphere_nv;
        c.triangles = sphere_t;
        c.triangle_count = sphere_nt;
        int32_t id;
        return wc_world_add_mesh_collider(s->w, &c, &id);
    }
    case 4: {
        *what = "wc_world_add_convex_collider (box)";
        wc_convex_collider_def c = wc_convex_collider_def_default();
        c.shape = WC_SHAPE_BOX;
        c.position[0] = 0.35;
        c.position[2] = 0.1;
        c.half_extents[0] = c.half_extents[1] = c.half_extents[2] = 0.2;
        int32_t id;
        return wc_world_add_convex_collider(s->w, &c, &id);
    }
    case 5: {
        *what = "wc_world_add_convex_collider (hull)";
        wc_convex_collider_def c = wc_convex_collider_def_default();
        c.shape = WC_SHAPE_CONVEX_HULL;
        c.points = hull_points;
        c.point_count = 5;
        c.position[0] = -0.4;
        c.position[2] = 0.1;
        int32_t id;
        return wc_world_add_convex_collider(s->w, &c, &id);
    }
    case 6: {
        *what = "wc_world_add_convex_collider (capsule)";
        wc_convex_collider_def c = wc_convex_collider_def_default();
        c.shape = WC_SHAPE_CAPSULE;
        c.radius = 0.05;
        c.position[1] = 0.4;
        int32_t id;
        return wc_world_add_convex_collider(s->w, &c, &id);
    }
    case 7: {
        *what = "wc_world_add_convex_collider (sphere, the 5th collider: grows the list)";
        wc_convex_collider_def c = wc_convex_collider_def_default();
        c.radius = 0.05;
        c.position[1] = -0.4;
        int32_t id;
        return wc_world_add_convex_collider(s->w, &c, &id);
    }
    case 8: {
        *what = "wc_cloth_pin";
        int32_t pins[2] = {0, SIDE - 1};
        return wc_cloth_pin(s->w, s->grid, pins, 2);
    }
    case 9: {
        *what = "wc_cloth_pin_soft";
        int32_t pins[2] = {SIDE * SIDE - SIDE, SIDE * SIDE - 1};
        double stiffness[2] = {200.0, 300.0};
        return wc_cloth_pin_soft(s->w, s->grid, pins, stiffness, 2);
    }
    case 10: {
        *what = "wc_cloth_pin (after soft pins: grows their stiffness list)";
        int32_t pin = SIDE / 2;
        return wc_cloth_pin(s->w, s->grid, &pin, 1);
    }
    case 11: {
        *what = "wc_cloth_set_air_velocity";
        double u[3 * SIDE * SIDE];
        for (int i = 0; i < 3 * SIDE * SIDE; ++i) u[i] = i % 3 == 0 ? 3.0 : 0.1;
        return wc_cloth_set_air_velocity(s->w, s->grid, u, SIDE * SIDE);
    }
    case 12: {
        *what = "wc_cloth_set_external_forces";
        double p[3 * 4] = {0.0, 0.5, -1.0, 0.0, 0.5, -1.0, 0.0, 0.5, -1.0, 0.0, 0.5, -1.0};
        return wc_cloth_set_external_forces(s->w, s->mesh, p, 4);
    }
    }
    return WC_OK;
}
#define OPS 13

/* What a failed call must not change. */
typedef struct counts {
    int32_t cloths, colliders, pins;
} counts;

static counts get_counts(const scene *s)
{
    counts c = {0, 0, 0};
    if (!s->w) return c;
    c.cloths = wc_world_cloth_count(s->w);
    c.colliders = wc_world_collider_count(s->w);
    c.pins = c.cloths ? wc_cloth_pin_count(s->w, s->grid) : 0;
    return c;
}

/* Hash of both cloths' positions. */
static uint64_t hash_all(const scene *s)
{
    return scene_hash_positions(s->w, s->grid) * 31u + scene_hash_positions(s->w, s->mesh);
}

/* Builds the whole scene with no failure. */
static void build(scene *s)
{
    memset(s, 0, sizeof *s);
    for (int k = 0; k < OPS; ++k) {
        const char *what = "";
        wc_status st = op(s, k, &what);
        CHECK(st == WC_OK, "%s: %s", what, k ? wc_world_last_error(s->w) : "");
    }
}

static uint64_t g_reference; /* hash after STEPS steps of a run that never failed */
static long g_step_allocs[STEPS];

static int run_steps(scene *s, int from)
{
    for (int i = from; i < STEPS; ++i)
        if (wc_world_step(s->w, DT) != WC_OK) {
            CHECK(0, "step %d: %s", i, wc_world_last_error(s->w));
            return 0;
        }
    return 1;
}

static void reference(void)
{
    scene s;
    fail_at(-1);
    build(&s);
    for (int i = 0; i < STEPS; ++i) {
        long before = g_calls;
        CHECK(wc_world_step(s.w, DT) == WC_OK, "reference step %d: %s", i,
              wc_world_last_error(s.w));
        g_step_allocs[i] = g_calls - before;
    }
    wc_step_stats st = wc_world_get_stats(s.w);
    CHECK(st.collider_contacts > 0, "the scene should touch its colliders (%d contacts)",
          (int)st.collider_contacts);
    g_reference = hash_all(&s);
    wc_world_destroy(s.w);
    CHECK(g_live_count == 0, "reference run leaks %ld blocks", g_live_count);
}

/* Fails allocation `index` (counted from the start of the setup) and
 * checks the failing call. Returns 0 once the index lies past the setup. */
static int setup_with_failure(long index)
{
    scene s;
    memset(&s, 0, sizeof s);
    g_calls = 0;
    fail_at(index);
    int hit = 0;
    for (int k = 0; k < OPS; ++k) {
        counts before = get_counts(&s);
        long live_before = g_live_count;
        const char *what = "";
        wc_status st = op(&s, k, &what);
        if (g_failed && !hit) {
            hit = 1;
            CHECK(st == WC_ERROR_OUT_OF_MEMORY, "allocation %ld fails in %s: status %s", index,
                  what, wc_status_name(st));
            if (k > 0) {
                const char *m = wc_world_last_error(s.w);
                CHECK(m[0] != '\0', "allocation %ld fails in %s: no message", index, what);
            }
            counts after = get_counts(&s);
            CHECK(memcmp(&before, &after, sizeof before) == 0,
                  "allocation %ld fails in %s: counts changed (%d %d %d -> %d %d %d)", index, what,
                  (int)before.cloths, (int)before.colliders, (int)before.pins, (int)after.cloths,
                  (int)after.colliders, (int)after.pins);
            CHECK(g_live_count == live_before,
                  "allocation %ld fails in %s: %ld blocks leaked by the failed call", index, what,
                  g_live_count - live_before);
            /* the retry succeeds */
            fail_at(-1);
            g_failed = 1;
            st = op(&s, k, &what);
            CHECK(st == WC_OK, "retrying %s after a failed allocation %ld: %s", what, index,
                  s.w ? wc_world_last_error(s.w) : "");
        } else {
            CHECK(st == WC_OK, "%s: %s", what, s.w ? wc_world_last_error(s.w) : "");
        }
        if (st) break;
    }
    if (hit && s.w && run_steps(&s, 0))
        CHECK(hash_all(&s) == g_reference,
              "allocation %ld failed during setup: after the retry the run differs from the "
              "reference", index);
    wc_world_destroy(s.w);
    CHECK(g_live_count == 0, "allocation %ld failed during setup: %ld blocks leaked", index,
          g_live_count);
    CHECK(g_bad_frees == 0, "%ld frees of unknown blocks", g_bad_frees);
    fail_at(-1);
    return hit;
}

static void read_all(const scene *s, double *out)
{
    int32_t n = wc_cloth_particle_count(s->w, s->grid);
    CHECK(wc_cloth_get_positions(s->w, s->grid, out, n) == WC_OK, "positions");
    CHECK(wc_cloth_get_positions(s->w, s->mesh, out + 3 * n, 4) == WC_OK, "positions");
}

/* Runs `step` good steps, then fails allocation `offset` of the next. */
static void step_with_failure(int step, long offset)
{
    enum { N = 3 * (SIDE * SIDE + 4) };
    scene s;
    fail_at(-1);
    build(&s);
    for (int i = 0; i < step; ++i)
        CHECK(wc_world_step(s.w, DT) == WC_OK, "step %d: %s", i, wc_world_last_error(s.w));
    double before[N], after[N];
    read_all(&s, before);
    double t = wc_world_time(s.w);
    long live_before = g_live_count;
    fail_at(g_calls + offset);
    wc_status st = wc_world_step(s.w, DT);
    CHECK(g_failed, "step %d: allocation %ld of the step never came", step, offset);
    CHECK(st == WC_ERROR_OUT_OF_MEMORY, "step %d, allocation %ld fails: status %s", step, offset,
          wc_status_name(st));
    CHECK(wc_world_last_error(s.w)[0] != '\0', "step %d, allocation %ld fails: no message", step,
          offset);
    read_all(&s, after);
    CHECK(memcmp(before, after, sizeof before) == 0,
          "step %d, allocation %ld fails: positions changed (%s)", step, offset,
          wc_world_last_error(s.w));
    CHECK(wc_world_time(s.w) == t, "step %d, allocation %ld fails: time moved", step, offset);
    /* a step may keep buffers it grew for the next step, but must not lose
     * track of them: the destroy below frees everything */
    (void)live_before;
    fail_at(-1);
    /* the world goes on: the retry and the steps after it succeed, and end
     * bitwise where the run that never failed does (the failed step put
     * back the contact state it had changed) */
    if (run_steps(&s, step))
        CHECK(hash_all(&s) == g_reference,
              "step %d, allocation %ld failed: after the retry the run differs from the reference",
              step, offset);
    wc_world_destroy(s.w);
    CHECK(g_live_count == 0, "step %d, allocation %ld failed: %ld blocks leaked", step, offset,
          g_live_count);
    CHECK(g_bad_frees == 0, "%ld frees of unknown blocks", g_bad_frees);
}

/* Every allocation of the setup and of each step fails in turn, for the
 * world's current integrator. */
static void fail_everything(void)
{
    reference();

    long setup_points = 0;
    while (setup_with_failure(setup_points)) ++setup_points;
    CHECK(setup_points > 50, "the setup should allocate more than 50 times (%ld)", setup_points);

    long step_points = 0;
    for (int step = 0; step < STEPS; ++step) {
        for (long k = 0; k < g_step_allocs[step]; ++k) step_with_failure(step, k);
        step_points += g_step_allocs[step];
    }
    CHECK(g_step_allocs[0] > 10, "the first step should allocate (%ld)", g_step_allocs[0]);
    printf("%s: %ld setup and %ld step allocation failures contained\n",
           INTEGRATOR_NAME[g_integrator], setup_points, step_points);
}

int main(void)
{
    sphere_nv = scene_uv_sphere(0.3, 16, 8, sphere_v, sphere_t, &sphere_nt);
    wc_set_allocator(track_alloc, track_free, NULL);

    const wc_integrator all[] = {WC_INTEGRATOR_VERLET, WC_INTEGRATOR_XPBD, WC_INTEGRATOR_IMPLICIT};
    for (size_t k = 0; k < sizeof all / sizeof all[0]; ++k) {
        g_integrator = all[k];
        fail_everything();
    }

    /* back to malloc: a world made now works and frees through free() */
    wc_set_allocator(NULL, NULL, NULL);
    long calls = g_calls;
    wc_world *w = scene_world(1);
    CHECK(g_calls == calls, "the hook is still called after wc_set_allocator(NULL, NULL, NULL)");
    wc_world_destroy(w);
    free(g_live);
    return test_report("test_oom");
}
