#include "forces.h"

#include <math.h>

#include "buckling.h"
#include "parallel.h"

/* Bend links shorter than this fraction of their rest length are folded
 * flat: their direction is undefined (the ends coincide), so they push with
 * no force rather than in an arbitrary direction. The force magnitude itself
 * stays finite and continuous down to d = 0. */
#define FOLDED_FRACTION 1e-12

static void compute_velocities(wc_cloth *c, int threads)
{
    int32_t n = c->particle_count;
    (void)threads; /* unused when built without OpenMP */
    if (!c->has_history) {
        for (int32_t i = 0; i < n; ++i) c->vx[i] = c->px[i], c->vy[i] = c->py[i], c->vz[i] = c->pz[i];
        return;
    }
    double inv_dt = 1.0 / c->dt_prev;
#pragma omp parallel for schedule(static) num_threads(threads) if (n >= WC_PARALLEL_MIN)
    for (int32_t i = 0; i < n; ++i) {
        c->vx[i] = (c->x[i] - c->px[i]) * inv_dt;
        c->vy[i] = (c->y[i] - c->py[i]) * inv_dt;
        c->vz[i] = (c->z[i] - c->pz[i]) * inv_dt;
    }
}

/* Thesis eq. 2.1, restoring: f_a = -K (d - l) u when d > l, none otherwise.
 * The dashpot acts along the link whether it is taut or slack. */
static void stretch_link_forces(wc_cloth *c, int threads)
{
    (void)threads;
    const wc_link_set *s = &c->topology.stretch;
    const double *x = c->x, *y = c->y, *z = c->z;
    const double *k = c->stretch_k, *damp = c->stretch_c;
    int32_t count = s->count;
#pragma omp parallel for schedule(static) num_threads(threads) if (count >= WC_PARALLEL_MIN)
    for (int32_t e = 0; e < count; ++e) {
        int32_t a = s->a[e], b = s->b[e];
        double dx = x[a] - x[b], dy = y[a] - y[b], dz = z[a] - z[b];
        double d2 = dx * dx + dy * dy + dz * dz;
        double d = sqrt(d2), scale = 0.0;
        if (d2 > 0.0) {
            /* one division per link: both terms divide by the length */
            double inv_d = 1.0 / d;
            if (d > s->rest[e]) scale = -k[e] * (d - s->rest[e]) * inv_d;
            if (damp) {
                double dvx = c->vx[a] - c->vx[b], dvy = c->vy[a] - c->vy[b], dvz = c->vz[a] - c->vz[b];
                scale -= damp[e] * (dvx * dx + dvy * dy + dvz * dz) * (inv_d * inv_d);
            }
        }
        c->link_fx[e] = scale * dx;
        c->link_fy[e] = scale * dy;
        c->link_fz[e] = scale * dz;
    }
}

/* Thesis eq. 2.2-2.3 (Choi & Ko): a compressed bend link pushes its ends
 * apart with (R / l^2) Phi(theta), ramped in over the first 0.1 % of
 * compression; see buckling.h. */
static void bend_link_forces(wc_cloth *c, int threads)
{
    (void)threads;
    const wc_link_set *s = &c->topology.bend;
    const double *x = c->x, *y = c->y, *z = c->z, *r = c->bend_r;
    int32_t count = s->count, offset = c->topology.stretch.count;
#pragma omp parallel for schedule(static) num_threads(threads) if (count >= WC_PARALLEL_MIN)
    for (int32_t e = 0; e < count; ++e) {
        int32_t a = s->a[e], b = s->b[e];
        double dx = x[a] - x[b], dy = y[a] - y[b], dz = z[a] - z[b];
        double d = sqrt(dx * dx + dy * dy + dz * dz);
        double l = s->rest[e];
        double scale = 0.0;
        if (d < l && d > FOLDED_FRACTION * l) {
            /* wc_buckling_force_ramped(d, l, R) / d with one division by l
             * and one by d, not three divisions */
            double inv_l = 1.0 / l;
            scale = r[e] * inv_l * inv_l * wc_buckling_phi_ramped((l - d) * inv_l) / d;
        }
        c->link_fx[offset + e] = scale * dx;
        c->link_fy[offset + e] = scale * dy;
        c->link_fz[offset + e] = scale * dz;
    }
}

static void gather_particle_forces(wc_cloth *c, const double g[3], int threads)
{
    (void)threads;
    int32_t n = c->particle_count;
    const int32_t *start = c->link_start, *list = c->link_list;
    const double *area = c->topology.area;
    double drag = c->material.air_drag;
#pragma omp parallel for schedule(static) num_threads(threads) if (n >= WC_PARALLEL_MIN)
    for (int32_t i = 0; i < n; ++i) {
        double fx = c->mass[i] * g[0], fy = c->mass[i] * g[1], fz = c->mass[i] * g[2];
        if (drag > 0.0) {
            fx -= drag * area[i] * c->vx[i];
            fy -= drag * area[i] * c->vy[i];
            fz -= drag * area[i] * c->vz[i];
        }
        for (int32_t k = start[i]; k < start[i + 1]; ++k) {
            int32_t e = list[k];
            if (e >= 0) {
                fx += c->link_fx[e], fy += c->link_fy[e], fz += c->link_fz[e];
            } else {
                fx -= c->link_fx[~e], fy -= c->link_fy[~e], fz -= c->link_fz[~e];
            }
        }
        c->fx[i] = fx, c->fy[i] = fy, c->fz[i] = fz;
    }
}

void wc_forces_compute(wc_cloth *c, const double gravity[3], int threads)
{
    if (c->vx) compute_velocities(c, threads);
    /* Under XPBD the stretch links are constraints (xpbd.c), not forces:
     * their entries in link_fx stay at zero from the allocation. */
    if (c->integrator != WC_INTEGRATOR_XPBD) stretch_link_forces(c, threads);
    bend_link_forces(c, threads);
    gather_particle_forces(c, gravity, threads);
}
