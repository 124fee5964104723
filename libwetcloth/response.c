#include "response.h"
#include "vec3.h"

#include <math.h>

wc_particle_arrays wci_particle_arrays_of(wc_cloth *c)
{
    wc_particle_arrays p;
    p.count = c->particle_count;
    p.x = c->x, p.y = c->y, p.z = c->z;
    p.nx = c->nx, p.ny = c->ny, p.nz = c->nz;
    p.qx = c->qx, p.qy = c->qy, p.qz = c->qz;
    p.history_override = c->history_override;
    p.inv_mass = c->inv_mass;
    p.pin_slot = c->pin_slot;
    p.contact = c->contact;
    p.normal_x = c->normal_x, p.normal_y = c->normal_y, p.normal_z = c->normal_z;
    p.contact_prev = c->contact_prev;
    p.wetness = c->wetness;
    p.grip = c->grip;
    p.step_squared = c->dt_step * c->dt_step;
    return p;
}

double wci_friction_keep(double mu, double normal_change, double tangential, double wet, double q,
                         double grip)
{
    if (!(tangential > 0.0)) return 1.0;
    double keep = 1.0 - mu * normal_change / tangential;
    if (keep < 0.0) keep = 0.0;
    if (wet > 0.0) {
        /* what Coulomb left, less the wet share of it, but never more than
         * the grip: past that the cloth slides */
        double wet_loss = wet * (1.0 - q) * keep * tangential;
        if (wet_loss > grip) wet_loss = grip;
        keep -= wet_loss / tangential;
        if (keep < 0.0) keep = 0.0;
    }
    return keep;
}

/* Where particle i's displacement over the step is measured from: its
 * previous position as the next step will see it, which is the start of the
 * step unless a response already moved it (a collider pass that pushed the
 * particle out shifted it by the push). Measured from the start of the step
 * instead, such a push counted as approach and came back as a velocity of
 * push / dt: 0.35 mm at a step of 8.6 us launched a particle at 40 m/s (the
 * 101 x 101 drape's 8x reference). */
static void from_of(const wc_particle_arrays *p, int32_t i, double out[3])
{
    if (p->history_override[i]) out[0] = p->qx[i], out[1] = p->qy[i], out[2] = p->qz[i];
    else out[0] = p->x[i], out[1] = p->y[i], out[2] = p->z[i];
}

/* The contact's wetness in sustained contact, the weighted wetness of its
 * particles that touched something in the last step, over both sides; and
 * *grip, the most tangential displacement wet friction can take off its
 * point in the step: the same weighted mean of the particles' grip (an
 * acceleration) times the step squared. */
static double sustained_wetness(const wc_particle_arrays *p, const wc_contact *k, double *grip)
{
    double wet = 0.0, held = 0.0, total = 0.0;
    for (int j = 0; j < k->count; ++j) {
        int32_t i = k->particle[j];
        double w = fabs(k->weight[j]);
        total += w;
        if (p->contact_prev[i] != WC_CONTACT_NONE) wet += w * p->wetness[i], held += w * p->grip[i];
    }
    *grip = total > 0.0 ? held / total * p->step_squared : 0.0;
    return total > 0.0 && wet > 0.0 ? wet / total : 0.0;
}

/* Inverse masses the response shares its changes by: none for pins, and
 * none along a collider's normal for a particle resting on it when cloth
 * would push it in. Returns sum w_k^2 m_k^-1. */
static double effective_inverse_masses(const wc_particle_arrays *p, const wc_contact *k, double im[4])
{
    double weight = 0.0;
    for (int j = 0; j < k->count; ++j) {
        int32_t i = k->particle[j];
        im[j] = k->weight[j] == 0.0 || p->pin_slot[i] >= 0 ? 0.0 : p->inv_mass[i];
        if (k->source == WC_SOURCE_CLOTH && im[j] > 0.0 && p->contact[i] == WC_CONTACT_COLLIDER) {
            double nc[3] = {p->normal_x[i], p->normal_y[i], p->normal_z[i]};
            double side = k->weight[j] > 0.0 ? 1.0 : -1.0;
            if (side * dot3(k->normal, nc) < 0.0) im[j] = 0.0;
        }
        weight += k->weight[j] * k->weight[j] * im[j];
    }
    return weight;
}

static void mark(const wc_particle_arrays *p, const wc_contact *k, int32_t *marked)
{
    for (int j = 0; j < k->count; ++j) {
        int32_t i = k->particle[j];
        if (k->weight[j] == 0.0) continue;
        double side = k->weight[j] > 0.0 ? 1.0 : -1.0;
        int collider = k->source == WC_SOURCE_COLLIDER;
        /* a single particle on a collider face keeps the normal of the last
         * face it met; elements and cloth pairs mark only what had none */
        if (p->contact[i] != WC_CONTACT_NONE && !(collider && k->count == 1)) continue;
        if (p->contact[i] == WC_CONTACT_NONE && marked) ++*marked;
        p->contact[i] = collider ? WC_CONTACT_COLLIDER : WC_CONTACT_CLOTH;
        p->normal_x[i] = side * k->normal[0];
        p->normal_y[i] = side * k->normal[1];
        p->normal_z[i] = side * k->normal[2];
    }
}

int wci_response_apply(const wc_particle_arrays *p, const wc_contact *k,
                      const wc_response_options *options, int32_t *marked, uint8_t moved[4])
{
    double im[4];
    for (int j = 0; j < 4; ++j) moved[j] = 0;
    if (dot3(k->normal, k->normal) == 0.0) return 0;
    if (k->source == WC_SOURCE_CLOTH) mark(p, k, marked);
    double weight = effective_inverse_masses(p, k, im);
    if (!(weight > 0.0)) return 0;
    /* u: the contact points' relative displacement over the step */
    double u[3] = {-k->surface_motion[0], -k->surface_motion[1], -k->surface_motion[2]};
    for (int j = 0; j < k->count; ++j) {
        double from[3];
        int32_t i = k->particle[j];
        from_of(p, i, from);
        u[0] += k->weight[j] * (p->nx[i] - from[0]);
        u[1] += k->weight[j] * (p->ny[i] - from[1]);
        u[2] += k->weight[j] * (p->nz[i] - from[2]);
    }
    double un = dot3(u, k->normal);
    double dv = un < 0.0 ? -un : 0.0;
    double dp = k->target - (k->distance + dv);
    if (k->source == WC_SOURCE_CLOTH) {
        /* an impact whose normal motion already keeps the target cannot be
         * answered along n: the fail-safe takes it */
        if (k->impact && !(k->distance < k->target)) return 0;
        if (!k->impact && dv <= options->slack && fabs(dp) <= options->slack) return 0;
    }
    if (dv == 0.0 && dp <= 0.0) return 0;
    if (k->source == WC_SOURCE_COLLIDER) mark(p, k, marked);
    /* tangential motion at the new place: the step's, plus the part of the
     * placement across the normal */
    double ut[3], at[3], place_n = dot3(k->place, k->normal);
    for (int m = 0; m < 3; ++m) {
        ut[m] = u[m] - un * k->normal[m];
        at[m] = ut[m] + (k->place[m] - place_n * k->normal[m]);
    }
    double lose = 0.0;
    if (dv > 0.0) {
        double grip, wet = sustained_wetness(p, k, &grip);
        lose = 1.0 - wci_friction_keep(k->friction, dv, sqrt(dot3(ut, ut)), wet, k->wet_friction,
                                       grip);
    }
    /* the point's change of position (de) and of displacement (du) */
    double de[3], du[3];
    for (int m = 0; m < 3; ++m) {
        de[m] = k->place[m] + (dv + dp) * k->normal[m] - lose * at[m];
        du[m] = dv * k->normal[m] - lose * ut[m];
    }
    for (int j = 0; j < k->count; ++j) {
        double scale = k->weight[j] * im[j] / weight;
        if (scale == 0.0) continue;
        int32_t i = k->particle[j];
        double from[3];
        from_of(p, i, from);
        p->nx[i] += scale * de[0];
        p->ny[i] += scale * de[1];
        p->nz[i] += scale * de[2];
        /* what of the position change is not velocity moves q with it */
        p->qx[i] = from[0] + scale * (de[0] - du[0]);
        p->qy[i] = from[1] + scale * (de[1] - du[1]);
        p->qz[i] = from[2] + scale * (de[2] - du[2]);
        p->history_override[i] = 1;
        moved[j] = 1;
    }
    return 1;
}
