#include "wetness.h"

#include <math.h>
#include <string.h>

#include "parallel.h"

/* Thesis eq. 2.8 and 2.9, made independent of units:
 *  - a particle in contact with a surface of normal N (from the surface
 *    toward it) is pulled toward it with S = -s w N, s = adhesion * area,
 *    every step while in contact, so it touches again next step and stays
 *    until something pulls harder;
 *  - a particle not in contact, linked by stretch links to stuck
 *    particles, is pulled toward each one's surface with
 *    O = -s w beta (l / d) N_j, the pull weaker the more the link is
 *    stretched; the sum is capped at s w. The stuck area thus grows from its
 *    rim, one ring per contact, until bending resists more than adhesion
 *    pulls (thesis Fig. 3.5).
 * Each particle sums its own pulls, so the loop is parallel and the result
 * the same for any thread count. */
void wc_wet_forces(wc_cloth *c, int threads)
{
    int32_t n = c->particle_count, stretch_count = c->topology.stretch.count;
    const wc_material *m = &c->material;
    const wc_link_set *links = &c->topology.stretch;
    (void)threads;
#pragma omp parallel for schedule(static) num_threads(threads) if (n >= WC_PARALLEL_MIN)
    for (int32_t i = 0; i < n; ++i) {
        double w = c->wetness[i];
        if (w <= 0.0 || c->pin_slot[i] >= 0) continue;
        double s = m->adhesion * c->topology.area[i] * w;
        double f[3] = {0.0, 0.0, 0.0};
        if (c->contact[i] != WC_CONTACT_NONE) {
            f[0] = -s * c->normal_x[i], f[1] = -s * c->normal_y[i], f[2] = -s * c->normal_z[i];
        } else if (m->spread > 0.0) {
            for (int32_t k = c->link_start[i]; k < c->link_start[i + 1]; ++k) {
                int32_t e = c->link_list[k] >= 0 ? c->link_list[k] : ~c->link_list[k];
                if (e >= stretch_count) continue; /* bend links do not spread */
                int32_t j = links->a[e] == i ? links->b[e] : links->a[e];
                if (!c->stuck[j]) continue;
                double dx = c->x[i] - c->x[j], dy = c->y[i] - c->y[j], dz = c->z[i] - c->z[j];
                double d = sqrt(dx * dx + dy * dy + dz * dz);
                double pull = s * m->spread * (d > links->rest[e] ? links->rest[e] / d : 1.0);
                f[0] -= pull * c->normal_x[j];
                f[1] -= pull * c->normal_y[j];
                f[2] -= pull * c->normal_z[j];
            }
            double len = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
            if (len > s) {
                double scale = s / len;
                f[0] *= scale, f[1] *= scale, f[2] *= scale;
            }
        }
        c->fx[i] += f[0];
        c->fy[i] += f[1];
        c->fz[i] += f[2];
    }
}

int32_t wc_wet_mark_stuck(wc_cloth *c)
{
    int32_t stuck = 0;
    int adhesive = c->material.adhesion > 0.0;
    for (int32_t i = 0; i < c->particle_count; ++i) {
        c->stuck[i] = adhesive && c->wetness[i] > 0.0 && c->contact[i] != WC_CONTACT_NONE &&
                      c->contact_prev[i] != WC_CONTACT_NONE;
        stuck += c->stuck[i];
    }
    return stuck;
}

/* Wicking: dw_i/dt = D sum_j (w_j - w_i) / l_ij^2 over stretch links, the
 * graph form of the diffusion equation, explicit, in as many equal
 * sub-steps as its stability (D dt / l^2 below 1 / (2 * links)) needs.
 * Each particle gathers from its links into a second buffer (Jacobi), so
 * the order of particles does not matter. Drying: w *= exp(-rate dt),
 * exact for dw/dt = -rate w. */
void wc_wet_update(wc_cloth *c, double dt)
{
    const wc_material *m = &c->material;
    const wc_link_set *links = &c->topology.stretch;
    int32_t n = c->particle_count;
    if (m->wicking > 0.0 && c->wetness_next) {
        double worst = 0.0;
        for (int32_t i = 0; i < n; ++i) {
            double rate = 0.0;
            for (int32_t k = c->link_start[i]; k < c->link_start[i + 1]; ++k) {
                int32_t e = c->link_list[k] >= 0 ? c->link_list[k] : ~c->link_list[k];
                if (e < links->count) rate += m->wicking / (links->rest[e] * links->rest[e]);
            }
            if (rate > worst) worst = rate;
        }
        int substeps = (int)ceil(dt * worst / 0.5);
        if (substeps < 1) substeps = 1;
        double h = dt / substeps;
        for (int sub = 0; sub < substeps; ++sub) {
            for (int32_t i = 0; i < n; ++i) {
                double change = 0.0;
                for (int32_t k = c->link_start[i]; k < c->link_start[i + 1]; ++k) {
                    int32_t e = c->link_list[k] >= 0 ? c->link_list[k] : ~c->link_list[k];
                    if (e >= links->count) continue;
                    int32_t j = links->a[e] == i ? links->b[e] : links->a[e];
                    change += (c->wetness[j] - c->wetness[i]) / (links->rest[e] * links->rest[e]);
                }
                double next = c->wetness[i] + h * m->wicking * change;
                c->wetness_next[i] = next < 0.0 ? 0.0 : (next > 1.0 ? 1.0 : next);
            }
            memcpy(c->wetness, c->wetness_next, (size_t)n * sizeof *c->wetness);
        }
    }
    if (m->drying > 0.0) {
        double keep = exp(-m->drying * dt);
        for (int32_t i = 0; i < n; ++i) c->wetness[i] *= keep;
    }
    wc_cloth_apply_material(c);
}
