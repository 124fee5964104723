#include "applied.h"

#include <math.h>
#include <string.h>

#include "alloc.h"
#include "integrate.h"
#include "parallel.h"
#include "status.h"
#include "world.h"

/* Largest speed of the air and largest external force density accepted:
 * far beyond anything physical (the speed of sound is 343 m/s; 1e6 N/m^2
 * is ten atmospheres), low enough that the forces they make stay finite. */
#define MAX_AIR_SPEED 1e4
#define MAX_FORCE_DENSITY 1e6

int wci_applied_active(const wc_cloth *c)
{
    return (c->air_velocity && c->material.air_drag > 0.0) || c->external_force ||
           c->pins.soft_count > 0;
}

/* What the pass needs; NULL for what the cloth does not have. */
typedef struct applied_pass {
    wc_cloth *cloth;
    double target_fraction;
    const double *air_velocity;
    const double *external_force;
    const int32_t *soft_pin_slot;
} applied_pass;

static int applied_range(void *context, int64_t begin, int64_t end)
{
    const applied_pass *p = context;
    wc_cloth *c = p->cloth;
    const double *area = c->topology.area, *u = p->air_velocity, *ext = p->external_force;
    double drag = c->material.air_drag;
    for (int64_t i = begin; i < end; ++i) {
        if (c->pin_slot[i] >= 0) continue;
        double fx = c->fx[i], fy = c->fy[i], fz = c->fz[i];
        if (u) {
            double k = drag * area[i];
            fx += k * u[3 * i], fy += k * u[3 * i + 1], fz += k * u[3 * i + 2];
        }
        if (ext) fx += ext[3 * i], fy += ext[3 * i + 1], fz += ext[3 * i + 2];
        if (p->soft_pin_slot && p->soft_pin_slot[i] >= 0) {
            int32_t slot = p->soft_pin_slot[i];
            double target[3];
            wci_pinned_position(c, slot, p->target_fraction, target);
            /* k = m s: the particle's own angular frequency about its
             * target is sqrt(s) whatever its mass, so the same stiffness
             * gives the same motion at any mesh resolution and wetness */
            double k = c->mass[i] * c->pins.stiffness[slot];
            fx -= k * (c->x[i] - target[0]);
            fy -= k * (c->y[i] - target[1]);
            fz -= k * (c->z[i] - target[2]);
        }
        c->fx[i] = fx, c->fy[i] = fy, c->fz[i] = fz;
    }
    return 0;
}

void wci_applied_forces_add(wc_cloth *c, double target_fraction, int threads)
{
    applied_pass pass = {c, target_fraction,
                         c->material.air_drag > 0.0 ? c->air_velocity : NULL,
                         c->external_force, c->pins.soft_count > 0 ? c->soft_pin_slot : NULL};
    int32_t n = c->particle_count;
    wci_parallel_for(n, wc_threads_for(n, threads), applied_range, &pass);
}

/* ------------------------------------------------------------------------ */
/* The public setters                                                        */
/* ------------------------------------------------------------------------ */

/* The cloth's fields that the setters fill. */
typedef enum field_id { FIELD_AIR_VELOCITY, FIELD_EXTERNAL_FORCE } field_id;

/* What one setter takes: the field, its name for messages, what its values
 * are, their unit and largest length, and whether they are scaled by each
 * particle's rest area when stored. */
typedef struct field_kind {
    field_id id;
    const char *caller;
    const char *argument;
    const char *quantity;
    const char *unit;
    double limit;
    int per_area;
} field_kind;

/* Every value finite, every vector no longer than the limit. */
static wc_status check_field(const wc_world *w, const field_kind *kind, const double *xyz,
                             int32_t count)
{
    for (int32_t i = 0; i < count; ++i) {
        const double *v = xyz + 3 * (size_t)i;
        for (int k = 0; k < 3; ++k)
            if (!isfinite(v[k]))
                return wci_fail(wci_world_message(w), WC_ERROR_INVALID_ARGUMENT,
                               "%s: %s[%ld] (%c of particle %d) must be finite but is %g",
                               kind->caller, kind->argument, 3L * i + k, "xyz"[k], (int)i, v[k]);
        double length = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        if (!(length <= kind->limit))
            return wci_fail(wci_world_message(w), WC_ERROR_INVALID_ARGUMENT,
                           "%s: the %s of particle %d is (%g, %g, %g), of length %g %s; it must "
                           "be at most %g %s",
                           kind->caller, kind->quantity, (int)i, v[0], v[1], v[2], length,
                           kind->unit, kind->limit, kind->unit);
    }
    return WC_OK;
}

/* Sets, or with NULL and count 0 clears, one per-particle field. Checks
 * everything and allocates before it changes anything. */
static wc_status set_field(wc_world *w, int32_t cloth, const double *xyz, int32_t count,
                           const field_kind *kind)
{
    if (!w) return WC_ERROR_INVALID_ARGUMENT;
    wc_cloth *c = wci_world_find_cloth(w, cloth, kind->caller);
    if (!c) return WC_ERROR_NOT_FOUND;
    double **field = kind->id == FIELD_AIR_VELOCITY ? &c->air_velocity : &c->external_force;
    if (!xyz) {
        if (count != 0)
            return wci_fail(&w->error, WC_ERROR_INVALID_ARGUMENT,
                           "%s: %s is NULL but count is %d (NULL with count 0 clears the %s)",
                           kind->caller, kind->argument, (int)count, kind->quantity);
        wci_free(*field);
        *field = NULL;
        return WC_OK;
    }
    if (count != c->particle_count)
        return wci_fail(&w->error, WC_ERROR_INVALID_ARGUMENT,
                       "%s: count must be %d for cloth %d (its particle count) but is %d",
                       kind->caller, (int)c->particle_count, (int)cloth, (int)count);
    wc_status s = check_field(w, kind, xyz, count);
    if (s) return s;
    if (!*field) {
        *field = wci_alloc_array(3 * (size_t)count, sizeof **field);
        if (!*field)
            return wci_fail(&w->error, WC_ERROR_OUT_OF_MEMORY,
                           "%s: out of memory for the %s of %d particles", kind->caller,
                           kind->quantity, (int)count);
    }
    if (!kind->per_area) {
        memcpy(*field, xyz, 3 * (size_t)count * sizeof *xyz);
        return WC_OK;
    }
    const double *area = c->topology.area;
    for (size_t k = 0; k < 3 * (size_t)count; ++k) (*field)[k] = area[k / 3] * xyz[k];
    return WC_OK;
}

wc_status wc_cloth_set_air_velocity(wc_world *w, int32_t cloth, const double *velocity_xyz,
                                    int32_t count)
{
    static const field_kind kind = {FIELD_AIR_VELOCITY, "wc_cloth_set_air_velocity",
                                    "velocity_xyz", "air velocity", "m/s", MAX_AIR_SPEED, 0};
    return set_field(w, cloth, velocity_xyz, count, &kind);
}

wc_status wc_cloth_set_external_forces(wc_world *w, int32_t cloth, const double *force_per_area_xyz,
                                       int32_t count)
{
    static const field_kind kind = {FIELD_EXTERNAL_FORCE, "wc_cloth_set_external_forces",
                                    "force_per_area_xyz", "external force density", "N/m^2",
                                    MAX_FORCE_DENSITY, 1};
    return set_field(w, cloth, force_per_area_xyz, count, &kind);
}
