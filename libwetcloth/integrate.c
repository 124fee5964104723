#include "integrate.h"

#include <math.h>

#include "parallel.h"
#include "primitives.h"

void wci_pinned_position(const wc_cloth *c, int32_t slot, double fraction, double out[3])
{
    const double *from = c->pins.from + 3 * (size_t)slot, *to = c->pins.to + 3 * (size_t)slot;
    for (int k = 0; k < 3; ++k) out[k] = fraction == 1.0 ? to[k] : wc_lerp(from[k], to[k], fraction);
}

/* One Verlet step's constants (see wci_integrate_verlet). */
typedef struct verlet_pass {
    wc_cloth *cloth;
    double pin_fraction, ratio, acc_scale;
    int first;
} verlet_pass;

/* Returns 1 when a new position is not finite. */
static int verlet_range(void *context, int64_t begin, int64_t end)
{
    const verlet_pass *v = context;
    wc_cloth *c = v->cloth;
    double ratio = v->ratio, acc_scale = v->acc_scale;
    int first = v->first, bad = 0;
    for (int64_t i = begin; i < end; ++i) {
        double p[3];
        if (c->pin_slot[i] >= 0) {
            wci_pinned_position(c, c->pin_slot[i], v->pin_fraction, p);
        } else {
            double s = c->inv_mass[i] * acc_scale;
            double mx = first ? c->px[i] : c->x[i] - c->px[i];
            double my = first ? c->py[i] : c->y[i] - c->py[i];
            double mz = first ? c->pz[i] : c->z[i] - c->pz[i];
            p[0] = c->x[i] + mx * ratio + c->fx[i] * s;
            p[1] = c->y[i] + my * ratio + c->fy[i] * s;
            p[2] = c->z[i] + mz * ratio + c->fz[i] * s;
        }
        c->nx[i] = p[0], c->ny[i] = p[1], c->nz[i] = p[2];
        bad = bad || !(isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]));
    }
    return bad;
}

int32_t wci_integrate_verlet(wc_cloth *c, double dt, double pin_fraction, int threads)
{
    int32_t n = c->particle_count;
    int first = !c->has_history;
    /* x(t+dt) = x + (x - x_prev) dt/dt_prev + a dt (dt + dt_prev) / 2:
     * Verlet for a step length that may change (with a constant step it is
     * exactly x + (x - x_prev) + a dt^2, thesis eq. 2.4). The history is
     * rescaled to the new step, and the acceleration acts over the mean of
     * the two steps, which keeps constant acceleration exact. The first step
     * starts from the velocity v held in px: x + v dt + a dt^2 / 2. */
    verlet_pass pass = {c, pin_fraction, first ? dt : dt / c->dt_prev,
                        first ? 0.5 * dt * dt : 0.5 * dt * (dt + c->dt_prev), first};
    if (!wci_parallel_for(n, wc_threads_for(n, threads), verlet_range, &pass)) return -1;
    return wci_first_non_finite_xyz(c->nx, c->ny, c->nz, n);
}

int32_t wci_first_non_finite_xyz(const double *x, const double *y, const double *z, int32_t n)
{
    for (int32_t i = 0; i < n; ++i)
        if (!(isfinite(x[i]) && isfinite(y[i]) && isfinite(z[i]))) return i;
    return -1;
}
