#include "xpbd.h"

#include <math.h>
#include <string.h>

#include "alloc.h"
#include "integrate.h"
#include "invariant.h"
#include "parallel.h"

/* Colours 0 .. GREEDY_COLORS - 1 come from a greedy colouring with one bit
 * per colour and particle; a link whose two ends have used them all (a
 * vertex of very high valence) goes to one last colour that is projected
 * serially. A regular grid needs 8 to 12 colours. */
#define GREEDY_COLORS 64

/* Gauss-Seidel sweeps over the stretch constraints per step: one, as in
 * Small Steps. Measured with 4 (tools/bench_integrators, thesis drape): the
 * error against 8x the steps falls about 2x at 5-10 steps per frame (400
 * particles 5.9e-2 -> 2.1e-2 at 5; 10,201 particles 0.17 -> 0.08 at 10), but
 * the stiffer cloth then leaves 24 intersecting pair-frames in the wet
 * wrap (tests/test_integrators.c) and gains little at 20 steps per frame
 * (6.3e-3 -> 6.6e-3 on 12^2). lambda accumulates across sweeps, so more
 * sweeps stay correct XPBD. */
#define XPBD_ITERATIONS 1

/* One link set grouped by colour. */
typedef struct link_colors {
    int32_t color_count;
    /// Links of colour k: links[color_start[k] .. color_start[k + 1]).
    int32_t color_start[GREEDY_COLORS + 2];
    int32_t *links;
    /// 1 when the last colour is the serial remainder.
    int serial_last;
    /// Accumulated impulse of each link in the current step, kg m.
    double *lambda;
} link_colors;

struct wc_xpbd_state {
    link_colors stretch;
};

static void free_colors(link_colors *lc)
{
    wci_free(lc->links);
    wci_free(lc->lambda);
}

/* Greedy colouring of one link set; links ascending within a colour, so
 * the order is fixed by the mesh alone. Returns 0 when out of memory. */
static int color_links(const wc_link_set *s, int32_t particles, link_colors *lc)
{
    uint64_t *used = wci_alloc_array((size_t)particles, sizeof *used);
    uint8_t *color = wci_alloc_array((size_t)s->count + 1, sizeof *color);
    lc->links = wci_alloc_array((size_t)s->count + 1, sizeof *lc->links);
    lc->lambda = wci_alloc_array((size_t)s->count + 1, sizeof *lc->lambda);
    int ok = used && color && lc->links && lc->lambda;
    if (ok) {
        int32_t count[GREEDY_COLORS + 1] = {0};
        for (int32_t e = 0; e < s->count; ++e) {
            uint64_t taken = used[s->a[e]] | used[s->b[e]];
            int k = 0;
            while (k < GREEDY_COLORS && (taken >> k & 1u)) ++k;
            if (k < GREEDY_COLORS) {
                used[s->a[e]] |= (uint64_t)1 << k;
                used[s->b[e]] |= (uint64_t)1 << k;
            }
            color[e] = (uint8_t)k;
            count[k]++;
        }
        /* keep only colours that have links, in order */
        int32_t colors = 0, start = 0;
        for (int k = 0; k <= GREEDY_COLORS; ++k) {
            if (!count[k]) continue;
            lc->color_start[colors] = start;
            for (int32_t e = 0; e < s->count; ++e)
                if (color[e] == k) lc->links[start++] = e;
            lc->serial_last = k == GREEDY_COLORS;
            ++colors;
        }
        lc->color_start[colors] = start;
        lc->color_count = colors;
    }
    wci_free(used);
    wci_free(color);
    return ok;
}

wc_xpbd_state *wci_xpbd_state_create(const wc_cloth *c)
{
    wc_xpbd_state *st = wci_alloc_array(1, sizeof *st);
    if (!st) return NULL;
    if (!color_links(&c->topology.stretch, c->particle_count, &st->stretch)) {
        wci_xpbd_state_destroy(st);
        return NULL;
    }
    return st;
}

void wci_xpbd_state_destroy(wc_xpbd_state *st)
{
    if (!st) return;
    free_colors(&st->stretch);
    wci_free(st);
}

int32_t wci_xpbd_color_count(const wc_xpbd_state *st) { return st->stretch.color_count; }

/* One compliant projection of stretch link e (XPBD, Macklin, Mueller &
 * Chentanez 2016, eq. 18 with their Rayleigh damping, eq. 26), written with
 * both sides multiplied by K h^2 so that K = 0 is allowed:
 *   dlambda = -(K' h^2 C + lambda + c' h rate) / ((K' h^2 + c' h)(w_a + w_b) + 1),
 * C = d - l, rate = grad C . (p - x) the link's lengthening in this step.
 * Two kinds of pass use it:
 *  - slack pass (slack = 1): links slack at the prediction get only their
 *    dashpot (K' = 0, c' = c): from lambda = 0 this is exactly the
 *    backward-Euler dashpot, the relative velocity along the link divided
 *    by 1 + c h (w_a + w_b), stable at any step. It runs once, before the
 *    constraint sweeps, so it damps the motion forces and gravity gave and
 *    does not resist the corrections the constraints pass along the cloth.
 *  - constraint pass (slack = 0): K' = K while the link is taut (C > 0) and
 *    0 while slack (the spring resists tension only), c' = c while taut.
 *    lambda accumulates over the iterations of one step (a position
 *    impulse, kg m): a link a sweep over-corrects into slackness gives its
 *    elastic part back in the next.
 * p are the positions being computed, x those at the start of the step; w
 * the inverse masses, zero for pins. */
static void project_link(wc_cloth *c, double *lambda, int32_t e, double h, int slack)
{
    const wc_link_set *s = &c->topology.stretch;
    int32_t a = s->a[e], b = s->b[e];
    double wa = c->pin_slot[a] >= 0 ? 0.0 : c->inv_mass[a];
    double wb = c->pin_slot[b] >= 0 ? 0.0 : c->inv_mass[b];
    if (wa + wb == 0.0) return;
    double dx = c->nx[a] - c->nx[b], dy = c->ny[a] - c->ny[b], dz = c->nz[a] - c->nz[b];
    double d = sqrt(dx * dx + dy * dy + dz * dz);
    if (!(d > 0.0)) return;
    double constraint = d - s->rest[e];
    int taut = constraint > 0.0;
    if (slack && taut) return;
    double kh2 = !slack && taut ? c->stretch_k[e] * h * h : 0.0;
    double ch = c->stretch_c && (slack || taut) ? c->stretch_c[e] * h : 0.0;
    double held = slack ? 0.0 : lambda[e];
    if (kh2 == 0.0 && ch == 0.0 && held == 0.0) return;
    double ux = dx / d, uy = dy / d, uz = dz / d;
    double rate = 0.0;
    if (ch > 0.0)
        rate = ux * ((c->nx[a] - c->x[a]) - (c->nx[b] - c->x[b])) +
               uy * ((c->ny[a] - c->y[a]) - (c->ny[b] - c->y[b])) +
               uz * ((c->nz[a] - c->z[a]) - (c->nz[b] - c->z[b]));
    double dl = -(kh2 * constraint + held + ch * rate) / ((kh2 + ch) * (wa + wb) + 1.0);
    if (!slack) lambda[e] += dl;
    c->nx[a] += wa * dl * ux, c->ny[a] += wa * dl * uy, c->nz[a] += wa * dl * uz;
    c->nx[b] -= wb * dl * ux, c->ny[b] -= wb * dl * uy, c->nz[b] -= wb * dl * uz;
}

/* Projections of a run of links of one colour. */
typedef struct sweep_pass {
    wc_cloth *cloth;
    double *lambda;
    const int32_t *links;
    double h;
    int slack;
} sweep_pass;

static int sweep_range(void *context, int64_t begin, int64_t end)
{
    const sweep_pass *p = context;
    for (int64_t i = begin; i < end; ++i) project_link(p->cloth, p->lambda, p->links[i], p->h, p->slack);
    return 0;
}

/* One Gauss-Seidel sweep over the stretch links, colour by colour: their
 * dashpots where slack (slack = 1), or their constraints (slack = 0). */
static void sweep(wc_cloth *c, link_colors *lc, double h, int slack, int threads)
{
    for (int32_t k = 0; k < lc->color_count; ++k) {
        int32_t begin = lc->color_start[k], count = lc->color_start[k + 1] - begin;
        sweep_pass pass = {c, lc->lambda, lc->links + begin, h, slack};
        /* links of one colour share no particle: any thread order gives the
         * same bits; the serial remainder's do */
        int serial = lc->serial_last && k == lc->color_count - 1;
        wci_parallel_for(count, serial ? 1 : wc_threads_for(count, threads), sweep_range, &pass);
    }
}

int32_t wci_integrate_xpbd(wc_cloth *c, double dt, double pin_fraction, int threads)
{
    WC_ASSERT(c->xpbd != NULL);
    WC_ASSERT(dt > 0.0 && pin_fraction >= 0.0 && pin_fraction <= 1.0 && threads >= 1);
    int32_t bad = wci_integrate_verlet(c, dt, pin_fraction, threads);
    if (bad >= 0) return bad;
    wc_xpbd_state *st = c->xpbd;
    memset(st->stretch.lambda, 0, (size_t)c->topology.stretch.count * sizeof(double));
    if (c->stretch_c) sweep(c, &st->stretch, dt, 1, threads);
    for (int it = 0; it < XPBD_ITERATIONS; ++it) sweep(c, &st->stretch, dt, 0, threads);
    return wci_first_non_finite_xyz(c->nx, c->ny, c->nz, c->particle_count);
}
