#include "xpbd.h"

#include <math.h>
#include <string.h>

#include "alloc.h"
#include "integrate.h"
#include "parallel.h"

/* Colours 0 .. GREEDY_COLORS - 1 come from a greedy colouring with one bit
 * per colour and particle; a link whose two ends have used them all (a
 * vertex of very high valence) goes to one last colour that is projected
 * serially. A regular grid needs 8 to 12 colours. */
#define GREEDY_COLORS 64

struct wc_xpbd_state {
    int32_t color_count;
    /// Links of colour k: links[color_start[k] .. color_start[k + 1]).
    int32_t color_start[GREEDY_COLORS + 2];
    int32_t *links;
    /// 1 when the last colour is the serial remainder.
    int serial_last;
};

wc_xpbd_state *wc_xpbd_state_create(const wc_cloth *c)
{
    const wc_link_set *s = &c->topology.stretch;
    wc_xpbd_state *st = wc_alloc_array(1, sizeof *st);
    uint64_t *used = wc_alloc_array((size_t)c->particle_count, sizeof *used);
    uint8_t *color = wc_alloc_array((size_t)s->count, sizeof *color);
    if (st) st->links = wc_alloc_array((size_t)s->count, sizeof *st->links);
    if (!st || !used || !color || !st->links) {
        wc_free(used);
        wc_free(color);
        wc_xpbd_state_destroy(st);
        return NULL;
    }
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
    /* keep only colours that have links, in order; links in ascending
     * order within a colour */
    int32_t colors = 0, start = 0;
    for (int k = 0; k <= GREEDY_COLORS; ++k) {
        if (!count[k]) continue;
        st->color_start[colors] = start;
        for (int32_t e = 0; e < s->count; ++e)
            if (color[e] == k) st->links[start++] = e;
        st->serial_last = k == GREEDY_COLORS;
        ++colors;
    }
    st->color_start[colors] = start;
    st->color_count = colors;
    wc_free(used);
    wc_free(color);
    return st;
}

void wc_xpbd_state_destroy(wc_xpbd_state *st)
{
    if (!st) return;
    wc_free(st->links);
    wc_free(st);
}

int32_t wc_xpbd_color_count(const wc_xpbd_state *st) { return st->color_count; }

/* One compliant projection of stretch link e (XPBD, Macklin, Mueller &
 * Chentanez 2016, eq. 18 with their Rayleigh damping, eq. 26):
 *   C = d - l (active only when taut: the link resists tension only),
 *   alpha~ = 1 / (K h^2), gamma = alpha~ c h = c / (K h),
 *   dlambda = -(C + gamma grad C . (p - x)) / ((1 + gamma) (w_a + w_b) + alpha~),
 * from lambda = 0: with one iteration per small step there is no lambda to
 * carry (Small Steps, section 4). p are the positions being computed, x
 * those at the start of the step; w the inverse masses, zero for pins. For
 * K -> infinity alpha~ -> 0 and this is the inextensible projection.
 * Damping acts only on taut links: a slack link is no constraint (the force
 * model's dashpot also acts on slack links; here it is dropped, see
 * docs/model.md). */
static void project_link(wc_cloth *c, int32_t e, double h2, double h)
{
    const wc_link_set *s = &c->topology.stretch;
    int32_t a = s->a[e], b = s->b[e];
    double k = c->stretch_k[e];
    if (!(k > 0.0)) return;
    double wa = c->pin_slot[a] >= 0 ? 0.0 : c->inv_mass[a];
    double wb = c->pin_slot[b] >= 0 ? 0.0 : c->inv_mass[b];
    if (wa + wb == 0.0) return;
    double dx = c->nx[a] - c->nx[b], dy = c->ny[a] - c->ny[b], dz = c->nz[a] - c->nz[b];
    double d = sqrt(dx * dx + dy * dy + dz * dz);
    double constraint = d - s->rest[e];
    if (!(constraint > 0.0)) return;
    double ux = dx / d, uy = dy / d, uz = dz / d;
    double alpha = 1.0 / (k * h2), gamma = 0.0, rate = 0.0;
    if (c->stretch_c) {
        gamma = c->stretch_c[e] / (k * h);
        rate = ux * ((c->nx[a] - c->x[a]) - (c->nx[b] - c->x[b])) +
               uy * ((c->ny[a] - c->y[a]) - (c->ny[b] - c->y[b])) +
               uz * ((c->nz[a] - c->z[a]) - (c->nz[b] - c->z[b]));
    }
    double dl = -(constraint + gamma * rate) / ((1.0 + gamma) * (wa + wb) + alpha);
    c->nx[a] += wa * dl * ux, c->ny[a] += wa * dl * uy, c->nz[a] += wa * dl * uz;
    c->nx[b] -= wb * dl * ux, c->ny[b] -= wb * dl * uy, c->nz[b] -= wb * dl * uz;
}

int32_t wc_integrate_xpbd(wc_cloth *c, double dt, double pin_fraction, int threads)
{
    (void)threads;
    int32_t bad = wc_integrate_verlet(c, dt, pin_fraction, threads);
    if (bad >= 0) return bad;
    const wc_xpbd_state *st = c->xpbd;
    double h2 = dt * dt;
    for (int32_t k = 0; k < st->color_count; ++k) {
        int32_t begin = st->color_start[k], end = st->color_start[k + 1];
        if (st->serial_last && k == st->color_count - 1) {
            for (int32_t i = begin; i < end; ++i) project_link(c, st->links[i], h2, dt);
            continue;
        }
        /* links of one colour share no particle: any thread order gives the
         * same bits */
#pragma omp parallel for schedule(static) num_threads(threads) if (end - begin >= WC_PARALLEL_MIN)
        for (int32_t i = begin; i < end; ++i) project_link(c, st->links[i], h2, dt);
    }
    return wc_first_non_finite_xyz(c->nx, c->ny, c->nz, c->particle_count);
}
