/* Public entry points that add, read and change cloths. Each validates all of
 * its input before touching the world, so a failed call changes nothing. */
#include <math.h>
#include <string.h>

#include "alloc.h"
#include "buckling.h"
#include "cloth.h"
#include "material.h"
#include "status.h"
#include "world.h"

#define MAX_VERTICES (1 << 26)
/* A soft pin's largest stiffness, 1/s^2: an angular frequency of 1e4 rad/s,
 * far stiffer than any goal a scene needs, with k (x - T) still finite. */
#define MAX_PIN_STIFFNESS 1e8
#define MAX_FACES (1 << 27)

wc_mesh_cloth_def wc_mesh_cloth_def_default(void)
{
    wc_mesh_cloth_def d;
    memset(&d, 0, sizeof d);
    d.face_size = 3;
    d.material = wc_material_default();
    d.collide_with_cloths = 1;
    return d;
}

wc_grid_cloth_def wc_grid_cloth_def_default(void)
{
    wc_grid_cloth_def d;
    memset(&d, 0, sizeof d);
    d.count_u = d.count_v = 32;
    d.size_u = d.size_v = 1.0;
    d.axis_u[0] = 1.0;
    d.axis_v[1] = 1.0;
    d.material = wc_material_default();
    d.collide_with_cloths = 1;
    return d;
}

static wc_status append_cloth(wc_world *w, wc_cloth *c, int32_t *out_cloth)
{
    if (w->cloth_count == w->cloth_capacity) {
        int32_t capacity = w->cloth_capacity ? 2 * w->cloth_capacity : 4;
        wc_cloth **grown = wci_alloc_array((size_t)capacity, sizeof *grown);
        if (!grown) {
            wci_cloth_destroy(c);
            return wci_fail(&w->error, WC_ERROR_OUT_OF_MEMORY, "out of memory adding a cloth");
        }
        if (w->cloth_count) memcpy(grown, w->cloths, (size_t)w->cloth_count * sizeof *grown);
        wci_free(w->cloths);
        w->cloths = grown;
        w->cloth_capacity = capacity;
    }
    wci_cloth_set_integrator(c, w->def.integrator);
    w->cloths[w->cloth_count] = c;
    *out_cloth = w->cloth_count++;
    return WC_OK;
}

wc_status wc_world_add_mesh_cloth(wc_world *w, const wc_mesh_cloth_def *d, int32_t *out_cloth)
{
    if (!w) return WC_ERROR_INVALID_ARGUMENT;
    wc_message *msg = &w->error;
    if (!d || !out_cloth)
        return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT, "wc_world_add_mesh_cloth: %s is NULL",
                       d ? "out_cloth" : "def");
    if (d->vertex_count < 3 || d->vertex_count > MAX_VERTICES)
        return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                       "mesh_cloth_def.vertex_count must be in [3, %d] but is %d", MAX_VERTICES,
                       (int)d->vertex_count);
    if (d->face_count < 1 || d->face_count > MAX_FACES)
        return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                       "mesh_cloth_def.face_count must be in [1, %d] but is %d", MAX_FACES,
                       (int)d->face_count);
    if (d->face_size != 3 && d->face_size != 4)
        return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                       "mesh_cloth_def.face_size must be 3 or 4 but is %d", (int)d->face_size);
    if (!d->vertices || !d->faces)
        return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT, "mesh_cloth_def.%s is NULL",
                       d->vertices ? "faces" : "vertices");
    if (d->self_collision != 0 && d->self_collision != 1)
        return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                       "mesh_cloth_def.self_collision must be 0 or 1 but is %d",
                       (int)d->self_collision);
    if (d->collide_with_cloths != 0 && d->collide_with_cloths != 1)
        return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                       "mesh_cloth_def.collide_with_cloths must be 0 or 1 but is %d",
                       (int)d->collide_with_cloths);
    if (!(d->wetness >= 0.0 && d->wetness <= 1.0))
        return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                       "mesh_cloth_def.wetness must be in [0, 1] but is %g", d->wetness);
    wc_status s = wci_material_validate(&d->material, msg);
    if (s) return s;
    wc_cloth *c;
    s = wci_cloth_create(&c, d->vertices, d->vertex_count, d->faces, d->face_count, d->face_size,
                        &d->material, d->self_collision, d->wetness, msg);
    if (s) return s;
    c->collide_cloths = d->collide_with_cloths;
    return append_cloth(w, c, out_cloth);
}

static wc_status validate_grid(const wc_grid_cloth_def *d, wc_message *msg)
{
    if (d->count_u < 2 || d->count_u > 32768 || d->count_v < 2 || d->count_v > 32768)
        return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                       "grid_cloth_def.count_u and count_v must be in [2, 32768] but are %d and %d",
                       (int)d->count_u, (int)d->count_v);
    if ((int64_t)d->count_u * d->count_v > MAX_VERTICES)
        return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                       "grid_cloth_def: count_u * count_v must be at most %d but is %lld",
                       MAX_VERTICES, (long long)d->count_u * d->count_v);
    if (!(isfinite(d->size_u) && d->size_u > 0 && d->size_u <= 1e6 && isfinite(d->size_v) &&
          d->size_v > 0 && d->size_v <= 1e6))
        return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                       "grid_cloth_def.size_u and size_v must be in (0, 1e6] m but are %g and %g",
                       d->size_u, d->size_v);
    double lu = 0, lv = 0, dot = 0;
    for (int k = 0; k < 3; ++k) {
        if (!isfinite(d->center[k]))
            return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                           "grid_cloth_def.center[%d] must be finite but is %g", k, d->center[k]);
        lu += d->axis_u[k] * d->axis_u[k];
        lv += d->axis_v[k] * d->axis_v[k];
        dot += d->axis_u[k] * d->axis_v[k];
    }
    if (!(fabs(lu - 1.0) <= 1e-6 && fabs(lv - 1.0) <= 1e-6 && fabs(dot) <= 1e-6))
        return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                       "grid_cloth_def.axis_u and axis_v must be perpendicular unit vectors but "
                       "have lengths %g and %g and dot product %g",
                       sqrt(lu), sqrt(lv), dot);
    if (d->self_collision != 0 && d->self_collision != 1)
        return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                       "grid_cloth_def.self_collision must be 0 or 1 but is %d",
                       (int)d->self_collision);
    if (d->collide_with_cloths != 0 && d->collide_with_cloths != 1)
        return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                       "grid_cloth_def.collide_with_cloths must be 0 or 1 but is %d",
                       (int)d->collide_with_cloths);
    if (!(d->wetness >= 0.0 && d->wetness <= 1.0))
        return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                       "grid_cloth_def.wetness must be in [0, 1] but is %g", d->wetness);
    return wci_material_validate(&d->material, msg);
}

wc_status wc_world_add_grid_cloth(wc_world *w, const wc_grid_cloth_def *d, int32_t *out_cloth)
{
    if (!w) return WC_ERROR_INVALID_ARGUMENT;
    if (!d || !out_cloth)
        return wci_fail(&w->error, WC_ERROR_INVALID_ARGUMENT, "wc_world_add_grid_cloth: %s is NULL",
                       d ? "out_cloth" : "def");
    wc_status s = validate_grid(d, &w->error);
    if (s) return s;
    int32_t nu = d->count_u, nv = d->count_v, n = nu * nv, quads = (nu - 1) * (nv - 1);
    double *xyz = wci_alloc_array(3 * (size_t)n, sizeof *xyz);
    int32_t *faces = wci_alloc_array(4 * (size_t)quads, sizeof *faces);
    if (!xyz || !faces) {
        wci_free(xyz);
        wci_free(faces);
        return wci_fail(&w->error, WC_ERROR_OUT_OF_MEMORY, "out of memory building a %d x %d grid",
                       (int)nu, (int)nv);
    }
    for (int32_t j = 0; j < nv; ++j)
        for (int32_t i = 0; i < nu; ++i) {
            double u = ((double)i / (nu - 1) - 0.5) * d->size_u;
            double v = ((double)j / (nv - 1) - 0.5) * d->size_v;
            for (int k = 0; k < 3; ++k)
                xyz[3 * ((size_t)j * nu + i) + k] = d->center[k] + u * d->axis_u[k] + v * d->axis_v[k];
        }
    for (int32_t j = 0; j + 1 < nv; ++j)
        for (int32_t i = 0; i + 1 < nu; ++i) {
            int32_t *f = faces + 4 * ((size_t)j * (nu - 1) + i);
            f[0] = j * nu + i;
            f[1] = j * nu + i + 1;
            f[2] = (j + 1) * nu + i + 1;
            f[3] = (j + 1) * nu + i;
        }
    wc_cloth *c;
    s = wci_cloth_create(&c, xyz, n, faces, quads, 4, &d->material, d->self_collision, d->wetness,
                        &w->error);
    wci_free(xyz);
    wci_free(faces);
    if (s) return s;
    c->collide_cloths = d->collide_with_cloths;
    return append_cloth(w, c, out_cloth);
}

/* Finds a cloth and checks that an array argument has the expected count. */
static wc_cloth *cloth_with_count(const wc_world *w, int32_t cloth, const void *array,
                                  int32_t count, int32_t expected, const char *caller)
{
    if (!w) return NULL;
    wc_cloth *c = wci_world_find_cloth(w, cloth, caller);
    if (!c) return NULL;
    if (!array) {
        wci_fail(wci_world_message(w), WC_ERROR_INVALID_ARGUMENT, "%s: the array is NULL", caller);
        return NULL;
    }
    if (expected >= 0 && count != expected) {
        wci_fail(wci_world_message(w), WC_ERROR_INVALID_ARGUMENT,
                "%s: count must be %d for cloth %d but is %d", caller, (int)expected, (int)cloth,
                (int)count);
        return NULL;
    }
    return c;
}

static wc_status lookup_status(const wc_world *w, int32_t cloth)
{
    if (!w) return WC_ERROR_INVALID_ARGUMENT;
    return cloth >= 0 && cloth < w->cloth_count ? WC_ERROR_INVALID_ARGUMENT : WC_ERROR_NOT_FOUND;
}

int32_t wc_cloth_particle_count(const wc_world *w, int32_t cloth)
{
    return w && cloth >= 0 && cloth < w->cloth_count ? w->cloths[cloth]->particle_count : 0;
}

static const wc_link_set *link_set(const wc_cloth *c, wc_link_kind kind)
{
    if (kind == WC_LINK_STRETCH) return &c->topology.stretch;
    if (kind == WC_LINK_BEND) return &c->topology.bend;
    return NULL;
}

int32_t wc_cloth_link_count(const wc_world *w, int32_t cloth, wc_link_kind kind)
{
    if (!w || cloth < 0 || cloth >= w->cloth_count) return 0;
    const wc_link_set *s = link_set(w->cloths[cloth], kind);
    return s ? s->count : 0;
}

wc_status wc_cloth_get_links(const wc_world *w, int32_t cloth, wc_link_kind kind,
                             int32_t *out_pairs, double *out_rest_lengths, int32_t capacity)
{
    if (!w) return WC_ERROR_INVALID_ARGUMENT;
    wc_cloth *c = wci_world_find_cloth(w, cloth, "wc_cloth_get_links");
    if (!c) return WC_ERROR_NOT_FOUND;
    const wc_link_set *s = link_set(c, kind);
    if (!s)
        return wci_fail(wci_world_message(w), WC_ERROR_INVALID_ARGUMENT,
                       "wc_cloth_get_links: kind must be WC_LINK_STRETCH (0) or WC_LINK_BEND (1) "
                       "but is %d", (int)kind);
    if (capacity < s->count)
        return wci_fail(wci_world_message(w), WC_ERROR_INVALID_ARGUMENT,
                       "wc_cloth_get_links: capacity must be at least %d but is %d", (int)s->count,
                       (int)capacity);
    for (int32_t e = 0; e < s->count; ++e) {
        if (out_pairs) out_pairs[2 * e] = s->a[e], out_pairs[2 * e + 1] = s->b[e];
        if (out_rest_lengths) out_rest_lengths[e] = s->rest[e];
    }
    return WC_OK;
}

int32_t wc_cloth_triangle_count(const wc_world *w, int32_t cloth)
{
    return w && cloth >= 0 && cloth < w->cloth_count ? w->cloths[cloth]->topology.triangle_count : 0;
}

wc_status wc_cloth_get_triangles(const wc_world *w, int32_t cloth, int32_t *out, int32_t capacity)
{
    wc_cloth *c = cloth_with_count(w, cloth, out, capacity, -1, "wc_cloth_get_triangles");
    if (!c) return lookup_status(w, cloth);
    if (capacity < c->topology.triangle_count)
        return wci_fail(wci_world_message(w), WC_ERROR_INVALID_ARGUMENT,
                       "wc_cloth_get_triangles: capacity must be at least %d but is %d",
                       (int)c->topology.triangle_count, (int)capacity);
    memcpy(out, c->topology.triangles, 3 * (size_t)c->topology.triangle_count * sizeof *out);
    return WC_OK;
}

wc_status wc_cloth_get_positions(const wc_world *w, int32_t cloth, double *out, int32_t count)
{
    wc_cloth *c = cloth_with_count(w, cloth, out, count, wc_cloth_particle_count(w, cloth),
                                   "wc_cloth_get_positions");
    if (!c) return lookup_status(w, cloth);
    for (int32_t i = 0; i < count; ++i) {
        out[3 * (size_t)i] = c->x[i];
        out[3 * (size_t)i + 1] = c->y[i];
        out[3 * (size_t)i + 2] = c->z[i];
    }
    return WC_OK;
}

wc_status wc_cloth_get_positions_f32(const wc_world *w, int32_t cloth, float *out, int32_t count)
{
    wc_cloth *c = cloth_with_count(w, cloth, out, count, wc_cloth_particle_count(w, cloth),
                                   "wc_cloth_get_positions_f32");
    if (!c) return lookup_status(w, cloth);
    for (int32_t i = 0; i < count; ++i) {
        out[3 * (size_t)i] = (float)c->x[i];
        out[3 * (size_t)i + 1] = (float)c->y[i];
        out[3 * (size_t)i + 2] = (float)c->z[i];
    }
    return WC_OK;
}

static wc_status check_finite_xyz(const wc_world *w, const double *xyz, int32_t count,
                                  const char *caller)
{
    long bad = wci_first_non_finite(xyz, 3L * count);
    if (bad < 0) return WC_OK;
    return wci_fail(wci_world_message(w), WC_ERROR_INVALID_ARGUMENT,
                   "%s: value %ld (%c of entry %ld) must be finite but is %g", caller, bad,
                   "xyz"[bad % 3], bad / 3, xyz[bad]);
}

wc_status wc_cloth_set_positions(wc_world *w, int32_t cloth, const double *xyz, int32_t count)
{
    wc_cloth *c = cloth_with_count(w, cloth, xyz, count, wc_cloth_particle_count(w, cloth),
                                   "wc_cloth_set_positions");
    if (!c) return lookup_status(w, cloth);
    wc_status s = check_finite_xyz(w, xyz, count, "wc_cloth_set_positions");
    if (s) return s;
    for (int32_t i = 0; i < count; ++i) {
        c->x[i] = xyz[3 * (size_t)i];
        c->y[i] = xyz[3 * (size_t)i + 1];
        c->z[i] = xyz[3 * (size_t)i + 2];
        c->px[i] = c->py[i] = c->pz[i] = 0.0; /* velocity zero, see cloth.h */
    }
    c->has_history = 0;
    for (int32_t p = 0; p < c->pins.count; ++p) {
        int32_t i = c->pins.particle[p];
        double *from = c->pins.from + 3 * (size_t)p, *to = c->pins.to + 3 * (size_t)p;
        from[0] = to[0] = c->x[i];
        from[1] = to[1] = c->y[i];
        from[2] = to[2] = c->z[i];
    }
    return WC_OK;
}

wc_status wc_cloth_get_velocities(const wc_world *w, int32_t cloth, double *out, int32_t count)
{
    wc_cloth *c = cloth_with_count(w, cloth, out, count, wc_cloth_particle_count(w, cloth),
                                   "wc_cloth_get_velocities");
    if (!c) return lookup_status(w, cloth);
    for (int32_t i = 0; i < count; ++i) wci_cloth_velocity(c, i, out + 3 * (size_t)i);
    return WC_OK;
}

wc_status wc_cloth_set_velocities(wc_world *w, int32_t cloth, const double *xyz, int32_t count)
{
    wc_cloth *c = cloth_with_count(w, cloth, xyz, count, wc_cloth_particle_count(w, cloth),
                                   "wc_cloth_set_velocities");
    if (!c) return lookup_status(w, cloth);
    wc_status s = check_finite_xyz(w, xyz, count, "wc_cloth_set_velocities");
    if (s) return s;
    for (int32_t i = 0; i < count; ++i) {
        c->px[i] = xyz[3 * (size_t)i];
        c->py[i] = xyz[3 * (size_t)i + 1];
        c->pz[i] = xyz[3 * (size_t)i + 2];
    }
    c->has_history = 0;
    return WC_OK;
}

wc_status wc_cloth_get_view(const wc_world *w, int32_t cloth, wc_cloth_view *out)
{
    wc_cloth *c = cloth_with_count(w, cloth, out, 0, -1, "wc_cloth_get_view");
    if (!c) return lookup_status(w, cloth);
    out->particle_count = c->particle_count;
    out->x = c->x;
    out->y = c->y;
    out->z = c->z;
    out->mass = c->mass;
    out->contact = c->contact;
    out->normal_x = c->normal_x;
    out->normal_y = c->normal_y;
    out->normal_z = c->normal_z;
    out->wetness = c->wetness;
    out->stuck = c->stuck;
    return WC_OK;
}

/* ------------------------------------------------------------------------ */
/* Pins                                                                      */
/* ------------------------------------------------------------------------ */

/* Checks a pin list completely before anything changes: range, pinned
 * already (hard or soft), repeated in the list. Marks each listed particle
 * in pin_slot for the repeat check; undo_pin_marks takes the marks away. */
static wc_status validate_pins(const wc_world *w, wc_cloth *c, const int32_t *idx, int32_t count,
                               const char *caller)
{
    wc_message *msg = wci_world_message(w);
    if (count < 0 || (int64_t)count + c->pins.count > c->particle_count)
        return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                       "%s: count must be in [0, %d] (unpinned particles) but is %d", caller,
                       (int)(c->particle_count - c->pins.count), (int)count);
    for (int32_t k = 0; k < count; ++k) {
        int32_t i = idx[k];
        if (i < 0 || i >= c->particle_count)
            return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                           "%s: indices[%d] is %d, but the cloth has %d particles", caller,
                           (int)k, (int)i, (int)c->particle_count);
        if (c->soft_pin_slot && c->soft_pin_slot[i] >= 0)
            return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                           "%s: indices[%d] = %d is already pinned (soft pin %d)", caller, (int)k,
                           (int)i, (int)c->soft_pin_slot[i]);
        if (c->pin_slot[i] >= 0)
            return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT, "%s: indices[%d] = %d is %s", caller,
                           (int)k, (int)i,
                           c->pin_slot[i] < c->pins.count ? "already pinned"
                                                          : "repeated in the list");
        c->pin_slot[i] = c->pins.count + k; /* marks it for the duplicate check */
    }
    return WC_OK;
}

static void undo_pin_marks(wc_cloth *c, const int32_t *idx, int32_t count)
{
    for (int32_t k = 0; k < count; ++k)
        if (idx[k] >= 0 && idx[k] < c->particle_count && c->pin_slot[idx[k]] >= c->pins.count)
            c->pin_slot[idx[k]] = -1;
}

/* Each soft pin's stiffness, 1/s^2, finite, in (0, 1e8]. */
static wc_status validate_stiffness(const wc_world *w, const int32_t *idx, const double *stiffness,
                                    int32_t count)
{
    for (int32_t k = 0; k < count; ++k)
        if (!(stiffness[k] > 0.0 && stiffness[k] <= MAX_PIN_STIFFNESS))
            return wci_fail(wci_world_message(w), WC_ERROR_INVALID_ARGUMENT,
                           "wc_cloth_pin_soft: stiffness[%d] (for particle %d) must be in "
                           "(0, %g] 1/s^2 but is %g",
                           (int)k, (int)idx[k], MAX_PIN_STIFFNESS, stiffness[k]);
    return WC_OK;
}

/* The pin arrays grown by count pins: NULL stiffness adds hard pins, else
 * soft ones. Allocates everything first; on failure the cloth is as it was. */
typedef struct grown_pins {
    int32_t *particle, *soft_pin_slot;
    double *from, *to, *stiffness;
} grown_pins;

static void free_grown(grown_pins *g)
{
    wci_free(g->particle);
    wci_free(g->from);
    wci_free(g->to);
    wci_free(g->stiffness);
    wci_free(g->soft_pin_slot);
}

static int allocate_grown(const wc_cloth *c, int32_t total, int soft, grown_pins *g)
{
    memset(g, 0, sizeof *g);
    g->particle = wci_alloc_array((size_t)total, sizeof *g->particle);
    g->from = wci_alloc_array(3 * (size_t)total, sizeof *g->from);
    g->to = wci_alloc_array(3 * (size_t)total, sizeof *g->to);
    int ok = g->particle && g->from && g->to;
    /* a cloth that ever had a soft pin keeps a stiffness per pin */
    if (soft || c->pins.stiffness) {
        g->stiffness = wci_alloc_array((size_t)total, sizeof *g->stiffness);
        ok &= g->stiffness != NULL;
    }
    if (soft && !c->soft_pin_slot) {
        g->soft_pin_slot = wci_alloc_array((size_t)c->particle_count, sizeof *g->soft_pin_slot);
        ok &= g->soft_pin_slot != NULL;
    }
    if (!ok) free_grown(g);
    return ok;
}

/* Moves the grown arrays in, the new pins after the old ones, each pin's
 * target where its particle is now. */
static void install_pins(wc_cloth *c, grown_pins *g, const int32_t *idx, const double *stiffness,
                         int32_t count)
{
    int32_t old = c->pins.count, total = old + count;
    if (old) {
        memcpy(g->particle, c->pins.particle, (size_t)old * sizeof *g->particle);
        memcpy(g->from, c->pins.from, 3 * (size_t)old * sizeof *g->from);
        memcpy(g->to, c->pins.to, 3 * (size_t)old * sizeof *g->to);
        if (c->pins.stiffness) memcpy(g->stiffness, c->pins.stiffness, (size_t)old * sizeof(double));
    }
    if (g->stiffness && !c->pins.stiffness)
        for (int32_t p = 0; p < old; ++p) g->stiffness[p] = 0.0; /* the hard pins so far */
    if (g->soft_pin_slot) {
        for (int32_t i = 0; i < c->particle_count; ++i) g->soft_pin_slot[i] = -1;
        c->soft_pin_slot = g->soft_pin_slot;
    }
    for (int32_t k = 0; k < count; ++k) {
        int32_t p = old + k, i = idx[k];
        g->particle[p] = i;
        g->from[3 * p] = g->to[3 * p] = c->x[i];
        g->from[3 * p + 1] = g->to[3 * p + 1] = c->y[i];
        g->from[3 * p + 2] = g->to[3 * p + 2] = c->z[i];
        if (g->stiffness) g->stiffness[p] = stiffness ? stiffness[k] : 0.0;
        if (stiffness)
            c->soft_pin_slot[i] = p, c->pin_slot[i] = -1;
        else
            c->pin_slot[i] = p;
    }
    wci_free(c->pins.particle);
    wci_free(c->pins.from);
    wci_free(c->pins.to);
    if (g->stiffness) wci_free(c->pins.stiffness);
    c->pins.particle = g->particle;
    c->pins.from = g->from;
    c->pins.to = g->to;
    if (g->stiffness) c->pins.stiffness = g->stiffness;
    c->pins.count = total;
    if (stiffness) c->pins.soft_count += count;
}

/* Adds hard pins or (soft = 1) soft pins with the given stiffness. */
static wc_status add_pins(wc_world *w, int32_t cloth, const int32_t *idx, int soft,
                          const double *stiffness, int32_t count, const char *caller)
{
    wc_cloth *c = cloth_with_count(w, cloth, idx, count, -1, caller);
    if (!c) return lookup_status(w, cloth);
    if (soft && !stiffness)
        return wci_fail(&w->error, WC_ERROR_INVALID_ARGUMENT, "%s: the stiffness array is NULL",
                       caller);
    wc_status s = validate_pins(w, c, idx, count, caller);
    if (!s && soft) s = validate_stiffness(w, idx, stiffness, count);
    grown_pins g;
    if (!s && !allocate_grown(c, c->pins.count + count, soft, &g))
        s = wci_fail(&w->error, WC_ERROR_OUT_OF_MEMORY, "out of memory pinning %d particles",
                    (int)count);
    undo_pin_marks(c, idx, count);
    if (s) return s;
    install_pins(c, &g, idx, soft ? stiffness : NULL, count);
    /* the springs are explicit forces for Verlet and XPBD */
    if (soft) wci_cloth_update_stable_dt(c);
    return WC_OK;
}

wc_status wc_cloth_pin(wc_world *w, int32_t cloth, const int32_t *idx, int32_t count)
{
    return add_pins(w, cloth, idx, 0, NULL, count, "wc_cloth_pin");
}

wc_status wc_cloth_pin_soft(wc_world *w, int32_t cloth, const int32_t *idx, const double *stiffness,
                            int32_t count)
{
    return add_pins(w, cloth, idx, 1, stiffness, count, "wc_cloth_pin_soft");
}

wc_status wc_cloth_unpin_all(wc_world *w, int32_t cloth)
{
    if (!w) return WC_ERROR_INVALID_ARGUMENT;
    wc_cloth *c = wci_world_find_cloth(w, cloth, "wc_cloth_unpin_all");
    if (!c) return WC_ERROR_NOT_FOUND;
    for (int32_t p = 0; p < c->pins.count; ++p) {
        int32_t i = c->pins.particle[p];
        c->pin_slot[i] = -1;
        if (c->soft_pin_slot) c->soft_pin_slot[i] = -1;
    }
    int had_soft = c->pins.soft_count > 0;
    c->pins.count = 0;
    c->pins.soft_count = 0;
    if (had_soft) wci_cloth_update_stable_dt(c);
    return WC_OK;
}

int32_t wc_cloth_pin_count(const wc_world *w, int32_t cloth)
{
    return w && cloth >= 0 && cloth < w->cloth_count ? w->cloths[cloth]->pins.count : 0;
}

wc_status wc_cloth_set_pin_targets(wc_world *w, int32_t cloth, const double *xyz, int32_t count)
{
    wc_cloth *c = cloth_with_count(w, cloth, xyz, count, wc_cloth_pin_count(w, cloth),
                                   "wc_cloth_set_pin_targets");
    if (!c) return lookup_status(w, cloth);
    wc_status s = check_finite_xyz(w, xyz, count, "wc_cloth_set_pin_targets");
    if (s) return s;
    if (count) memcpy(c->pins.to, xyz, 3 * (size_t)count * sizeof *xyz); /* no pins: to is NULL */
    return WC_OK;
}

double wc_cloth_stable_dt(const wc_world *w, int32_t cloth)
{
    return w && cloth >= 0 && cloth < w->cloth_count ? w->cloths[cloth]->stable_dt : 0.0;
}

wc_status wc_cloth_get_energy(const wc_world *w, int32_t cloth, wc_energy *out)
{
    wc_cloth *c = cloth_with_count(w, cloth, out, 0, -1, "wc_cloth_get_energy");
    if (!c) return lookup_status(w, cloth);
    const double *g = w->def.gravity;
    const wc_topology *t = &c->topology;
    wc_energy e = {0.0, 0.0, 0.0, 0.0};
    for (int32_t i = 0; i < c->particle_count; ++i) {
        double v[3];
        wci_cloth_velocity(c, i, v);
        e.kinetic += 0.5 * c->mass[i] * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        e.gravity -= c->mass[i] * (g[0] * c->x[i] + g[1] * c->y[i] + g[2] * c->z[i]);
    }
    for (int32_t k = 0; k < t->stretch.count; ++k) {
        int32_t a = t->stretch.a[k], b = t->stretch.b[k];
        double d = sqrt((c->x[a] - c->x[b]) * (c->x[a] - c->x[b]) +
                        (c->y[a] - c->y[b]) * (c->y[a] - c->y[b]) +
                        (c->z[a] - c->z[b]) * (c->z[a] - c->z[b]));
        if (d > t->stretch.rest[k])
            e.stretch += 0.5 * c->stretch_k[k] * (d - t->stretch.rest[k]) * (d - t->stretch.rest[k]);
    }
    for (int32_t k = 0; k < t->bend.count; ++k) {
        int32_t a = t->bend.a[k], b = t->bend.b[k];
        double d = sqrt((c->x[a] - c->x[b]) * (c->x[a] - c->x[b]) +
                        (c->y[a] - c->y[b]) * (c->y[a] - c->y[b]) +
                        (c->z[a] - c->z[b]) * (c->z[a] - c->z[b]));
        e.bend += wci_buckling_energy_ramped(d, t->bend.rest[k], c->bend_r[k]);
    }
    *out = e;
    return WC_OK;
}

wc_status wc_cloth_get_contacts(const wc_world *w, int32_t cloth, uint8_t *out_kind,
                                double *out_normals, int32_t count)
{
    const void *any = out_kind ? (const void *)out_kind : (const void *)out_normals;
    wc_cloth *c = cloth_with_count(w, cloth, any ? any : (const void *)w, count,
                                   wc_cloth_particle_count(w, cloth), "wc_cloth_get_contacts");
    if (!c) return lookup_status(w, cloth);
    for (int32_t i = 0; i < count; ++i) {
        if (out_kind) out_kind[i] = c->contact[i];
        if (out_normals) {
            out_normals[3 * (size_t)i] = c->normal_x[i];
            out_normals[3 * (size_t)i + 1] = c->normal_y[i];
            out_normals[3 * (size_t)i + 2] = c->normal_z[i];
        }
    }
    return WC_OK;
}

/* ------------------------------------------------------------------------ */
/* Wetness                                                                   */
/* ------------------------------------------------------------------------ */

wc_status wc_cloth_set_wetness_uniform(wc_world *w, int32_t cloth, double wetness)
{
    if (!w) return WC_ERROR_INVALID_ARGUMENT;
    wc_cloth *c = wci_world_find_cloth(w, cloth, "wc_cloth_set_wetness_uniform");
    if (!c) return WC_ERROR_NOT_FOUND;
    if (!(wetness >= 0.0 && wetness <= 1.0))
        return wci_fail(&w->error, WC_ERROR_INVALID_ARGUMENT,
                       "wc_cloth_set_wetness_uniform: wetness must be in [0, 1] but is %g", wetness);
    for (int32_t i = 0; i < c->particle_count; ++i) c->wetness[i] = wetness;
    wci_cloth_apply_material(c);
    return WC_OK;
}

wc_status wc_cloth_set_wetness(wc_world *w, int32_t cloth, const double *wetness, int32_t count)
{
    wc_cloth *c = cloth_with_count(w, cloth, wetness, count, wc_cloth_particle_count(w, cloth),
                                   "wc_cloth_set_wetness");
    if (!c) return lookup_status(w, cloth);
    for (int32_t i = 0; i < count; ++i)
        if (!(wetness[i] >= 0.0 && wetness[i] <= 1.0))
            return wci_fail(&w->error, WC_ERROR_INVALID_ARGUMENT,
                           "wc_cloth_set_wetness: wetness[%d] must be in [0, 1] but is %g", (int)i,
                           wetness[i]);
    memcpy(c->wetness, wetness, (size_t)count * sizeof *wetness);
    wci_cloth_apply_material(c);
    return WC_OK;
}

wc_status wc_cloth_get_wetness(const wc_world *w, int32_t cloth, double *out, int32_t count)
{
    wc_cloth *c = cloth_with_count(w, cloth, out, count, wc_cloth_particle_count(w, cloth),
                                   "wc_cloth_get_wetness");
    if (!c) return lookup_status(w, cloth);
    memcpy(out, c->wetness, (size_t)count * sizeof *out);
    return WC_OK;
}

wc_status wc_cloth_get_stuck(const wc_world *w, int32_t cloth, uint8_t *out, int32_t count)
{
    wc_cloth *c = cloth_with_count(w, cloth, out, count, wc_cloth_particle_count(w, cloth),
                                   "wc_cloth_get_stuck");
    if (!c) return lookup_status(w, cloth);
    memcpy(out, c->stuck, (size_t)count);
    return WC_OK;
}
