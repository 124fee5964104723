/* Contact-stage benchmark: the scenes artists bake, one run per call, one
 * JSON line of figures out. It uses the public API only, so the same binary
 * runs against another build of the library (LD_LIBRARY_PATH=<that build>):
 * tools/bench/contacts_side.py runs it against this build and the build of
 * the commit before the contact stage, alternated, with Blender's cloth
 * through bpy on the same scenes.
 *
 *   build/tools/bench_contacts scene=NAME [key=value ...]
 *
 * Scenes (grid cloths fall from rest onto a mesh collider; frames of 1/24 s):
 *   thesis     20 x 20 cloth, 1 m, 0.6 m above the 114-vertex UV sphere of
 *              radius 0.3 m (16 x 8, 224 triangles): Table 3.2's scene
 *   sphere64   50 x 50 cloth, 1 m, 0.6 m above a 64 x 32 UV sphere of radius
 *              0.3 m (3,968 triangles)
 *   sphere176  the same above a 176 x 88 UV sphere (30,624 triangles)
 *   soaked     50 x 50 cloth, 2 m, 1 m above a 176 x 88 UV sphere of radius
 *              0.5 m (the soaked cloth; wet=1 soaks it)
 *   cylinder   33 x 33 cloth, 1 m, 0.35 m above a 96 x 154 open tube (14,784
 *              vertices, 29,376 triangles) of radius 0.15 m and length 1.2 m
 *              along x, whose ends bend up over the run (z += 0.25 s(t)
 *              (x / 0.6)^2, s from 0 to 1 smoothly): a deforming collider
 *   drape101   101 x 101 cloth, 1 m, 0.6 m above the 114-vertex sphere
 *
 * Keys: frames (24), integrator (default | verlet | xpbd | implicit),
 * steps (substeps per frame, 0 = automatic; ignored with the default
 * integrator unless given), threads (1), adapt (1: the world's adapt_threads,
 * the library's default; 0 runs exactly `threads`), wet (0 | 1: wetness 1), self (0 |
 * 1: self-collision), thickness (collider thickness, m, 0.02: Blender's
 * Collision modifier default, which the add-on passes on), friction (the
 * collider's, 0.5), size (override the cloth's particle count per side),
 * out (file: float64 positions of every frame, for error measurement),
 * adhesion, spread, wet_friction, wet_grip, damping (stretch damping; the cloth
 * material's, for experiments),
 * check (1: count intersections at the last frame; 2: at every frame),
 * bend (1: the cylinder's ends rise; 0: it stays straight), carry (m/s, 0:
 * from the middle frame of the run on, the collider moves along x at that
 * speed, carrying the cloth that rests on it), trace (1: one
 * line per frame on stderr: wall and collide ms, the threads of its last
 * step, longest link, fail-safe particles, intersections when counted).
 *
 * Printed: ms per frame (wall), collision ms per frame (the library's
 * collide phase), substeps per frame, intersections (all, and cloth against
 * the collider: without self-collision a cloth may pass through itself),
 * fail-safe particles (summed over the last substep of each frame), the highest particle
 * after landing against the start height, the longest stretch link over
 * the run as a multiple of its rest length, and whether every position
 * stayed finite. Landing is the first frame with a collider contact. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"
#include "wetcloth.h"

#define PI 3.14159265358979323846

typedef struct options {
    const char *scene;
    int frames, steps, threads, adapt, wet, self, size, check, steps_given, bend, trace;
    const char *integrator;
    double thickness, friction, adhesion, spread, wet_friction, wet_grip, damping, carry;
    const char *out;
} options;

typedef struct mesh {
    double *v;
    int32_t *t;
    int32_t vertex_count, triangle_count;
} mesh;

static void *checked_malloc(size_t bytes)
{
    void *p = malloc(bytes ? bytes : 1);
    if (!p) {
        fprintf(stderr, "out of memory\n");
        exit(1);
    }
    return p;
}

/* UV sphere as Blender and tools/bench/scenes.py make it: poles plus
 * (rings - 1) rings of `segments` vertices; 2 segments (rings - 1)
 * triangles. */
static mesh uv_sphere(int segments, int rings, double radius)
{
    mesh m;
    m.vertex_count = 2 + (rings - 1) * segments;
    m.triangle_count = 2 * segments * (rings - 1);
    m.v = checked_malloc(3 * (size_t)m.vertex_count * sizeof *m.v);
    m.t = checked_malloc(3 * (size_t)m.triangle_count * sizeof *m.t);
    int32_t n = 0, k = 0;
    m.v[0] = m.v[1] = 0.0, m.v[2] = radius, n = 1;
    for (int j = 1; j < rings; ++j)
        for (int i = 0; i < segments; ++i, ++n) {
            double polar = PI * j / rings, az = 2.0 * PI * i / segments;
            m.v[3 * n] = radius * sin(polar) * cos(az);
            m.v[3 * n + 1] = radius * sin(polar) * sin(az);
            m.v[3 * n + 2] = radius * cos(polar);
        }
    m.v[3 * n] = m.v[3 * n + 1] = 0.0, m.v[3 * n + 2] = -radius;
    int32_t bottom = n, base = 1 + (rings - 2) * segments;
    for (int i = 0; i < segments; ++i) m.t[k++] = 0, m.t[k++] = 1 + i, m.t[k++] = 1 + (i + 1) % segments;
    for (int j = 0; j + 2 < rings; ++j)
        for (int i = 0; i < segments; ++i) {
            int32_t a = 1 + j * segments + i, b = 1 + j * segments + (i + 1) % segments;
            m.t[k++] = a, m.t[k++] = a + segments, m.t[k++] = b;
            m.t[k++] = b, m.t[k++] = a + segments, m.t[k++] = b + segments;
        }
    for (int i = 0; i < segments; ++i)
        m.t[k++] = bottom, m.t[k++] = base + (i + 1) % segments, m.t[k++] = base + i;
    return m;
}

/* Open tube along x: `rings` circles of `segments` vertices from -len/2 to
 * len/2, quads split in two. */
static mesh tube(int segments, int rings, double radius, double length)
{
    mesh m;
    m.vertex_count = segments * rings;
    m.triangle_count = 2 * segments * (rings - 1);
    m.v = checked_malloc(3 * (size_t)m.vertex_count * sizeof *m.v);
    m.t = checked_malloc(3 * (size_t)m.triangle_count * sizeof *m.t);
    for (int j = 0; j < rings; ++j)
        for (int i = 0; i < segments; ++i) {
            double a = 2.0 * PI * i / segments;
            double *p = m.v + 3 * (size_t)(j * segments + i);
            p[0] = -0.5 * length + length * j / (rings - 1);
            p[1] = radius * cos(a);
            p[2] = radius * sin(a);
        }
    int32_t k = 0;
    for (int j = 0; j + 1 < rings; ++j)
        for (int i = 0; i < segments; ++i) {
            int32_t a = j * segments + i, b = j * segments + (i + 1) % segments;
            m.t[k++] = a, m.t[k++] = b, m.t[k++] = a + segments;
            m.t[k++] = b, m.t[k++] = b + segments, m.t[k++] = a + segments;
        }
    return m;
}

/* The tube's bend at time s in [0, 1] of the run: its ends rise. */
static void bend_tube(const mesh *rest, double s, double *out)
{
    double ease = 0.5 - 0.5 * cos(PI * s);
    for (int32_t v = 0; v < rest->vertex_count; ++v) {
        const double *p = rest->v + 3 * (size_t)v;
        double u = p[0] / 0.6;
        out[3 * v] = p[0], out[3 * v + 1] = p[1], out[3 * v + 2] = p[2] + 0.25 * ease * u * u;
    }
}

static int32_t add_mesh(wc_world *w, const mesh *m, const options *o)
{
    wc_mesh_collider_def d = wc_mesh_collider_def_default();
    d.vertices = m->v, d.vertex_count = m->vertex_count;
    d.triangles = m->t, d.triangle_count = m->triangle_count;
    d.thickness = o->thickness, d.friction = o->friction;
    int32_t id;
    bench_check(wc_world_add_mesh_collider(w, &d, &id), w, "add collider");
    return id;
}

static int parse(int argc, char **argv, options *o)
{
    memset(o, 0, sizeof *o);
    o->scene = "thesis", o->frames = 24, o->threads = 1, o->adapt = 1, o->thickness = 0.02, o->friction = 0.5;
    o->integrator = "default", o->check = 1, o->bend = 1, o->adhesion = -1.0, o->spread = -1.0, o->wet_friction = -1.0, o->wet_grip = -1.0, o->damping = -1.0;
    for (int k = 1; k < argc; ++k) {
        char *eq = strchr(argv[k], '=');
        if (!eq) return 0;
        *eq = '\0';
        const char *key = argv[k], *val = eq + 1;
        if (!strcmp(key, "scene")) o->scene = val;
        else if (!strcmp(key, "frames")) o->frames = atoi(val);
        else if (!strcmp(key, "steps")) o->steps = atoi(val), o->steps_given = 1;
        else if (!strcmp(key, "threads")) o->threads = atoi(val);
        else if (!strcmp(key, "adapt")) o->adapt = atoi(val);
        else if (!strcmp(key, "wet")) o->wet = atoi(val);
        else if (!strcmp(key, "self")) o->self = atoi(val);
        else if (!strcmp(key, "size")) o->size = atoi(val);
        else if (!strcmp(key, "check")) o->check = atoi(val);
        else if (!strcmp(key, "bend")) o->bend = atoi(val);
        else if (!strcmp(key, "carry")) o->carry = atof(val);
        else if (!strcmp(key, "trace")) o->trace = atoi(val);
        else if (!strcmp(key, "integrator")) o->integrator = val;
        else if (!strcmp(key, "thickness")) o->thickness = atof(val);
        else if (!strcmp(key, "friction")) o->friction = atof(val);
        else if (!strcmp(key, "out")) o->out = val;
        else if (!strcmp(key, "adhesion")) o->adhesion = atof(val);
        else if (!strcmp(key, "spread")) o->spread = atof(val);
        else if (!strcmp(key, "wet_friction")) o->wet_friction = atof(val);
        else if (!strcmp(key, "wet_grip")) o->wet_grip = atof(val);
        else if (!strcmp(key, "damping")) o->damping = atof(val);
        else return 0;
    }
    return o->frames > 0;
}

typedef struct scene {
    wc_world *world;
    int32_t cloth, collider;
    mesh collider_mesh;
    int deforming;
    double start_height;
} scene;

static int set_integrator(wc_world_def *wd, const char *name)
{
    if (!strcmp(name, "default")) return 1;
    if (!strcmp(name, "verlet")) wd->integrator = WC_INTEGRATOR_VERLET;
    else if (!strcmp(name, "xpbd")) wd->integrator = WC_INTEGRATOR_XPBD;
    else if (!strcmp(name, "implicit")) wd->integrator = WC_INTEGRATOR_IMPLICIT;
    else return 0;
    return 1;
}

static scene make_scene(const options *o)
{
    scene s;
    memset(&s, 0, sizeof s);
    wc_world_def wd = wc_world_def_default();
    wd.thread_count = o->threads;
    wd.adapt_threads = o->adapt;
    if (!set_integrator(&wd, o->integrator)) {
        fprintf(stderr, "unknown integrator %s\n", o->integrator);
        exit(2);
    }
    wc_message msg;
    bench_check(wc_world_create(&wd, &s.world, &msg), NULL, msg.text);
    wc_grid_cloth_def g = wc_grid_cloth_def_default();
    int n = 20;
    double width = 1.0, height = 0.6;
    if (!strcmp(o->scene, "thesis") || !strcmp(o->scene, "drape101")) {
        s.collider_mesh = uv_sphere(16, 8, 0.3);
        n = o->scene[0] == 't' ? 20 : 101;
    } else if (!strcmp(o->scene, "sphere64")) {
        s.collider_mesh = uv_sphere(64, 32, 0.3), n = 50;
    } else if (!strcmp(o->scene, "sphere176")) {
        s.collider_mesh = uv_sphere(176, 88, 0.3), n = 50;
    } else if (!strcmp(o->scene, "soaked")) {
        s.collider_mesh = uv_sphere(176, 88, 0.5), n = 50, width = 2.0, height = 1.0;
    } else if (!strcmp(o->scene, "cylinder")) {
        s.collider_mesh = tube(96, 154, 0.15, 1.2), n = 33, height = 0.35, s.deforming = o->bend;
    } else {
        fprintf(stderr, "unknown scene %s\n", o->scene);
        exit(2);
    }
    if (o->size > 1) n = o->size;
    s.collider = add_mesh(s.world, &s.collider_mesh, o);
    g.count_u = g.count_v = n;
    g.size_u = g.size_v = width;
    g.center[2] = height;
    g.self_collision = o->self;
    g.wetness = o->wet ? 1.0 : 0.0;
    if (o->adhesion >= 0.0) g.material.adhesion = o->adhesion;
    if (o->spread >= 0.0) g.material.spread = o->spread;
    if (o->wet_friction >= 0.0) g.material.wet_friction = o->wet_friction;
    if (o->wet_grip >= 0.0) g.material.wet_grip = o->wet_grip;
    if (o->damping >= 0.0) g.material.stretch_damping = o->damping;
    bench_check(wc_world_add_grid_cloth(s.world, &g, &s.cloth), s.world, "add cloth");
    s.start_height = height;
    return s;
}

/* Longest stretch link now as a multiple of its rest length. */
static double longest_link(const double *xyz, const int32_t *pairs, const double *rest, int32_t count)
{
    double most = 0.0;
    for (int32_t k = 0; k < count; ++k) {
        const double *a = xyz + 3 * (size_t)pairs[2 * k], *b = xyz + 3 * (size_t)pairs[2 * k + 1];
        double d[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
        double r = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) / rest[k];
        if (r > most) most = r;
    }
    return most;
}

int main(int argc, char **argv)
{
    options o;
    if (!parse(argc, argv, &o)) {
        fprintf(stderr, "usage: bench_contacts scene=thesis|sphere64|sphere176|soaked|cylinder|"
                        "drape101 [frames=24] [integrator=default|verlet|xpbd|implicit] [steps=0] "
                        "[threads=1] [adapt=1] [wet=0] [self=0] [thickness=0.02] [friction=0.5] [size=N] "
                        "[check=1] [bend=1] [carry=0] [trace=0] [out=FILE]\n");
        return 2;
    }
    scene s = make_scene(&o);
    int32_t n = wc_cloth_particle_count(s.world, s.cloth);
    int32_t links = wc_cloth_link_count(s.world, s.cloth, WC_LINK_STRETCH);
    int32_t *pairs = checked_malloc(2 * (size_t)links * sizeof *pairs);
    double *rest = checked_malloc((size_t)links * sizeof *rest);
    double *xyz = checked_malloc(3 * (size_t)n * sizeof *xyz);
    int moves = s.deforming || o.carry != 0.0;
    double *bent = moves ? checked_malloc(3 * (size_t)s.collider_mesh.vertex_count * sizeof *bent) : NULL;
    bench_check(wc_cloth_get_links(s.world, s.cloth, WC_LINK_STRETCH, pairs, rest, links), s.world,
                "links");
    uint8_t *contact = checked_malloc((size_t)n);
    FILE *out = o.out ? fopen(o.out, "wb") : NULL;
    if (o.out && !out) {
        fprintf(stderr, "cannot write %s\n", o.out);
        return 1;
    }
    /* Steps per frame: the library's default unless asked. */
    int steps = o.steps_given ? o.steps : 0;
    double wall = 0.0, collide = 0.0, highest = -INFINITY, stretch = 0.0;
    int64_t substeps = 0;
    int landed = -1, finite = 1, worst_intersections = 0, last_intersections = 0, last_collider = 0;
    int64_t failsafe = 0, halved = 0, iterations = 0;
    /* a library built before wc_step_stats.halved_steps returns a shorter
     * struct (the commit before, run side by side): its count reads 0 */
    int has_halved = wc_struct_size("wc_step_stats") >= (int64_t)sizeof(wc_step_stats);
    for (int f = 0; f < o.frames; ++f) {
        if (moves) {
            int32_t nv = s.collider_mesh.vertex_count;
            if (s.deforming) bend_tube(&s.collider_mesh, (double)(f + 1) / o.frames, bent);
            else memcpy(bent, s.collider_mesh.v, 3 * (size_t)nv * sizeof *bent);
            double shift = f + 1 > o.frames / 2 ? o.carry * (f + 1 - o.frames / 2) / 24.0 : 0.0;
            for (int32_t v = 0; v < nv; ++v) bent[3 * v] += shift;
            bench_check(wc_collider_set_vertices(s.world, s.collider, bent, s.collider_mesh.vertex_count),
                        s.world, "set vertices");
        }
        double t0 = bench_now();
        wc_status st = wc_world_advance(s.world, 1.0 / 24.0, steps);
        double frame_seconds = bench_now() - t0;
        wall += frame_seconds;
        if (st != WC_OK) {
            finite = 0;
            fprintf(stderr, "frame %d: %s\n", f, wc_world_last_error(s.world));
            break;
        }
        wc_step_stats stats = wc_world_get_stats(s.world);
        collide += stats.collide_seconds;
        failsafe += stats.failsafe_particles;
        int frame_halved = has_halved ? stats.halved_steps : 0;
        halved += frame_halved;
        iterations += stats.solver_iterations;
        substeps += wc_world_last_substeps(s.world);
        bench_check(wc_cloth_get_positions(s.world, s.cloth, xyz, n), s.world, "positions");
        bench_check(wc_cloth_get_contacts(s.world, s.cloth, contact, NULL, n), s.world, "contacts");
        if (out) fwrite(xyz, sizeof *xyz, 3 * (size_t)n, out);
        int any = 0;
        for (int32_t i = 0; i < n; ++i) any |= contact[i] == WC_CONTACT_COLLIDER, finite &= isfinite(xyz[3 * i + 2]);
        if (landed < 0 && any) landed = f;
        if (landed >= 0)
            for (int32_t i = 0; i < n; ++i) highest = fmax(highest, xyz[3 * (size_t)i + 2]);
        double longest = longest_link(xyz, pairs, rest, links);
        stretch = fmax(stretch, longest);
        if (o.check == 2 || (o.check == 1 && f == o.frames - 1)) {
            wc_intersection_counts k;
            bench_check(wc_world_count_intersections(s.world, &k), s.world, "intersections");
            last_intersections = k.cloth_cloth + k.cloth_collider;
            last_collider = k.cloth_collider;
            if (last_intersections > worst_intersections) worst_intersections = last_intersections;
        }
        if (o.trace)
            fprintf(stderr, "frame %d: %.1f ms (collide %.1f, integrate %.1f, %lld solver iterations, "
                            "last step on %d threads), "
                            "longest link %.3f, fail-safe %lld, halved steps %d, intersections %d "
                            "(with the collider %d)\n",
                    f, 1e3 * frame_seconds, 1e3 * stats.collide_seconds, 1e3 * stats.integrate_seconds,
                    (long long)stats.solver_iterations, (int)stats.threads,
                    longest, (long long)stats.failsafe_particles, frame_halved,
                    o.check == 2 ? last_intersections : -1, o.check == 2 ? last_collider : -1);
    }
    if (out) fclose(out);
    int frames_done = o.frames;
    printf("{\"scene\": \"%s\", \"library\": \"%s\", \"integrator\": \"%s\", \"wet\": %d, "
           "\"self\": %d, \"particles\": %d, \"collider_triangles\": %d, \"thickness\": %g, "
           "\"frames\": %d, \"threads\": %d, \"ms_per_frame\": %.3f, \"collide_ms_per_frame\": %.3f, "
           "\"substeps_per_frame\": %.2f, \"intersections_last\": %d, \"intersections_worst\": %d, "
           "\"landed_frame\": %d, \"start_height\": %.4f, \"highest_after_landing\": %.4f, "
           "\"longest_link\": %.4f, \"finite\": %d, \"cloth_collider_last\": %d, "
           "\"failsafe_last_substeps\": %lld, \"halved_steps\": %lld, "
           "\"solver_iterations_per_step\": %.2f}\n",
           o.scene, wc_version_string(), o.integrator, o.wet, o.self, (int)n,
           (int)s.collider_mesh.triangle_count, o.thickness, frames_done, o.threads,
           1e3 * wall / frames_done, 1e3 * collide / frames_done, (double)substeps / frames_done,
           last_intersections, worst_intersections, landed, s.start_height,
           landed >= 0 ? highest : s.start_height, stretch, finite, last_collider,
           (long long)failsafe, (long long)halved,
           substeps > 0 ? (double)iterations / (double)substeps : 0.0);
    wc_world_destroy(s.world);
    free(pairs), free(rest), free(xyz), free(bent), free(contact);
    free(s.collider_mesh.v), free(s.collider_mesh.t);
    return finite ? 0 : 3;
}
