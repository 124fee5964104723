#include "step_guard.h"

#include <math.h>

#include "cloth.h"
#include "parallel.h"

/* Growth per step that counts (an unstable Verlet mode grows by 1.49 per
 * step at 2 % above its limit, by 2.4 at 10 %). A run of r >= 2 such steps
 * fires when their growth G has G^r >= RUN_POWER: two growing 32-fold
 * together, three 10-fold, ..., and any eight (1.2^8 = 4.3). Far above the
 * limit the growth is huge from the first steps and fires at once; close to
 * it, slowly, it takes eight. Never one step alone: a collision can kick a
 * particle hard, and its links pull back the other way the next step
 * (measured: a quad cloth struck by particles a box collider threw out). */
#define GROWTH 1.2
#define RUN_POWER 1e3
#define RUN 8
#define MIN_RUN 2
/* Smallest size of the oscillation that fires, in mean link lengths per
 * step: far above rounding noise, far below anything visible. */
#define FLOOR 1e-3
/* The largest change is found per fixed slice of the particles, then the
 * slices are compared in order: the same particle for any thread count. */
#define SLICES 64

/* Change of particle i's velocity over the step, m/s, and its square. */
static double change_at(const wc_cloth *c, int32_t i, double dt, double dv[3])
{
    double v[3];
    wci_cloth_velocity(c, i, v);
    dv[0] = (c->nx[i] - c->x[i]) / dt - v[0];
    dv[1] = (c->ny[i] - c->y[i]) / dt - v[1];
    dv[2] = (c->nz[i] - c->z[i]) / dt - v[2];
    return dv[0] * dv[0] + dv[1] * dv[1] + dv[2] * dv[2];
}

/* The free particle with the largest velocity change (the lowest index
 * among equals), or -1; *change2 gets its square. */
static int32_t largest_change(const wc_cloth *c, double dt, int threads, double *change2)
{
    double best[SLICES];
    int32_t at[SLICES];
    int32_t n = c->particle_count;
    (void)threads;
#pragma omp parallel for schedule(static) num_threads(threads) if (n >= WC_PARALLEL_MIN)
    for (int k = 0; k < SLICES; ++k) {
        best[k] = -1.0, at[k] = -1;
        for (int32_t i = (int32_t)((int64_t)n * k / SLICES); i < (int32_t)((int64_t)n * (k + 1) / SLICES); ++i) {
            if (c->pin_slot[i] >= 0) continue;
            double dv[3], m2 = change_at(c, i, dt, dv);
            if (m2 > best[k]) best[k] = m2, at[k] = i;
        }
    }
    int32_t p = -1;
    *change2 = -1.0;
    for (int k = 0; k < SLICES; ++k)
        if (at[k] >= 0 && best[k] > *change2) *change2 = best[k], p = at[k];
    return p;
}

static double mean_link_length(const wc_cloth *c)
{
    const wc_link_set *s = &c->topology.stretch;
    double sum = 0.0;
    for (int32_t e = 0; e < s->count; ++e) sum += s->rest[e];
    return s->count ? sum / s->count : 1.0;
}

int32_t wci_step_guard_check(const wc_cloth *c, const wc_step_guard *g, double dt, int threads,
                            wc_step_guard *next)
{
    *next = *g;
    /* A step within the stable estimate (a bound) cannot be unstable:
     * whatever goes wrong there is not the step's length. Watching only
     * longer steps keeps the guard off every run at automatic substeps. */
    if (!(dt > c->stable_dt)) {
        next->particle = -1, next->change = 0.0, next->run = 0;
        return -1;
    }
    if (next->scale == 0.0) next->scale = mean_link_length(c);
    double m2;
    int32_t p = largest_change(c, dt, threads, &m2);
    next->particle = p;
    next->run = 0;
    next->growth = 1.0;
    if (p < 0 || !isfinite(m2)) return -1;
    /* as an acceleration, so that steps of different lengths compare */
    next->change = sqrt(m2) / dt;
    change_at(c, p, dt, next->dv);
    if (g->particle < 0 || !(g->change > 0.0)) return -1;
    double ratio = next->change / g->change, before[3];
    change_at(c, g->particle, dt, before);
    int alternates = before[0] * g->dv[0] + before[1] * g->dv[1] + before[2] * g->dv[2] < 0.0;
    if (!(ratio >= GROWTH && alternates)) return -1;
    next->run = g->run + 1;
    next->growth = (g->run ? g->growth : 1.0) * ratio;
    int grown = next->run >= RUN ||
                (next->run >= MIN_RUN && next->run * log(next->growth) >= log(RUN_POWER));
    return grown && next->change * dt * dt >= FLOOR * next->scale ? p : -1;
}

static double squared_length(const double *x, const double *y, const double *z, int32_t a, int32_t b)
{
    double d[3] = {x[a] - x[b], y[a] - y[b], z[a] - z[b]};
    return d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
}

/* What wci_step_tears reads. */
typedef struct tear_pass {
    const wc_cloth *cloth;
    double ratio, growth;
} tear_pass;

/* The first link of [begin, end) that tears, or -1. */
static int32_t first_tear(const tear_pass *pass, int64_t begin, int64_t end)
{
    const wc_cloth *c = pass->cloth;
    const wc_link_set *s = &c->topology.stretch;
    for (int64_t e = begin; e < end; ++e) {
        double limit = pass->ratio * s->rest[e];
        double end2 = squared_length(c->nx, c->ny, c->nz, s->a[e], s->b[e]);
        /* the root only for the rare link past the ratio */
        if (!(end2 > limit * limit)) continue;
        double start = sqrt(squared_length(c->x, c->y, c->z, s->a[e], s->b[e]));
        if (sqrt(end2) - start > pass->growth * s->rest[e]) return (int32_t)e;
    }
    return -1;
}

static int tear_range(void *context, int64_t begin, int64_t end)
{
    return first_tear(context, begin, end) >= 0;
}

/* Every link looked at on every thread; the first that tears is looked
 * for again on one, only when some link does (a step that tears is taken
 * again as two: rare). */
int32_t wci_step_tears(const wc_cloth *c, double ratio, double growth, int threads)
{
    tear_pass pass = {c, ratio, growth};
    int64_t n = c->topology.stretch.count;
    if (!wci_parallel_for(n, wc_threads_for(n, threads), tear_range, &pass)) return -1;
    return first_tear(&pass, 0, n);
}
