/* libFuzzer target for the C API (docs/robustness.md). The input bytes are a little
 * program: a world description, then up to MAX_OPS calls (add mesh or grid
 * cloths, mesh and convex colliders, pins, pin targets, positions,
 * velocities, wetness, collider motion, steps and advances, and the
 * read-back calls) whose arguments come from the bytes: counts, indices
 * (negative, out of range, repeated), NaN, infinities, huge and tiny values,
 * degenerate and duplicate faces. Running out of bytes reads zeros, which
 * decode to sensible defaults, so short inputs make valid scenes.
 *
 * With bit 128 of the first byte set, one allocation (its number taken from
 * the input) fails, through wc_set_allocator.
 *
 * It aborts (a crash libFuzzer reports) when a call fails with an empty
 * message or an unknown status, or when a step or advance returns WC_OK and
 * leaves a non-finite position. The sanitizers (address, undefined) catch
 * the rest. Array lengths always match the counts the library is told,
 * except for counts outside the documented ranges, which the library must
 * reject before reading anything. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "wetcloth.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define MAX_OPS 24
#define MAX_VERTICES 24
#define MAX_FACES 24
#define MAX_HULL 10
/* Budget units one input may spend on substeps in all (the final step
 * included); a substep costs step_cost() units, 1 without self- or
 * cloth-cloth collision. The goal is many inputs through every entry point; long simulations belong to the
 * tests and benchmarks. Without a budget a few inputs (24 advances of 8
 * substeps of a self-colliding cloth) took seconds under the sanitizers and
 * the run averaged ~20 inputs per second per core. An operation over the
 * budget is skipped; its bytes are still read, so the input decodes the same.
 * The environment variable WC_FUZZ_STEP_BUDGET (1 .. 1000) overrides it for
 * a run. */
#define STEP_BUDGET 12

static int32_t step_budget(void)
{
    static int32_t budget = 0;
    if (!budget) {
        const char *e = getenv("WC_FUZZ_STEP_BUDGET");
        long b = e ? strtol(e, NULL, 10) : STEP_BUDGET;
        budget = b >= 1 && b <= 1000 ? (int32_t)b : STEP_BUDGET;
    }
    return budget;
}

static double g_steps_left;

/* Which cloths collide with themselves and with other cloths, by id. */
#define MAX_CLOTHS 32
static uint8_t g_self[MAX_CLOTHS], g_group[MAX_CLOTHS];

static void note_cloth(wc_status s, int32_t id, int32_t self, int32_t group)
{
    if (s != WC_OK || id < 0 || id >= MAX_CLOTHS) return;
    g_self[id] = self == 1, g_group[id] = group == 1;
}

/* Cost of one substep in budget units: 1, plus the worst case of the
 * self- and cloth-cloth collision, whose pair tests (a crumpled cloth makes
 * every vertex-face pair a candidate) cost ~2 us each under the sanitizers
 * and dominated the run: a tangled 56-particle grid took 66 ms a step.
 * With this cost the same 1,212-input corpus replays in 4.1 s instead of
 * 13.2 s, and a fresh run from the seeds makes ~380 inputs a second on one
 * core instead of ~100 to 150. Tangled cloths still get a step or more. */
#define PAIRS_PER_UNIT 150.0
static double step_cost(wc_world *w)
{
    /* within each self-colliding cloth, and across every two grouped
     * cloths: (sum of T)(sum of n) less each grouped cloth with itself */
    double self = 0.0, own = 0.0, group_t = 0.0, group_n = 0.0;
    int32_t n = wc_world_cloth_count(w);
    if (n > MAX_CLOTHS) n = MAX_CLOTHS;
    for (int32_t a = 0; a < n; ++a) {
        double t = wc_cloth_triangle_count(w, a), p = wc_cloth_particle_count(w, a);
        if (g_self[a]) self += t * p;
        if (g_group[a]) own += t * p, group_t += t, group_n += p;
    }
    return 1.0 + (self + group_t * group_n - own) / PAIRS_PER_UNIT;
}

/* Substeps a step or advance of dt in `substeps` would run (0: automatic,
 * estimated from the stable step as wc_world_advance does); 0 when the call
 * will be rejected anyway (bad dt or count). */
static double steps_wanted(wc_world *w, double dt, int32_t substeps, double safety)
{
    if (!(dt > 0.0) || !isfinite(dt) || substeps < 0) return 0.0;
    if (substeps > 0) return (double)substeps;
    double stable = wc_world_stable_dt(w);
    if (!(safety > 0.0 && safety <= 1.0)) return 0.0;
    return isfinite(stable) && stable > 0.0 ? ceil(dt / (safety * stable)) : 1.0;
}

/* Takes n substeps from the budget if they are there. */
static int spend(double n, wc_world *w)
{
    n *= step_cost(w);
    if (n > g_steps_left) return 0;
    g_steps_left -= n;
    return 1;
}

typedef struct reader {
    const uint8_t *p;
    size_t left;
} reader;

static uint8_t u8(reader *r)
{
    if (!r->left) return 0;
    --r->left;
    return *r->p++;
}

static uint32_t u32(reader *r)
{
    uint32_t v = 0;
    for (int k = 0; k < 4; ++k) v |= (uint32_t)u8(r) << (8 * k);
    return v;
}

/* A double: mostly `usual` or small values near it, sometimes the awkward
 * ones. */
static double num(reader *r, double usual)
{
    uint8_t kind = u8(r);
    switch (kind) {
    case 0: return usual;
    case 1: return NAN;
    case 2: return INFINITY;
    case 3: return -INFINITY;
    case 4: return 1e308;
    case 5: return -1e308;
    case 6: return 1e-308;
    case 7: return 0.0;
    case 8: return -usual;
    case 9: {
        uint64_t bits = (uint64_t)u32(r) | (uint64_t)u32(r) << 32;
        double d;
        memcpy(&d, &bits, sizeof d);
        return d;
    }
    case 10: return usual * 1e6;
    case 11: return usual * 1e-6;
    default: return usual * ((double)(int8_t)u8(r) / 32.0);
    }
}

/* A count: mostly small, sometimes out of range in either direction. */
static int32_t count(reader *r, int32_t most)
{
    uint8_t kind = u8(r);
    switch (kind) {
    case 250: return -1;
    case 251: return INT32_MIN;
    case 252: return INT32_MAX;
    case 253: return (1 << 27) + 1;
    case 254: return (1 << 26) + 1;
    default: return (int32_t)(kind % (uint8_t)(most + 1));
    }
}

/* Counts past the arrays here but within the library's range become the
 * array length; counts past the library's range stay, and it must reject
 * them by range alone, before reading the arrays. */
static int32_t fit(int32_t n, int32_t mine, int32_t library)
{
    return n > mine && n <= library ? mine : n;
}

static int out_of_range(int32_t n, int32_t most) { return n < 0 || n > most; }

/* An index: mostly in [0, n), sometimes negative or past the end. */
static int32_t index_in(reader *r, int32_t n)
{
    uint8_t kind = u8(r);
    if (kind == 255) return (int32_t)u32(r);
    if (kind == 254) return -1;
    if (kind == 253) return n;
    return n > 0 ? (int32_t)(kind % (uint32_t)n) : 0;
}

/* Allocation failure: with bit 128 of the first byte set, allocation
 * number g_fail_at (from the input) returns NULL; the calls must then fail
 * with WC_ERROR_OUT_OF_MEMORY and a message, and leak nothing (AddressSanitizer's
 * leak check runs after each input). */
static long g_allocs, g_fail_at = -1;

static void *fuzz_alloc(size_t size, void *user)
{
    (void)user;
    if (g_allocs++ == g_fail_at) return NULL;
    return malloc(size);
}

static void fuzz_free(void *memory, void *user)
{
    (void)user;
    free(memory);
}

static void fail(const char *what, const char *detail)
{
    fprintf(stderr, "fuzz_api: %s: %s\n", what, detail);
    abort();
}

/* Every call that fails must say why. */
static void check(wc_world *w, wc_status s, const char *call)
{
    if (s == WC_OK) return;
    if (s != WC_ERROR_INVALID_ARGUMENT && s != WC_ERROR_OUT_OF_MEMORY &&
        s != WC_ERROR_NON_FINITE && s != WC_ERROR_NOT_FOUND)
        fail(call, "unknown status");
    const char *m = wc_world_last_error(w);
    if (!m || !m[0]) fail(call, "failed with an empty message");
    if (strlen(m) >= 256) fail(call, "message not terminated");
}

/* After a successful step: every position finite. */
static void check_finite(wc_world *w, const char *call)
{
    static double xyz[3 * 1024];
    for (int32_t c = 0; c < wc_world_cloth_count(w); ++c) {
        int32_t n = wc_cloth_particle_count(w, c);
        if (n > 1024) continue;
        if (wc_cloth_get_positions(w, c, xyz, n) != WC_OK) fail(call, "positions not readable");
        for (int32_t i = 0; i < 3 * n; ++i)
            if (!isfinite(xyz[i])) fail(call, "WC_OK but a position is not finite");
    }
}

static wc_material material(reader *r)
{
    wc_material m = wc_material_default();
    uint8_t which = u8(r); /* bit k set: field k is fuzzed */
    uint8_t more = u8(r);
    if (which & 1) m.density = num(r, m.density);
    if (which & 2) m.stretch_stiffness = num(r, m.stretch_stiffness);
    if (which & 4) m.bend_stiffness = num(r, m.bend_stiffness);
    if (which & 8) m.stretch_damping = num(r, m.stretch_damping);
    if (which & 16) m.air_drag = num(r, m.air_drag);
    if (which & 32) m.thickness = num(r, m.thickness);
    if (which & 64) m.friction = num(r, m.friction);
    if (which & 128) m.adhesion = num(r, m.adhesion);
    if (more & 1) m.spread = num(r, m.spread);
    if (more & 2) m.wet_friction = num(r, m.wet_friction);
    if (more & 4) m.wet_mass_gain = num(r, m.wet_mass_gain);
    if (more & 8) m.wet_softening = num(r, m.wet_softening);
    if (more & 16) m.wicking = num(r, 0.01);
    if (more & 32) m.drying = num(r, 0.5);
    if (more & 64) m.wet_grip = num(r, m.wet_grip);
    return m;
}

/* Vertices near a 0.5 m square at height z, each coordinate possibly
 * replaced by an awkward value. */
static void vertices(reader *r, double *v, int32_t n, double z)
{
    for (int32_t i = 0; i < n; ++i) {
        v[3 * i] = 0.5 * (double)(i % 4) / 3.0 - 0.25;
        v[3 * i + 1] = 0.5 * (double)(i / 4) / 5.0 - 0.25;
        v[3 * i + 2] = z;
        uint8_t odd = u8(r);
        if (odd & 1) v[3 * i] = num(r, v[3 * i] + 0.01);
        if (odd & 2) v[3 * i + 1] = num(r, v[3 * i + 1] + 0.01);
        if (odd & 4) v[3 * i + 2] = num(r, z + 0.01);
        if (odd & 8) v[3 * i + 2] = z; /* coplanar again */
        if (odd & 16 && i > 0) memcpy(v + 3 * i, v + 3 * (i - 1), 3 * sizeof *v); /* duplicate */
    }
}

/* Faces of a strip over the vertices, with fuzzed indices mixed in
 * (degenerate, repeated, negative, out of range). */
static void faces(reader *r, int32_t *f, int32_t nf, int32_t size, int32_t nv)
{
    for (int32_t k = 0; k < nf; ++k)
        for (int32_t j = 0; j < size; ++j) {
            int32_t base = nv > 0 ? (k + j) % nv : 0;
            uint8_t odd = u8(r);
            f[size * k + j] = odd < 200 ? base : index_in(r, nv);
        }
}

static void op_mesh_cloth(reader *r, wc_world *w)
{
    static double v[3 * MAX_VERTICES];
    static int32_t f[4 * MAX_FACES];
    wc_mesh_cloth_def d = wc_mesh_cloth_def_default();
    d.vertex_count = count(r, MAX_VERTICES);
    d.face_count = count(r, MAX_FACES);
    if (d.vertex_count == 0) d.vertex_count = 12;
    if (d.face_count == 0) d.face_count = 10;
    d.vertex_count = fit(d.vertex_count, MAX_VERTICES, 1 << 26);
    d.face_count = fit(d.face_count, MAX_FACES, 1 << 27);
    uint8_t size = u8(r);
    d.face_size = size < 200 ? 3 + (size & 1) : (int32_t)(size % 7) - 1;
    int32_t nv = out_of_range(d.vertex_count, MAX_VERTICES) ? 0 : d.vertex_count;
    int32_t nf = out_of_range(d.face_count, MAX_FACES) ? 0 : d.face_count;
    int32_t fs = d.face_size == 3 || d.face_size == 4 ? d.face_size : 0;
    vertices(r, v, nv, num(r, 0.4));
    faces(r, f, nf, fs, nv);
    d.vertices = u8(r) == 1 ? NULL : v;
    d.faces = u8(r) == 1 ? NULL : f;
    d.material = material(r);
    uint8_t flags = u8(r);
    d.self_collision = flags < 240 ? flags & 1 : (int32_t)flags;
    d.wetness = (flags & 2) ? num(r, 1.0) : 0.0;
    d.collide_with_cloths = (flags & 4) ? 0 : 1;
    int32_t id = -1;
    wc_status s = wc_world_add_mesh_cloth(w, &d, u8(r) == 1 ? NULL : &id);
    check(w, s, "wc_world_add_mesh_cloth");
    note_cloth(s, s == WC_OK ? wc_world_cloth_count(w) - 1 : -1, d.self_collision, d.collide_with_cloths);
}

static void op_grid_cloth(reader *r, wc_world *w)
{
    wc_grid_cloth_def d = wc_grid_cloth_def_default();
    uint8_t cu = u8(r), cv = u8(r);
    d.count_u = cu < 250 ? 2 + cu % 7 : count(r, 8);
    d.count_v = cv < 250 ? 2 + cv % 7 : count(r, 8);
    if (d.count_u > 32768 || d.count_v > 32768 || (int64_t)d.count_u * d.count_v > 4096) {
        /* past the documented limits: must be rejected without work */
        if (d.count_u <= 32768 && d.count_v <= 32768 && d.count_u >= 2 && d.count_v >= 2)
            d.count_u = d.count_v = 8;
    }
    uint8_t odd = u8(r);
    d.size_u = (odd & 1) ? num(r, 0.5) : 0.5;
    d.size_v = (odd & 2) ? num(r, 0.5) : 0.5;
    d.center[2] = (odd & 4) ? num(r, 0.3) : 0.3;
    if (odd & 8)
        for (int k = 0; k < 3; ++k) d.axis_u[k] = num(r, d.axis_u[k]);
    if (odd & 16)
        for (int k = 0; k < 3; ++k) d.axis_v[k] = num(r, d.axis_v[k]);
    d.material = material(r);
    uint8_t flags = u8(r);
    d.self_collision = flags < 240 ? flags & 1 : (int32_t)flags;
    d.wetness = (flags & 2) ? num(r, 1.0) : 0.0;
    d.collide_with_cloths = (flags & 4) ? 0 : 1;
    int32_t id = -1;
    wc_status s = wc_world_add_grid_cloth(w, &d, &id);
    check(w, s, "wc_world_add_grid_cloth");
    note_cloth(s, id, d.self_collision, d.collide_with_cloths);
}

static void op_mesh_collider(reader *r, wc_world *w)
{
    static double v[3 * MAX_VERTICES];
    static int32_t t[3 * MAX_FACES];
    wc_mesh_collider_def d = wc_mesh_collider_def_default();
    d.vertex_count = count(r, MAX_VERTICES);
    d.triangle_count = count(r, MAX_FACES);
    if (d.vertex_count == 0) d.vertex_count = 8;
    if (d.triangle_count == 0) d.triangle_count = 6;
    d.vertex_count = fit(d.vertex_count, MAX_VERTICES, 1 << 26);
    d.triangle_count = fit(d.triangle_count, MAX_FACES, 1 << 27);
    int32_t nv = out_of_range(d.vertex_count, MAX_VERTICES) ? 0 : d.vertex_count;
    int32_t nt = out_of_range(d.triangle_count, MAX_FACES) ? 0 : d.triangle_count;
    vertices(r, v, nv, num(r, 0.0));
    faces(r, t, nt, 3, nv);
    d.vertices = v;
    d.triangles = t;
    uint8_t odd = u8(r);
    if (odd & 1) d.thickness = num(r, 0.01);
    if (odd & 2) d.friction = num(r, 0.5);
    int32_t id;
    check(w, wc_world_add_mesh_collider(w, &d, &id), "wc_world_add_mesh_collider");
}

static void op_convex_collider(reader *r, wc_world *w)
{
    static double points[3 * MAX_HULL];
    wc_convex_collider_def d = wc_convex_collider_def_default();
    uint8_t shape = u8(r);
    d.shape = shape < 250 ? (wc_shape)(shape % 4) : (wc_shape)((int)shape - 252);
    uint8_t odd = u8(r);
    if (odd & 1)
        for (int k = 0; k < 3; ++k) d.position[k] = num(r, 0.1);
    if (odd & 2)
        for (int k = 0; k < 4; ++k) d.rotation[k] = num(r, k == 0 ? 1.0 : 0.3);
    if (odd & 4) d.radius = num(r, 0.2);
    if (odd & 8) d.half_height = num(r, 0.2);
    if (odd & 16)
        for (int k = 0; k < 3; ++k) d.half_extents[k] = num(r, 0.2);
    if (odd & 32) d.thickness = num(r, 0.01);
    if (odd & 64) d.friction = num(r, 0.5);
    d.point_count = count(r, MAX_HULL);
    if (d.point_count == 0) d.point_count = 6;
    d.point_count = fit(d.point_count, MAX_HULL, 65536);
    int32_t np = out_of_range(d.point_count, MAX_HULL) ? 0 : d.point_count;
    for (int32_t i = 0; i < np; ++i) {
        points[3 * i] = (i & 1) ? 0.2 : -0.2;
        points[3 * i + 1] = (i & 2) ? 0.2 : -0.2;
        points[3 * i + 2] = (i & 4) ? 0.2 : -0.2;
        uint8_t p = u8(r);
        if (p & 1)
            for (int k = 0; k < 3; ++k) points[3 * i + k] = num(r, points[3 * i + k]);
        if (p & 2 && i > 0) memcpy(points + 3 * i, points, 3 * sizeof *points);
        if (p & 4) points[3 * i + 2] = 0.0; /* flat */
    }
    d.points = (odd & 128) ? NULL : points;
    int32_t id;
    check(w, wc_world_add_convex_collider(w, &d, &id), "wc_world_add_convex_collider");
}

static int32_t pick_cloth(reader *r, wc_world *w) { return index_in(r, wc_world_cloth_count(w)); }

static int32_t particles_or_count(reader *r, wc_world *w, int32_t cloth)
{
    int32_t n = wc_cloth_particle_count(w, cloth);
    uint8_t k = u8(r);
    if (k == 1) return n + 1;
    if (k == 2) return n - 1;
    if (k == 3) return -1;
    return n;
}

static double g_buf[3 * 4096 + 3];

static void op_cloth_arrays(reader *r, wc_world *w)
{
    int32_t cloth = pick_cloth(r, w);
    int32_t n = wc_cloth_particle_count(w, cloth);
    int32_t given = particles_or_count(r, w, cloth);
    if (given > 4096 || (given > n && given > 0)) given = n; /* arrays are n long */
    uint8_t what = u8(r);
    double usual = what % 5 == 2 ? 0.5 : 0.3;
    for (int32_t i = 0; i < 3 * (n > 0 ? n : 0) && i < 3 * 4096; ++i) {
        g_buf[i] = usual + 0.01 * (double)(i % 7);
        if (u8(r) == 7) g_buf[i] = num(r, usual);
    }
    const double *arr = u8(r) == 1 ? NULL : g_buf;
    /* the applied force fields, from values no older input used much (so
     * the corpus keeps its meaning); NULL with count 0 clears them */
    if (what >= 250) {
        int clear = u8(r) == 1;
        if (what < 253)
            check(w, wc_cloth_set_air_velocity(w, cloth, clear ? NULL : arr, clear ? 0 : given),
                  "wc_cloth_set_air_velocity");
        else
            check(w, wc_cloth_set_external_forces(w, cloth, clear ? NULL : arr, clear ? 0 : given),
                  "wc_cloth_set_external_forces");
        return;
    }
    switch (what % 5) {
    case 0: check(w, wc_cloth_set_positions(w, cloth, arr, given), "wc_cloth_set_positions"); break;
    case 1: check(w, wc_cloth_set_velocities(w, cloth, arr, given), "wc_cloth_set_velocities"); break;
    case 2: check(w, wc_cloth_set_wetness(w, cloth, arr, given), "wc_cloth_set_wetness"); break;
    case 3:
        check(w, wc_cloth_set_wetness_uniform(w, cloth, num(r, 0.5)), "wc_cloth_set_wetness_uniform");
        break;
    default: {
        int32_t pins = wc_cloth_pin_count(w, cloth);
        int32_t m = particles_or_count(r, w, cloth) - n + pins; /* pins, or off by one */
        if (m > pins) m = pins;
        check(w, wc_cloth_set_pin_targets(w, cloth, arr, m), "wc_cloth_set_pin_targets");
    }
    }
}

static void op_pin(reader *r, wc_world *w)
{
    int32_t cloth = pick_cloth(r, w);
    int32_t n = wc_cloth_particle_count(w, cloth);
    int32_t idx[8];
    int32_t m = (int32_t)(u8(r) % 9);
    for (int32_t k = 0; k < m; ++k) idx[k] = index_in(r, n);
    uint8_t how = u8(r);
    if (how == 1) check(w, wc_cloth_unpin_all(w, cloth), "wc_cloth_unpin_all");
    else if (how == 2) check(w, wc_cloth_pin(w, cloth, NULL, m), "wc_cloth_pin");
    else if (how == 3) check(w, wc_cloth_pin(w, cloth, idx, -1), "wc_cloth_pin");
    else if (how == 4 || how == 5) {
        /* soft pins, each stiffness from the bytes (NaN, 0, huge, ...) */
        double stiffness[8];
        for (int32_t k = 0; k < m; ++k) stiffness[k] = num(r, 50.0);
        check(w, wc_cloth_pin_soft(w, cloth, idx, how == 5 && m ? NULL : stiffness, m),
              "wc_cloth_pin_soft");
    } else check(w, wc_cloth_pin(w, cloth, idx, m), "wc_cloth_pin");
}

static void op_move_collider(reader *r, wc_world *w)
{
    int32_t k = index_in(r, wc_world_collider_count(w));
    uint8_t how = u8(r);
    if (how & 1) {
        double pos[3], rot[4];
        for (int j = 0; j < 3; ++j) pos[j] = num(r, 0.05);
        for (int j = 0; j < 4; ++j) rot[j] = num(r, j == 0 ? 1.0 : 0.1);
        check(w, wc_collider_set_transform(w, k, pos, rot), "wc_collider_set_transform");
    } else {
        int32_t n = count(r, MAX_VERTICES);
        if (n > MAX_VERTICES || n < 0) n = 0;
        for (int32_t i = 0; i < 3 * n; ++i) g_buf[i] = num(r, 0.01 * (double)(i % 5));
        check(w, wc_collider_set_vertices(w, k, g_buf, n), "wc_collider_set_vertices");
    }
}

static void op_step(reader *r, wc_world *w, int auto_ok, double safety)
{
    uint8_t how = u8(r);
    double dt = num(r, 2e-4);
    if (how & 1) {
        uint8_t s = u8(r);
        int32_t substeps = s < 250 ? (int32_t)(s % 8) + 1 : (int32_t)s - 252;
        if (substeps == 0 && !auto_ok) substeps = 1;
        if (isfinite(dt) && fabs(dt) > 0.05) dt = 0.05; /* keeps each input fast */
        if (!spend(steps_wanted(w, dt, substeps, safety), w)) return;
        wc_status st = wc_world_advance(w, dt, substeps);
        check(w, st, "wc_world_advance");
        if (st == WC_OK) check_finite(w, "wc_world_advance");
    } else {
        if (!spend(steps_wanted(w, dt, 1, safety), w)) return;
        wc_status s = wc_world_step(w, dt);
        check(w, s, "wc_world_step");
        if (s == WC_OK) check_finite(w, "wc_world_step");
    }
}

static void op_read(reader *r, wc_world *w)
{
    static int32_t ints[2 * 8192];
    static double dbl[8192];
    static uint8_t bytes[4096];
    int32_t cloth = pick_cloth(r, w);
    int32_t n = wc_cloth_particle_count(w, cloth);
    uint8_t what = u8(r);
    switch (what % 6) {
    case 0: {
        wc_link_kind kind = (wc_link_kind)(u8(r) % 3);
        int32_t links = wc_cloth_link_count(w, cloth, kind);
        int32_t cap = links <= 8192 ? links - (int32_t)(u8(r) & 1) : 0;
        check(w, wc_cloth_get_links(w, cloth, kind, ints, dbl, cap), "wc_cloth_get_links");
        break;
    }
    case 1: {
        int32_t tris = wc_cloth_triangle_count(w, cloth);
        int32_t cap = 3 * tris <= 2 * 8192 ? tris - (int32_t)(u8(r) & 1) : 0;
        check(w, wc_cloth_get_triangles(w, cloth, ints, cap), "wc_cloth_get_triangles");
        break;
    }
    case 2: {
        wc_cloth_view view;
        check(w, wc_cloth_get_view(w, cloth, (u8(r) & 1) ? NULL : &view), "wc_cloth_get_view");
        break;
    }
    case 3: {
        wc_energy e;
        check(w, wc_cloth_get_energy(w, cloth, &e), "wc_cloth_get_energy");
        break;
    }
    case 4: {
        if (n > 4096) break;
        check(w, wc_cloth_get_contacts(w, cloth, bytes, g_buf, n), "wc_cloth_get_contacts");
        check(w, wc_cloth_get_stuck(w, cloth, bytes, n), "wc_cloth_get_stuck");
        check(w, wc_cloth_get_wetness(w, cloth, dbl, n), "wc_cloth_get_wetness");
        check(w, wc_cloth_get_velocities(w, cloth, g_buf, n), "wc_cloth_get_velocities");
        break;
    }
    default: {
        wc_intersection_counts counts;
        check(w, wc_world_count_intersections(w, &counts), "wc_world_count_intersections");
        (void)wc_world_stable_dt(w);
        (void)wc_cloth_stable_dt(w, cloth);
        (void)wc_world_get_stats(w);
    }
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    reader r = {data, size};
    wc_world_def def = wc_world_def_default();
    uint8_t odd = u8(&r);
    if (odd & 1)
        for (int k = 0; k < 3; ++k) def.gravity[k] = num(&r, def.gravity[k]);
    def.thread_count = (odd & 2) ? (int32_t)u32(&r) : 1;
    if (odd & 4) {
        def.integrator = (wc_integrator)(int32_t)(u8(&r) % 5) - 1;
        def.implicit_tolerance = num(&r, 0.5);
    }
    if (odd & 8) def.substep_safety = num(&r, 0.9);
    if (odd & 16) def.max_substeps = count(&r, 64);
    if (def.thread_count > 2 && def.thread_count <= 1024) def.thread_count = 2;
    g_allocs = 0;
    g_fail_at = -1;
    if (odd & 128) {
        g_fail_at = (long)u8(&r) + 256L * (long)(u8(&r) & 3);
        wc_set_allocator(fuzz_alloc, fuzz_free, NULL);
    }
    wc_world *w = NULL;
    wc_message msg;
    memset(&msg, 0, sizeof msg);
    wc_status s = wc_world_create((odd & 32) && (odd & 64) ? NULL : &def, &w, &msg);
    if (s != WC_OK) {
        if (w) fail("wc_world_create", "failed but gave a world");
        if (!msg.text[0]) fail("wc_world_create", "failed with an empty message");
        wc_set_allocator(NULL, NULL, NULL);
        return 0;
    }
    /* automatic substepping only where the world caps it low */
    int auto_ok = def.max_substeps <= 64;
    int ops = 0;
    g_steps_left = step_budget() - 1; /* one for the final step */
    memset(g_self, 0, sizeof g_self);
    memset(g_group, 0, sizeof g_group);
    while (r.left && ops++ < MAX_OPS) {
        uint8_t op = u8(&r);
        switch (op % 10) {
        case 0: op_grid_cloth(&r, w); break;
        case 1: op_mesh_cloth(&r, w); break;
        case 2: op_mesh_collider(&r, w); break;
        case 3: op_convex_collider(&r, w); break;
        case 4: op_pin(&r, w); break;
        case 5: op_cloth_arrays(&r, w); break;
        case 6: op_move_collider(&r, w); break;
        case 7: op_read(&r, w); break;
        default: op_step(&r, w, auto_ok, def.substep_safety); break;
        }
    }
    /* and a step after the last accepted input */
    g_steps_left += 1.0;
    if (spend(1.0, w) && wc_world_step(w, 2e-4) == WC_OK) check_finite(w, "final wc_world_step");
    wc_world_destroy(w);
    wc_set_allocator(NULL, NULL, NULL);
    return 0;
}

#ifdef WC_FUZZ_REPLAY
/* Without libFuzzer (any compiler): runs the harness on each file named,
 * or on each file of each folder named, so the corpus replays as a plain
 * test in every build. */
#include <dirent.h>

static int replay_file(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        fprintf(stderr, "fuzz_api: cannot open %s\n", path);
        return 1;
    }
    static uint8_t buf[1 << 16];
    size_t n = fread(buf, 1, sizeof buf, f);
    fclose(f);
    LLVMFuzzerTestOneInput(buf, n);
    return 0;
}

int main(int argc, char **argv)
{
    int files = 0, bad = 0;
    for (int a = 1; a < argc; ++a) {
        DIR *d = opendir(argv[a]);
        if (!d) {
            bad += replay_file(argv[a]);
            ++files;
            continue;
        }
        struct dirent *e;
        while ((e = readdir(d))) {
            if (e->d_name[0] == '.') continue;
            char path[4096];
            snprintf(path, sizeof path, "%s/%s", argv[a], e->d_name);
            bad += replay_file(path);
            ++files;
        }
        closedir(d);
    }
    printf("fuzz_api replay: %d inputs, %d unreadable, 0 failures\n", files, bad);
    return bad != 0 || files == 0;
}
#endif
