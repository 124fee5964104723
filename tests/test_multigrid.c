/* The implicit integrator's coarse levels (multigrid.c), on a synthetic
 * cloth graph with the matrix form of implicit.c: a grid of particles with
 * stretch links (structural and shear) and bend links (every second
 * particle), random positive semi-definite link blocks (about a third of
 * them zero, as slack links are), masses, and a pinned row and block.
 *
 * Checked: the structure (every node in one aggregate, each level smaller
 * by the promised factor); each coarse matrix is the Galerkin product
 * P^T A P, against a product written here from the fine arrays; the
 * correction is symmetric and positive, zero at pins and the same bits for
 * 1, 2 and 4 threads; preconditioned conjugate gradients need far fewer
 * iterations with it than with block-Jacobi alone; a cloth below
 * WC_MULTIGRID_MIN_PARTICLES gets none; an allocation failure at any
 * point of the construction returns an error and leaks nothing; and in a
 * world, a stiff wet cloth steps through pin sets that empty aggregates. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "multigrid.h"
#include "scenes.h"
#include "test_util.h"
#include "wetcloth.h"

/* Deterministic random numbers (64-bit LCG), uniform in [lo, hi). */
static uint64_t rng_state = 0x9E3779B97F4A7C15ull;
static double uniform(double lo, double hi)
{
    rng_state = rng_state * 6364136223846793005ull + 1442695040888963407ull;
    return lo + (hi - lo) * (double)(rng_state >> 11) * (1.0 / 9007199254740992.0);
}

/* ------------------------------------------------------------------------ */
/* The synthetic cloth                                                      */
/* ------------------------------------------------------------------------ */

typedef struct graph {
    int32_t side, n, links, stretch;
    int32_t *end_a, *end_b, *adj_start, *adj, *pin_slot;
    double *mass, *block;
} graph;

static void add_link(graph *g, int32_t a, int32_t b)
{
    g->end_a[g->links] = a, g->end_b[g->links] = b;
    ++g->links;
}

/* side x side particles; `pins`: the first row pinned, and a 4 x 4 block
 * inside (so that some aggregates are all pinned). */
static graph make_graph(int32_t side, int pins)
{
    graph g;
    memset(&g, 0, sizeof g);
    g.side = side, g.n = side * side;
    size_t most = 6 * (size_t)g.n;
    g.end_a = malloc(most * sizeof(int32_t));
    g.end_b = malloc(most * sizeof(int32_t));
    for (int32_t y = 0; y < side; ++y)
        for (int32_t x = 0; x < side; ++x) {
            int32_t i = y * side + x;
            if (x + 1 < side) add_link(&g, i, i + 1);
            if (y + 1 < side) add_link(&g, i, i + side);
            if (x + 1 < side && y + 1 < side) add_link(&g, i, i + side + 1);
            if (x + 1 < side && y + 1 < side) add_link(&g, i + 1, i + side);
        }
    g.stretch = g.links;
    for (int32_t y = 0; y < side; ++y)
        for (int32_t x = 0; x < side; ++x) {
            int32_t i = y * side + x;
            if (x + 2 < side) add_link(&g, i, i + 2);
            if (y + 2 < side) add_link(&g, i, i + 2 * side);
        }
    g.adj_start = calloc((size_t)g.n + 1, sizeof(int32_t));
    g.adj = malloc(2 * (size_t)g.links * sizeof(int32_t));
    int32_t *fill = calloc((size_t)g.n, sizeof(int32_t));
    for (int32_t e = 0; e < g.links; ++e) ++g.adj_start[g.end_a[e] + 1], ++g.adj_start[g.end_b[e] + 1];
    for (int32_t i = 0; i < g.n; ++i) g.adj_start[i + 1] += g.adj_start[i];
    for (int32_t e = 0; e < g.links; ++e) {
        g.adj[g.adj_start[g.end_a[e]] + fill[g.end_a[e]]++] = e;
        g.adj[g.adj_start[g.end_b[e]] + fill[g.end_b[e]]++] = ~e;
    }
    free(fill);
    g.pin_slot = malloc((size_t)g.n * sizeof(int32_t));
    g.mass = malloc((size_t)g.n * sizeof(double));
    for (int32_t i = 0; i < g.n; ++i) {
        int32_t x = i % side, y = i / side;
        int pinned = pins && (y == 0 || (x >= 20 && x < 24 && y >= 30 && y < 34));
        g.pin_slot[i] = pinned ? i : -1;
        g.mass[i] = 1e-3 * (1.0 + 0.5 * sin(0.37 * i));
    }
    /* h^2 (k u u^T + 0.01 k I), h^2 k up to 0.1: stiffness up to 100 times
     * the mass, as cotton at a few hundred steps per second */
    g.block = malloc(6 * (size_t)g.links * sizeof(double));
    for (int32_t e = 0; e < g.links; ++e) {
        double u[3] = {uniform(-1, 1), uniform(-1, 1), uniform(-0.2, 0.2)};
        double len = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
        double k = uniform(0.0, 1.0) < 0.3 ? 0.0 : uniform(0.0, 0.1), c = 0.01 * k;
        for (int j = 0; j < 3; ++j) u[j] /= len;
        double *b = g.block + 6 * (size_t)e;
        b[0] = k * u[0] * u[0] + c, b[1] = k * u[0] * u[1], b[2] = k * u[0] * u[2];
        b[3] = k * u[1] * u[1] + c, b[4] = k * u[1] * u[2], b[5] = k * u[2] * u[2] + c;
    }
    return g;
}

static void free_graph(graph *g)
{
    int32_t *ints[] = {g->end_a, g->end_b, g->adj_start, g->adj, g->pin_slot};
    for (size_t k = 0; k < sizeof ints / sizeof ints[0]; ++k) free(ints[k]);
    free(g->mass);
    free(g->block);
}

static int pinned(const graph *g, int32_t i) { return g->pin_slot[i] >= 0; }

static void block_times(const double *b, const double *x, double out[3])
{
    out[0] = b[0] * x[0] + b[1] * x[1] + b[2] * x[2];
    out[1] = b[1] * x[0] + b[3] * x[1] + b[4] * x[2];
    out[2] = b[2] * x[0] + b[4] * x[1] + b[5] * x[2];
}

/* out = A in over the free particles (as implicit.c's product); in must be
 * zero at pins, out is. Written here from the fine arrays alone. */
static void fine_product(const graph *g, const double *in, double *out)
{
    for (int32_t i = 0; i < g->n; ++i) {
        double *o = out + 3 * (size_t)i;
        o[0] = o[1] = o[2] = 0.0;
        if (pinned(g, i)) continue;
        for (int j = 0; j < 3; ++j) o[j] = g->mass[i] * in[3 * (size_t)i + j];
        for (int32_t k = g->adj_start[i]; k < g->adj_start[i + 1]; ++k) {
            int32_t entry = g->adj[k], e = entry >= 0 ? entry : ~entry;
            int32_t other = entry >= 0 ? g->end_b[e] : g->end_a[e];
            double d[3], t[3];
            for (int j = 0; j < 3; ++j) d[j] = in[3 * (size_t)i + j] - in[3 * (size_t)other + j];
            block_times(g->block + 6 * (size_t)e, d, t);
            for (int j = 0; j < 3; ++j) o[j] += t[j];
        }
    }
}

/* The block-Jacobi preconditioner: inverse of each free particle's whole
 * diagonal block, computed here by Gauss-Jordan on the full 3 x 3. */
static void jacobi_blocks(const graph *g, double *inv)
{
    for (int32_t i = 0; i < g->n; ++i) {
        double *out = inv + 9 * (size_t)i;
        memset(out, 0, 9 * sizeof *out);
        if (pinned(g, i)) continue;
        double m[3][6] = {{0}};
        for (int j = 0; j < 3; ++j) m[j][j] = g->mass[i], m[j][3 + j] = 1.0;
        for (int32_t k = g->adj_start[i]; k < g->adj_start[i + 1]; ++k) {
            int32_t entry = g->adj[k], e = entry >= 0 ? entry : ~entry;
            const double *b = g->block + 6 * (size_t)e;
            double full[3][3] = {{b[0], b[1], b[2]}, {b[1], b[3], b[4]}, {b[2], b[4], b[5]}};
            for (int r = 0; r < 3; ++r)
                for (int c = 0; c < 3; ++c) m[r][c] += full[r][c];
        }
        for (int p = 0; p < 3; ++p) {
            double piv = m[p][p];
            for (int c = 0; c < 6; ++c) m[p][c] /= piv;
            for (int r = 0; r < 3; ++r) {
                if (r == p) continue;
                double f = m[r][p];
                for (int c = 0; c < 6; ++c) m[r][c] -= f * m[p][c];
            }
        }
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) out[3 * r + c] = m[r][3 + c];
    }
}

static double dot(const double *a, const double *b, size_t len)
{
    double s = 0.0;
    for (size_t k = 0; k < len; ++k) s += a[k] * b[k];
    return s;
}

static void random_free_vector(const graph *g, double *v)
{
    for (int32_t i = 0; i < g->n; ++i)
        for (int j = 0; j < 3; ++j) v[3 * (size_t)i + j] = pinned(g, i) ? 0.0 : uniform(-1, 1);
}

static wc_multigrid *build(const graph *g, int threads)
{
    wc_multigrid *mg = NULL;
    int failed = wci_multigrid_create(g->n, g->links, g->end_a, g->end_b, g->stretch, g->adj_start,
                                     g->adj, &mg);
    CHECK(!failed && mg != NULL, "create: failed %d", failed);
    if (mg) wci_multigrid_update(mg, g->mass, g->block, NULL, g->pin_slot, threads);
    return mg;
}

/* ------------------------------------------------------------------------ */
/* Tests                                                                    */
/* ------------------------------------------------------------------------ */

/* Every node has an aggregate in range, every aggregate has a node, and
 * each level keeps at most 3/4 of the nodes below it (LEAST_REDUCTION). */
static void structure(void)
{
    graph g = make_graph(80, 1);
    wc_multigrid *mg = build(&g, 1);
    if (!mg) return;
    int32_t levels = wci_multigrid_levels(mg);
    CHECK(levels >= 3, "%d levels for 6400 particles", levels);
    printf("levels for 80 x 80:");
    for (int32_t k = 0; k < levels; ++k) printf(" %d", wci_multigrid_level_size(mg, k));
    printf("\n");
    for (int32_t k = 0; k + 1 < levels; ++k) {
        int32_t n = wci_multigrid_level_size(mg, k), nc = wci_multigrid_level_size(mg, k + 1);
        CHECK(nc <= 0.75 * n && nc >= 1, "level %d: %d nodes above %d", k + 1, nc, n);
        int32_t *members = calloc((size_t)nc, sizeof *members);
        int bad = 0;
        for (int32_t i = 0; i < n; ++i) {
            int32_t a = wci_multigrid_aggregate(mg, k, i);
            if (a < 0 || a >= nc) ++bad;
            else ++members[a];
        }
        for (int32_t a = 0; a < nc; ++a) bad += members[a] == 0;
        CHECK(bad == 0, "level %d: %d nodes without an aggregate or empty aggregates", k, bad);
        free(members);
    }
    wci_multigrid_destroy(mg);
    free_graph(&g);
}

/* A coarse matrix is P^T A P: for random x on level k + 1, the level's own
 * product equals the fine product of the prolonged x summed back over each
 * aggregate (at the finest level over free particles only, and with the
 * product written in this file). The sums run in different orders, so they
 * agree to rounding: 1e-13 of the vector's norm (measured 2e-16). */
static void galerkin(void)
{
    graph g = make_graph(80, 1);
    wc_multigrid *mg = build(&g, 1);
    if (!mg) return;
    for (int32_t k = 0; k + 1 < wci_multigrid_levels(mg); ++k) {
        int32_t n = wci_multigrid_level_size(mg, k), nc = wci_multigrid_level_size(mg, k + 1);
        double *xc = malloc(3 * (size_t)nc * sizeof(double));
        double *x = calloc(3 * (size_t)n, sizeof(double)), *ax = malloc(3 * (size_t)n * sizeof(double));
        double *want = calloc(3 * (size_t)nc, sizeof(double)), *got = malloc(3 * (size_t)nc * sizeof(double));
        for (size_t j = 0; j < 3 * (size_t)nc; ++j) xc[j] = uniform(-1, 1);
        for (int32_t i = 0; i < n; ++i)
            if (k > 0 || !pinned(&g, i))
                for (int j = 0; j < 3; ++j)
                    x[3 * (size_t)i + j] = xc[3 * (size_t)wci_multigrid_aggregate(mg, k, i) + j];
        if (k == 0) fine_product(&g, x, ax);
        else wci_multigrid_level_product(mg, k, x, ax);
        for (int32_t i = 0; i < n; ++i)
            if (k > 0 || !pinned(&g, i))
                for (int j = 0; j < 3; ++j)
                    want[3 * (size_t)wci_multigrid_aggregate(mg, k, i) + j] += ax[3 * (size_t)i + j];
        wci_multigrid_level_product(mg, k + 1, xc, got);
        double err = 0.0, norm = 0.0;
        for (size_t j = 0; j < 3 * (size_t)nc; ++j)
            err += (got[j] - want[j]) * (got[j] - want[j]), norm += want[j] * want[j];
        CHECK(sqrt(err) <= 1e-13 * sqrt(norm), "level %d: |A_c x - P^T A P x| = %.3g of %.3g",
              k + 1, sqrt(err), sqrt(norm));
        printf("Galerkin product, level %d: relative difference %.2g\n", k + 1,
               sqrt(err / norm));
        free(xc), free(x), free(ax), free(want), free(got);
    }
    wci_multigrid_destroy(mg);
    free_graph(&g);
}

/* The correction M r = P C P^T r: u . M v = v . M u (symmetric, to
 * rounding), u . M u > 0, zero at pins, finite, and the same bits for 1, 2
 * and 4 threads (6400 particles: the fine loops are split). */
static void correction(void)
{
    graph g = make_graph(80, 1);
    size_t len = 3 * (size_t)g.n;
    double *u = malloc(len * sizeof(double)), *v = malloc(len * sizeof(double));
    double *mu = calloc(len, sizeof(double)), *mv = calloc(len, sizeof(double));
    random_free_vector(&g, u);
    random_free_vector(&g, v);
    wc_multigrid *mg = build(&g, 1);
    if (!mg) return;
    wci_multigrid_add_correction(mg, u, mu, 1);
    wci_multigrid_add_correction(mg, v, mv, 1);
    double uv = dot(u, mv, len), vu = dot(v, mu, len), uu = dot(u, mu, len);
    CHECK(fabs(uv - vu) <= 1e-12 * sqrt(dot(u, u, len) * dot(mv, mv, len)),
          "u.Mv %.17g, v.Mu %.17g", uv, vu);
    CHECK(uu > 0.0, "u.Mu = %g", uu);
    int at_pins = 0, finite = 1;
    for (int32_t i = 0; i < g.n; ++i)
        for (int j = 0; j < 3; ++j) {
            finite &= isfinite(mu[3 * (size_t)i + j]) != 0;
            at_pins += pinned(&g, i) && mu[3 * (size_t)i + j] != 0.0;
        }
    CHECK(finite && at_pins == 0, "finite %d, %d nonzero values at pins", finite, at_pins);
    printf("correction: u.Mv %.6g, v.Mu %.6g, u.Mu %.6g\n", uv, vu, uu);
    for (int threads = 2; threads <= 4; threads += 2) {
        wc_multigrid *other = build(&g, threads);
        double *mt = calloc(len, sizeof(double));
        wci_multigrid_add_correction(other, u, mt, threads);
        CHECK(memcmp(mt, mu, len * sizeof(double)) == 0, "%d threads: other bits", threads);
        free(mt);
        wci_multigrid_destroy(other);
    }
    wci_multigrid_destroy(mg);
    free(u), free(v), free(mu), free(mv);
    free_graph(&g);
}

/* Preconditioned conjugate gradients on A y = b to |r| <= 1e-8 |b|, as
 * implicit.c solves; returns the iterations. */
static int pcg(const graph *g, const double *jacobi, wc_multigrid *mg, const double *b)
{
    size_t len = 3 * (size_t)g->n;
    double *y = calloc(len, sizeof(double)), *r = malloc(len * sizeof(double));
    double *z = malloc(len * sizeof(double)), *p = calloc(len, sizeof(double));
    double *q = malloc(len * sizeof(double));
    memcpy(r, b, len * sizeof(double));
    double bb = dot(b, b, len), rr = bb, rz = 0.0;
    int it = 0;
    for (; it < 5000 && rr > 1e-16 * bb; ++it) {
        for (int32_t i = 0; i < g->n; ++i) {
            const double *m = jacobi + 9 * (size_t)i, *ri = r + 3 * (size_t)i;
            for (int j = 0; j < 3; ++j)
                z[3 * (size_t)i + j] = m[3 * j] * ri[0] + m[3 * j + 1] * ri[1] + m[3 * j + 2] * ri[2];
        }
        if (mg) wci_multigrid_add_correction(mg, r, z, 1);
        double rz_next = dot(r, z, len);
        for (size_t k = 0; k < len; ++k) p[k] = z[k] + (it ? rz_next / rz : 0.0) * p[k];
        rz = rz_next;
        fine_product(g, p, q);
        double alpha = rz / dot(p, q, len);
        for (size_t k = 0; k < len; ++k) y[k] += alpha * p[k], r[k] -= alpha * q[k];
        rr = dot(r, r, len);
    }
    free(y), free(r), free(z), free(p), free(q);
    return it;
}

/* The point of it all: far fewer iterations. On this 6400-particle graph
 * block-Jacobi needs 2.6 times as many as block-Jacobi with the coarse
 * correction unpinned, 2.3 times pinned (174 / 67 and 172 / 76); the test
 * asks for at least 2 times. */
static void fewer_iterations(void)
{
    for (int pins = 0; pins <= 1; ++pins) {
        graph g = make_graph(80, pins);
        double *jacobi = malloc(9 * (size_t)g.n * sizeof(double));
        double *b = malloc(3 * (size_t)g.n * sizeof(double));
        jacobi_blocks(&g, jacobi);
        random_free_vector(&g, b);
        wc_multigrid *mg = build(&g, 1);
        if (!mg) return;
        int plain = pcg(&g, jacobi, NULL, b), with = pcg(&g, jacobi, mg, b);
        printf("conjugate gradients, 80 x 80, pins %d: %d iterations with block-Jacobi, %d with "
               "the coarse levels\n", pins, plain, with);
        CHECK(plain < 5000 && 2 * with <= plain, "pins %d: %d against %d iterations", pins, with,
              plain);
        wci_multigrid_destroy(mg);
        free(jacobi), free(b);
        free_graph(&g);
    }
}

/* Below WC_MULTIGRID_MIN_PARTICLES: no coarse levels, no error. */
static void small_cloth(void)
{
    graph g = make_graph(60, 0); /* 3600 particles */
    wc_multigrid *mg = (wc_multigrid *)&g;
    int failed = wci_multigrid_create(g.n, g.links, g.end_a, g.end_b, g.stretch, g.adj_start, g.adj,
                                     &mg);
    CHECK(!failed && mg == NULL, "3600 particles: failed %d, hierarchy %p", failed, (void *)mg);
    free_graph(&g);
}

/* Allocation failures: the hook fails its k-th call, for every k the
 * construction makes; create returns 1, sets NULL and frees everything. */
static long g_allocs, g_live, g_fail_at = -1;
static void *counting_alloc(size_t size, void *user)
{
    (void)user;
    if (g_allocs++ == g_fail_at) return NULL;
    ++g_live;
    return malloc(size);
}
static void counting_free(void *memory, void *user)
{
    (void)user;
    --g_live;
    free(memory);
}

static void out_of_memory(void)
{
    graph g = make_graph(70, 1);
    wc_set_allocator(counting_alloc, counting_free, NULL);
    wc_multigrid *mg = NULL;
    g_allocs = 0, g_live = 0, g_fail_at = -1;
    int failed = wci_multigrid_create(g.n, g.links, g.end_a, g.end_b, g.stretch, g.adj_start, g.adj,
                                     &mg);
    long needed = g_allocs;
    CHECK(!failed && mg, "without failures: failed %d", failed);
    wci_multigrid_destroy(mg);
    CHECK(g_live == 0, "%ld blocks live after destroy", g_live);
    int wrong = 0;
    for (long k = 0; k < needed; ++k) {
        g_allocs = 0, g_live = 0, g_fail_at = k;
        mg = (wc_multigrid *)&g;
        failed = wci_multigrid_create(g.n, g.links, g.end_a, g.end_b, g.stretch, g.adj_start, g.adj,
                                     &mg);
        if (failed != 1 || mg != NULL || g_live != 0) {
            if (wrong++ < 5)
                CHECK(0, "failing allocation %ld: returned %d, hierarchy %p, %ld blocks live", k,
                      failed, (void *)mg, g_live);
        }
    }
    CHECK(wrong == 0, "%d of %ld failing allocations mishandled", wrong, needed);
    printf("out of memory at each of the %ld allocations: all handled\n", needed);
    wc_set_allocator(NULL, NULL, NULL);
    g_fail_at = -1;
    free_graph(&g);
}

/* In a world: a 64 x 64 implicit cloth (4096 particles, the smallest with
 * coarse levels), stiff (1e9 N/m, the largest stretch stiffness allowed)
 * and wet, on the thesis sphere, through pin sets that empty whole
 * aggregates: all but one particle pinned, all pinned, none. Every step
 * succeeds, stays finite, and solves (iterations reported) whenever a
 * particle is free. */
static void in_a_world(void)
{
    wc_world_def def = wc_world_def_default();
    def.integrator = WC_INTEGRATOR_IMPLICIT;
    def.thread_count = 2;
    wc_world *w = scene_world_from(&def);
    scene_add_thesis_sphere(w, 0.3);
    wc_grid_cloth_def g = wc_grid_cloth_def_default();
    g.count_u = g.count_v = 64;
    g.center[2] = 0.32;
    g.material.stretch_stiffness = 1e9;
    g.wetness = 1.0;
    int32_t id = scene_add_grid(w, &g), n = wc_cloth_particle_count(w, id);
    int32_t *all = malloc((size_t)n * sizeof *all);
    for (int32_t i = 0; i < n; ++i) all[i] = i;
    double *x = malloc(3 * (size_t)n * sizeof *x);
    for (int phase = 0; phase < 3; ++phase) {
        wc_cloth_unpin_all(w, id);
        if (phase == 0) wc_cloth_pin(w, id, all + 1, n - 1);
        if (phase == 1) wc_cloth_pin(w, id, all, n);
        int64_t iterations = 0;
        for (int f = 0; f < 3; ++f) {
            wc_status st = wc_world_advance(w, 1.0 / 24, 6);
            CHECK(st == WC_OK, "phase %d frame %d: %s", phase, f, wc_world_last_error(w));
            iterations += wc_world_get_stats(w).solver_iterations;
        }
        wc_cloth_get_positions(w, id, x, n);
        int finite = 1;
        for (size_t k = 0; k < 3 * (size_t)n; ++k) finite &= isfinite(x[k]) != 0;
        CHECK(finite, "phase %d: positions not finite", phase);
        CHECK(phase == 1 ? iterations == 0 : iterations > 0, "phase %d: %lld iterations", phase,
              (long long)iterations);
        printf("64 x 64 at 1e9 N/m, %s pinned: %lld iterations over 18 steps\n",
               phase == 0 ? "all but one" : phase == 1 ? "all" : "none", (long long)iterations);
    }
    free(all), free(x);
    wc_world_destroy(w);
}

int main(void)
{
    structure();
    galerkin();
    correction();
    fewer_iterations();
    small_cloth();
    out_of_memory();
    in_a_world();
    return test_report("test_multigrid");
}
