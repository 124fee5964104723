#include "cloth.h"

#include <math.h>
#include <string.h>

#include "alloc.h"
#include "buckling.h"
#include "collider_contacts.h"
#include "implicit.h"
#include "particles.h"
#include "selfcollide.h"
#include "status.h"
#include "xpbd.h"

void wci_cloth_destroy(wc_cloth *c)
{
    if (!c) return;
    /* in a world, the per-particle arrays are the world's (particles.h) */
    if (!c->in_world) wci_particles_free_own(c);
    double *arrays[] = {c->vx, c->vy, c->vz, c->stretch_k, c->stretch_c, c->bend_r,
                        c->bend_inv_rest, c->bend_coef, c->link_fx, c->link_fy, c->link_fz,
                        c->pins.from, c->pins.to, c->wetness_next, c->pins.stiffness,
                        c->air_velocity, c->external_force};
    for (size_t i = 0; i < sizeof arrays / sizeof arrays[0]; ++i) wci_free(arrays[i]);
    wci_free(c->link_start);
    wci_free(c->link_list);
    wci_free(c->soft_pin_slot);
    wci_free(c->pins.particle);
    wci_free(c->self_touched);
    wci_free(c->adhesive_pairs);
    wci_free(c->adhesive_data);
    wci_self_state_destroy(c->self);
    wci_collider_contacts_destroy(c->collider_contacts);
    wci_xpbd_state_destroy(c->xpbd);
    wci_implicit_state_destroy(c->implicit);
    wci_topology_destroy(&c->topology);
    wci_free(c);
}

static int alloc_doubles(double **p, size_t count)
{
    *p = wci_alloc_array(count, sizeof **p);
    return *p != NULL;
}

static int alloc_particle_arrays(wc_cloth *c)
{
    size_t n = (size_t)c->particle_count;
    size_t links = (size_t)c->topology.stretch.count + (size_t)c->topology.bend.count;
    int needs_velocity = c->material.stretch_damping > 0.0 || c->material.air_drag > 0.0;
    int ok = alloc_doubles(&c->x, n) & alloc_doubles(&c->y, n) & alloc_doubles(&c->z, n) &
             alloc_doubles(&c->px, n) & alloc_doubles(&c->py, n) & alloc_doubles(&c->pz, n) &
             alloc_doubles(&c->nx, n) & alloc_doubles(&c->ny, n) & alloc_doubles(&c->nz, n) &
             alloc_doubles(&c->fx, n) & alloc_doubles(&c->fy, n) & alloc_doubles(&c->fz, n) &
             alloc_doubles(&c->mass, n) & alloc_doubles(&c->inv_mass, n) &
             alloc_doubles(&c->stretch_k, (size_t)c->topology.stretch.count) &
             alloc_doubles(&c->bend_r, (size_t)c->topology.bend.count) &
             alloc_doubles(&c->bend_inv_rest, (size_t)c->topology.bend.count) &
             alloc_doubles(&c->bend_coef, (size_t)c->topology.bend.count) &
             alloc_doubles(&c->link_fx, links) & alloc_doubles(&c->link_fy, links) &
             alloc_doubles(&c->link_fz, links);
    if (needs_velocity)
        ok &= alloc_doubles(&c->vx, n) & alloc_doubles(&c->vy, n) & alloc_doubles(&c->vz, n);
    if (c->material.stretch_damping > 0.0)
        ok &= alloc_doubles(&c->stretch_c, (size_t)c->topology.stretch.count);
    c->link_start = wci_alloc_array(n + 1, sizeof *c->link_start);
    c->link_list = wci_alloc_array(2 * links, sizeof *c->link_list);
    c->pin_slot = wci_alloc_array(n, sizeof *c->pin_slot);
    ok &= alloc_doubles(&c->normal_x, n) & alloc_doubles(&c->normal_y, n) &
          alloc_doubles(&c->normal_z, n) & alloc_doubles(&c->qx, n) & alloc_doubles(&c->qy, n) &
          alloc_doubles(&c->qz, n);
    c->contact = wci_alloc_array(n, sizeof *c->contact);
    c->contact_prev = wci_alloc_array(n, sizeof *c->contact_prev);
    c->stuck = wci_alloc_array(n, sizeof *c->stuck);
    c->history_override = wci_alloc_array(n, sizeof *c->history_override);
    ok &= alloc_doubles(&c->wetness, n) & alloc_doubles(&c->grip, n);
    if (c->material.wicking > 0.0) ok &= alloc_doubles(&c->wetness_next, n);
    return ok && c->link_start && c->link_list && c->pin_slot && c->contact && c->contact_prev &&
           c->stuck && c->history_override;
}

/* Per-particle link lists in ascending link order: the order in which a
 * particle sums its link forces, the same for any thread count. */
static void build_link_lists(wc_cloth *c)
{
    const wc_link_set *sets[2] = {&c->topology.stretch, &c->topology.bend};
    int32_t n = c->particle_count, *start = c->link_start, *list = c->link_list;
    memset(start, 0, ((size_t)n + 1) * sizeof *start);
    for (int s = 0; s < 2; ++s)
        for (int32_t e = 0; e < sets[s]->count; ++e) {
            start[sets[s]->a[e] + 1]++;
            start[sets[s]->b[e] + 1]++;
        }
    for (int32_t i = 0; i < n; ++i) start[i + 1] += start[i];
    /* pin_slot is free scratch here: it is reset to -1 right after. */
    int32_t *fill = c->pin_slot;
    memset(fill, 0, (size_t)n * sizeof *fill);
    int32_t offset = 0;
    for (int s = 0; s < 2; ++s) {
        for (int32_t e = 0; e < sets[s]->count; ++e) {
            int32_t a = sets[s]->a[e], b = sets[s]->b[e];
            list[start[a] + fill[a]++] = offset + e;
            list[start[b] + fill[b]++] = ~(offset + e);
        }
        offset += sets[s]->count;
    }
    for (int32_t i = 0; i < n; ++i) c->pin_slot[i] = -1;
}

/* The large-step integrators' automatic step is also capped at this, s.
 * Their stability bounds allow 0.014 s (XPBD) and 0.17 s (implicit) on the
 * thesis' 20 x 20 cotton, but collisions and the explicit wet adhesion are
 * resolved once per step: measured on the thesis wrap (tests/
 * test_integrators.c), at 5 steps per 1/24 s frame the wet cloth passes
 * through the solid with both integrators (1e5 - 1e6 intersecting pairs
 * over 48 frames); at 10 (1/240 s) the implicit integrator wraps it with no
 * intersection. */
#define LARGE_STEP_MAX (1.0 / 240.0)

/* What a stable step bound counts as explicit. */
typedef enum stable_mode {
    /* Verlet: every link, damping, drag and the soft pins' springs. */
    STABLE_ALL,
    /* XPBD: stretch links (and their damping) are constraints; the bend
     * links' ramped buckling slope, drag and the soft pins' springs remain
     * explicit. */
    STABLE_BEND_AND_DRAG,
    /* Implicit: stretch, bend axial stiffness, damping, drag and the soft
     * pins' springs are in the linear system; only the bend links'
     * transverse term, dropped from the
     * Jacobian (f/d across the link, see implicit.c), acts explicitly. Its
     * stiffness f/d is bounded by 4 pi^2 R / l^2 / (l / 2) while a bend link
     * keeps at least half its rest length, which is the bound used: a link
     * folded further is a crease, handled by collisions. */
    STABLE_TRANSVERSE_BEND
} stable_mode;

/* Gershgorin bound on the highest angular frequency of the linearised
 * system: omega^2 <= max_i sum_links k (1/m_i + 1/sqrt(m_i m_j)), with k the
 * stretch K or the bound on the ramped buckling force's slope, 12007 R / l^3,
 * plus, for a soft-pinned particle that the integrator treats explicitly
 * (Verlet, XPBD), its goal spring's k / m_i, which is the pin's stiffness
 * itself (applied.h: k = m_i stiffness). Damping and drag
 * shorten the explicit stable step further: for a damped oscillator with
 * ratio z the limit becomes 2 (sqrt(1 + z^2) - z) / omega, and drag alone
 * needs dt < 2 m / c. */
static double estimate_stable_dt(const wc_cloth *c, stable_mode mode)
{
    int32_t n = c->particle_count;
    const wc_link_set *st = &c->topology.stretch, *bd = &c->topology.bend;
    const double bend_bound = mode == STABLE_TRANSVERSE_BEND ? 8.0 * 9.8696044010893586
                                                             : WC_BUCKLING_STIFFNESS_BOUND_RAMPED;
    const int32_t *soft = mode != STABLE_TRANSVERSE_BEND && c->pins.soft_count ? c->soft_pin_slot
                                                                                : NULL;
    double omega2 = 0.0;
    for (int32_t i = 0; i < n; ++i) {
        double row = soft && soft[i] >= 0 ? c->pins.stiffness[soft[i]] : 0.0;
        for (int32_t k = c->link_start[i]; k < c->link_start[i + 1]; ++k) {
            int32_t e = c->link_list[k] >= 0 ? c->link_list[k] : ~c->link_list[k];
            double stiffness;
            int32_t a, b;
            if (e < st->count) {
                if (mode != STABLE_ALL) continue;
                stiffness = c->stretch_k[e];
                a = st->a[e], b = st->b[e];
            } else {
                int32_t f = e - st->count;
                double l = bd->rest[f];
                stiffness = bend_bound * c->bend_r[f] / (l * l * l);
                a = bd->a[f], b = bd->b[f];
            }
            int32_t j = a == i ? b : a;
            row += stiffness * (c->inv_mass[i] + sqrt(c->inv_mass[i] * c->inv_mass[j]));
        }
        if (row > omega2) omega2 = row;
    }
    double z = mode == STABLE_ALL ? c->material.stretch_damping : 0.0;
    double dt = omega2 > 0.0 ? 2.0 * (sqrt(1.0 + z * z) - z) / sqrt(omega2) : INFINITY;
    if (mode != STABLE_TRANSVERSE_BEND && c->material.air_drag > 0.0) {
        double drag_dt = 2.0 * c->material.density / c->material.air_drag;
        if (drag_dt < dt) dt = drag_dt;
    }
    if (mode != STABLE_ALL && dt > LARGE_STEP_MAX) dt = LARGE_STEP_MAX;
    return dt;
}

static stable_mode mode_of(wc_integrator integrator)
{
    return integrator == WC_INTEGRATOR_XPBD       ? STABLE_BEND_AND_DRAG
           : integrator == WC_INTEGRATOR_IMPLICIT ? STABLE_TRANSVERSE_BEND
                                                  : STABLE_ALL;
}


void wci_cloth_update_stable_dt(wc_cloth *c)
{
    c->stable_dt = estimate_stable_dt(c, mode_of(c->integrator));
}

void wci_cloth_set_integrator(wc_cloth *c, wc_integrator integrator)
{
    if (integrator == c->integrator) return; /* a new cloth starts as Verlet */
    c->integrator = integrator;
    c->stable_dt = estimate_stable_dt(c, mode_of(integrator));
}

/* Whether the wet forces can act: some particle wet, the material adhesive. */
static int any_wet_force(const wc_cloth *c)
{
    if (!(c->material.adhesion > 0.0)) return 0;
    for (int32_t i = 0; i < c->particle_count; ++i)
        if (c->wetness[i] > 0.0) return 1;
    return 0;
}

/* Turns area shares into masses and link constants (see wc_material),
 * wetness included: mass * (1 + gain w), stiffness * (1 - softening w),
 * w a link's mean wetness. For w = 0 both factors are exactly 1, so a dry
 * cloth gets bitwise the plain model's constants. */
void wci_cloth_apply_material(wc_cloth *c)
{
    const wc_topology *t = &c->topology;
    const wc_material *m = &c->material;
    const double *w = c->wetness;
    for (int32_t i = 0; i < c->particle_count; ++i) {
        c->mass[i] = m->density * t->area[i] * (1.0 + m->wet_mass_gain * w[i]);
        c->inv_mass[i] = 1.0 / c->mass[i];
        c->grip[i] = m->wet_grip * t->area[i] * w[i] * c->inv_mass[i];
    }
    for (int32_t e = 0; e < t->stretch.count; ++e) {
        int32_t a = t->stretch.a[e], b = t->stretch.b[e];
        double l = t->stretch.rest[e], soft = 1.0 - m->wet_softening * 0.5 * (w[a] + w[b]);
        c->stretch_k[e] = m->stretch_stiffness * t->stretch.share[e] / (l * l) * soft;
        if (c->stretch_c) {
            double ma = c->mass[a], mb = c->mass[b];
            c->stretch_c[e] = 2.0 * m->stretch_damping * sqrt(c->stretch_k[e] * ma * mb / (ma + mb));
        }
    }
    for (int32_t e = 0; e < t->bend.count; ++e) {
        double soft = 1.0 - m->wet_softening * 0.5 * (w[t->bend.a[e]] + w[t->bend.b[e]]);
        c->bend_r[e] = m->bend_stiffness * t->bend.share[e] / t->bend.rest[e] * soft;
        double inv_l = 1.0 / t->bend.rest[e];
        c->bend_inv_rest[e] = inv_l;
        c->bend_coef[e] = c->bend_r[e] * inv_l * inv_l;
    }
    c->stable_dt = estimate_stable_dt(c, mode_of(c->integrator));
    c->wet_forces = any_wet_force(c);
    /* pairs found while wet must not act when the cloth is wet again */
    if (!c->wet_forces) c->adhesive_count = 0;
}

/* Every link must join two distinct points of the rest shape. */
static wc_status check_links(const wc_cloth *c, wc_message *msg)
{
    const wc_link_set *s = &c->topology.stretch;
    for (int32_t e = 0; e < s->count; ++e)
        if (!(s->rest[e] > 0.0))
            return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                           "cloth vertices %d and %d are linked but lie at the same point",
                           (int)s->a[e], (int)s->b[e]);
    return WC_OK;
}

wc_status wci_cloth_create(wc_cloth **out, const double *xyz, int32_t n, const int32_t *faces,
                          int32_t face_count, int32_t face_size, const wc_material *material,
                          int self_collision, double wetness, wc_message *msg)
{
    *out = NULL;
    wc_cloth *c = wci_alloc_array(1, sizeof *c);
    if (!c) return wci_fail(msg, WC_ERROR_OUT_OF_MEMORY, "out of memory creating a cloth");
    c->particle_count = n;
    c->material = *material;
    wc_status s = wci_topology_create(&c->topology, xyz, n, faces, face_count, face_size, msg);
    if (s) {
        wci_free(c);
        return s;
    }
    if (!alloc_particle_arrays(c)) {
        wci_cloth_destroy(c);
        return wci_fail(msg, WC_ERROR_OUT_OF_MEMORY, "out of memory creating a cloth of %d vertices",
                       (int)n);
    }
    for (int32_t i = 0; i < n; ++i) {
        c->x[i] = xyz[3 * (size_t)i];
        c->y[i] = xyz[3 * (size_t)i + 1];
        c->z[i] = xyz[3 * (size_t)i + 2];
    }
    build_link_lists(c);
    if (self_collision) {
        c->self = wci_self_state_create(c);
        if (!c->self) {
            wci_cloth_destroy(c);
            return wci_fail(msg, WC_ERROR_OUT_OF_MEMORY,
                           "out of memory for the self-collision buffers of a cloth of %d vertices",
                           (int)n);
        }
    }
    s = check_links(c, msg);
    if (s) {
        wci_cloth_destroy(c);
        return s;
    }
    for (int32_t i = 0; i < n; ++i) c->wetness[i] = wetness;
    wci_cloth_apply_material(c);
    *out = c;
    return WC_OK;
}

void wci_cloth_commit(wc_cloth *c, double dt, int with_overrides)
{
    if (with_overrides)
        for (int32_t i = 0; i < c->particle_count; ++i)
            if (c->history_override[i]) c->px[i] = c->qx[i], c->py[i] = c->qy[i], c->pz[i] = c->qz[i];
    c->has_history = 1;
    c->dt_prev = dt;
}

void wci_cloth_velocity(const wc_cloth *c, int32_t i, double v[3])
{
    if (!c->has_history) {
        v[0] = c->px[i], v[1] = c->py[i], v[2] = c->pz[i];
        return;
    }
    double inv_dt = 1.0 / c->dt_prev;
    v[0] = (c->x[i] - c->px[i]) * inv_dt;
    v[1] = (c->y[i] - c->py[i]) * inv_dt;
    v[2] = (c->z[i] - c->pz[i]) * inv_dt;
}
