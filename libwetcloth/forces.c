#include "forces.h"

#include <math.h>

#include "buckling.h"
#include "parallel.h"

/* Bend links shorter than this fraction of their rest length are folded
 * flat: their direction is undefined (the ends coincide), so they push with
 * no force rather than in an arbitrary direction. The force magnitude itself
 * stays finite and continuous down to d = 0. */
#define FOLDED_FRACTION 1e-12

/* What the loops below need: the cloth, and gravity for the last one. */
typedef struct force_pass {
    wc_cloth *cloth;
    const double *gravity;
} force_pass;

static int velocities_range(void *context, int64_t begin, int64_t end)
{
    wc_cloth *c = ((force_pass *)context)->cloth;
    double inv_dt = 1.0 / c->dt_prev;
    for (int64_t i = begin; i < end; ++i) {
        c->vx[i] = (c->x[i] - c->px[i]) * inv_dt;
        c->vy[i] = (c->y[i] - c->py[i]) * inv_dt;
        c->vz[i] = (c->z[i] - c->pz[i]) * inv_dt;
    }
    return 0;
}

static void compute_velocities(force_pass *pass, int threads)
{
    wc_cloth *c = pass->cloth;
    int32_t n = c->particle_count;
    if (!c->has_history) {
        for (int32_t i = 0; i < n; ++i) c->vx[i] = c->px[i], c->vy[i] = c->py[i], c->vz[i] = c->pz[i];
        return;
    }
    wci_parallel_for(n, wc_threads_for(n, threads), velocities_range, pass);
}

/* Thesis eq. 2.1, restoring: f_a = -K (d - l) u when d > l, none otherwise.
 * The dashpot acts along the link whether it is taut or slack. */
static int stretch_range(void *context, int64_t begin, int64_t end)
{
    wc_cloth *c = ((force_pass *)context)->cloth;
    const wc_link_set *s = &c->topology.stretch;
    const double *x = c->x, *y = c->y, *z = c->z;
    const double *k = c->stretch_k, *damp = c->stretch_c;
    for (int64_t e = begin; e < end; ++e) {
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
    return 0;
}

/* Links per block of the bend loop. The loop runs in three passes over a
 * block (lengths, Phi, forces) so that the block's Phi polynomials, long
 * chains of dependent multiplies and adds, are independent work the
 * processor overlaps; one pass per link left them mostly one after another
 * (measured: forces of a draped 20 x 20 cloth 30.5 -> 25.5 us; blocks of 8
 * to 64 links are within 1 % of each other). */
#define BEND_BLOCK 32

/* Thesis eq. 2.2-2.3 (Choi & Ko): a compressed bend link pushes its ends
 * apart with (R / l^2) Phi(theta), ramped in over the first 0.1 % of
 * compression; see buckling.h. R / l^2 and 1 / l come precomputed with the
 * rounding this loop had when it computed them (cloth.h): the same bits,
 * two divisions fewer per link. */
static int bend_range(void *context, int64_t begin, int64_t end)
{
    wc_cloth *c = ((force_pass *)context)->cloth;
    const wc_link_set *s = &c->topology.bend;
    const double *x = c->x, *y = c->y, *z = c->z, *rest = s->rest;
    const double *inv_rest = c->bend_inv_rest, *coef = c->bend_coef;
    int32_t offset = c->topology.stretch.count;
    double *fx = c->link_fx + offset, *fy = c->link_fy + offset, *fz = c->link_fz + offset;
    for (int64_t first = begin; first < end; first += BEND_BLOCK) {
        int count = end - first < BEND_BLOCK ? (int)(end - first) : BEND_BLOCK;
        double d[BEND_BLOCK], phi[BEND_BLOCK];
        /* the link vectors wait in the link's force entries */
        for (int j = 0; j < count; ++j) {
            int64_t e = first + j;
            int32_t a = s->a[e], b = s->b[e];
            double dx = x[a] - x[b], dy = y[a] - y[b], dz = z[a] - z[b];
            fx[e] = dx, fy[e] = dy, fz[e] = dz;
            d[j] = sqrt(dx * dx + dy * dy + dz * dz);
        }
        for (int j = 0; j < count; ++j)
            phi[j] = wc_buckling_phi_ramped((rest[first + j] - d[j]) * inv_rest[first + j]);
        for (int j = 0; j < count; ++j) {
            int64_t e = first + j;
            double l = rest[e], scale = 0.0;
            if (d[j] < l && d[j] > FOLDED_FRACTION * l) scale = coef[e] * phi[j] / d[j];
            fx[e] = scale * fx[e], fy[e] = scale * fy[e], fz[e] = scale * fz[e];
        }
    }
    return 0;
}

static int gather_range(void *context, int64_t begin, int64_t end)
{
    wc_cloth *c = ((force_pass *)context)->cloth;
    const double *g = ((force_pass *)context)->gravity;
    const int32_t *start = c->link_start, *list = c->link_list;
    const double *area = c->topology.area;
    double drag = c->material.air_drag;
    for (int64_t i = begin; i < end; ++i) {
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
    return 0;
}

void wci_forces_compute(wc_cloth *c, const double gravity[3], int threads)
{
    force_pass pass = {c, gravity};
    int32_t n = c->particle_count, stretch = c->topology.stretch.count;
    int32_t bend = c->topology.bend.count;
    if (c->vx) compute_velocities(&pass, threads);
    /* Under XPBD the stretch links are constraints (xpbd.c), not forces:
     * their entries in link_fx stay at zero from the allocation. */
    if (c->integrator != WC_INTEGRATOR_XPBD)
        wci_parallel_for(stretch, wc_threads_for(stretch, threads), stretch_range, &pass);
    wci_parallel_for(bend, wc_threads_for(bend, threads), bend_range, &pass);
    wci_parallel_for(n, wc_threads_for(n, threads), gather_range, &pass);
}
