#include "implicit.h"

#include <math.h>
#include <string.h>

#include "alloc.h"
#include "buckling.h"
#include "integrate.h"
#include "invariant.h"
#include "multigrid.h"
#include "parallel.h"
#include "primitives.h"

/* The solve stops when |r| <= CG_TOLERANCE |b|. The right-hand side is the
 * step's momentum change h f; 1e-8 of it leaves velocity errors far below
 * what the step's own O(h) error is (tests/test_integrators.c: free fall
 * within 1e-7 of the closed form's lag), at a few tens of iterations on
 * cotton-like cloth. */
#define CG_TOLERANCE 1e-8
/* The tolerance's estimate of the current error sums the energy-norm
 * decreases of this many last iterations. CG lowers the squared energy
 * norm of its error by exactly alpha_j r_j.z_j at iteration j, so the
 * error of iterate k is the sum over all j >= k (Hestenes & Stiefel 1952;
 * Strakos & Tichy 2002); the last few terms bound that of the iterate this
 * many steps back from below, and the current iterate's error is smaller
 * than that one's. Each unit of delay costs one iteration; 4, 8 and 16
 * gave the same drape error (docs/model.md), and 8 keeps the true error
 * of the test's stretched cloth at half the tolerance (4: 0.95 of it), a
 * margin for solves whose error decrease stalls for a few iterations. */
#define ESTIMATE_DELAY 8
/* A cap for pathological systems; the step uses the last iterate, which is
 * still a descent toward the solution. */
#define CG_MAX_ITERATIONS 1000
/* Dot products sum fixed blocks of this many particles, then the blocks in
 * order: the same rounding for any thread count. */
#define BLOCK 512
/* The links are marked and placed in chunks of this many (owner_order):
 * each chunk's count, then its places from their running sum, so that both
 * loops split across threads and the places are the same for any count. */
#define PLACE_CHUNK 2048
/* The sets of partial sums: r . r (and b . b), p . A p, r . z, and the
 * residual's x, y and z summed over the particles (the translation's share
 * of it, for a cloth without coarse levels). */
#define PARTIAL_RR 0
#define PARTIAL_PQ 1
#define PARTIAL_RZ 2
#define PARTIAL_RX 3
#define PARTIAL_SETS 6

struct wc_implicit_state {
    int32_t n, links, blocks;
    /// Ends of each link, stretch links first, then bend links.
    int32_t *end_a, *end_b;
    /// The links ordered by their lower-numbered end, then by index: the
    /// order of their places among the active links (below), so that the
    /// product's pass over the links walks the particles once, in order,
    /// and a thread's share of the links is mostly those of the particles
    /// whose rows it sums (in index order, stretch links then bend links,
    /// each thread's links reached over every particle: 2 threads took
    /// 156-159 ms per frame on the 10,201-particle drape against 142-146
    /// in this order; 1 thread the same).
    int32_t *owner_order;
    /// Per PLACE_CHUNK links of owner_order: how many have a block this
    /// step, then where the chunk's places start.
    int32_t chunks, *chunk_start;
    /// Per particle: m + h drag A (the diagonal of M - h df/dv from drag),
    /// and the inverse of the whole 3 x 3 diagonal block (6 values).
    double *mass_diag, *precond;
    /// 3n vectors, xyz interleaved: start velocity, known dv of pins,
    /// right-hand side, solution, residual (two: an iteration writes the
    /// new one while the coarse levels read the old one), preconditioned
    /// residual, search direction, matrix times direction.
    double *v0, *fixed, *rhs, *y, *r, *r_next, *z, *p, *q;
    /// Per block, the sums of the dot products and of the residual: sets
    /// (PARTIAL_*) of their own, so
    /// that a thread that starts the next sum cannot overwrite one that
    /// another thread has not yet added up.
    double *partial;
    /// The links with a block in this step (not a slack stretch link
    /// without a dashpot, not a bend link that is not compressed: those
    /// would add exact zeros), in owner_order: `active_count` of them, each
    /// with its index and ends and, packed, its block B = share h^2 K + h c
    /// u u^T (xx, xy, xz, yy, yz, zz) and K (v0_a - v0_b), K = -df_a/dx_a,
    /// so that an iteration reads them in one sweep of memory; per link its
    /// place among them (`active_slot`, -1 for none); and per particle the
    /// entries of its link list (cloth.h) that refer to them, in the list's
    /// order, at the list's own offsets (`row_count` of them), as places
    /// (slot k, ~k at its second end). A link without a block is never
    /// written: the product, the right-hand side and the coarse levels
    /// visit only these.
    int32_t active_count, *active_slot, *active_link, *active_a, *active_b, *row_list, *row_count;
    double *active_block, *active_kv;
    /// Per active link, its block as the product applies it, B d = w (w .
    /// d) + beta d: w = sqrt(share h^2 along + h c) u and beta = share h^2
    /// across (4 values). The loop that reads them every iteration is bound
    /// by reading memory, and four numbers are two thirds of six (3-4 % less
    /// time per frame on the 10,201-particle drape, alternated).
    double *active_wb;
    /// Per active link, scratch of the product with the matrix:
    /// B (in_a - in_b).
    double *link_product;
    /// The preconditioner's coarse levels; NULL for a cloth too small to
    /// gain from them (multigrid.h).
    wc_multigrid *multigrid;
    /// Without coarse levels: the inverse of the matrix's restriction to
    /// the translations of the free particles together (6 values), with
    /// which the preconditioner solves for the cloth's motion as a whole.
    double translation_inverse[6];
    int32_t last_iterations;
    double last_residual;
};

/* s->owner_order: a counting sort of the links by their lower end,
 * stable in link index. Returns 1 when out of memory. */
static int order_by_owner(wc_implicit_state *s)
{
    int32_t *start = wci_alloc_array((size_t)s->n + 1, sizeof *start);
    if (!start) return 1;
    for (int32_t e = 0; e < s->links; ++e) {
        int32_t owner = s->end_a[e] < s->end_b[e] ? s->end_a[e] : s->end_b[e];
        start[owner + 1]++;
    }
    for (int32_t i = 0; i < s->n; ++i) start[i + 1] += start[i];
    for (int32_t e = 0; e < s->links; ++e) {
        int32_t owner = s->end_a[e] < s->end_b[e] ? s->end_a[e] : s->end_b[e];
        s->owner_order[start[owner]++] = e;
    }
    wci_free(start);
    return 0;
}

void wci_implicit_state_destroy(wc_implicit_state *s)
{
    if (!s) return;
    double *arrays[] = {s->mass_diag, s->precond, s->v0, s->fixed, s->rhs,
                        s->y, s->r, s->r_next, s->z, s->p, s->q, s->partial,
                        s->link_product, s->active_block, s->active_kv, s->active_wb};
    for (size_t i = 0; i < sizeof arrays / sizeof arrays[0]; ++i) wci_free(arrays[i]);
    wci_free(s->end_a);
    wci_free(s->end_b);
    wci_free(s->owner_order);
    wci_free(s->chunk_start);
    wci_free(s->active_slot);
    wci_free(s->active_link);
    wci_free(s->active_a);
    wci_free(s->active_b);
    wci_free(s->row_list);
    wci_free(s->row_count);
    wci_multigrid_destroy(s->multigrid);
    wci_free(s);
}

wc_implicit_state *wci_implicit_state_create(const wc_cloth *c)
{
    wc_implicit_state *s = wci_alloc_array(1, sizeof *s);
    if (!s) return NULL;
    const wc_link_set *st = &c->topology.stretch, *bd = &c->topology.bend;
    size_t n = (size_t)c->particle_count, links = (size_t)st->count + (size_t)bd->count;
    s->n = c->particle_count;
    s->links = (int32_t)links;
    s->blocks = (int32_t)((n + BLOCK - 1) / BLOCK);
    s->end_a = wci_alloc_array(links, sizeof *s->end_a);
    s->end_b = wci_alloc_array(links, sizeof *s->end_b);
    s->owner_order = wci_alloc_array(links + 1, sizeof *s->owner_order);
    s->chunks = (int32_t)((links + PLACE_CHUNK - 1) / PLACE_CHUNK);
    s->chunk_start = wci_alloc_array((size_t)s->chunks + 1, sizeof *s->chunk_start);
    s->mass_diag = wci_alloc_array(n, sizeof(double));
    s->precond = wci_alloc_array(6 * n, sizeof(double));
    double **vectors[] = {&s->v0, &s->fixed, &s->rhs, &s->y, &s->r,
                          &s->r_next, &s->z, &s->p, &s->q};
    int ok = 1;
    for (size_t i = 0; i < sizeof vectors / sizeof vectors[0]; ++i)
        ok &= (*vectors[i] = wci_alloc_array(3 * n, sizeof(double))) != NULL;
    s->partial = wci_alloc_array(PARTIAL_SETS * (size_t)s->blocks, sizeof(double));
    s->link_product = wci_alloc_array(3 * links + 1, sizeof(double));
    s->active_slot = wci_alloc_array(links + 1, sizeof *s->active_slot);
    s->active_link = wci_alloc_array(links + 1, sizeof *s->active_link);
    s->active_a = wci_alloc_array(links + 1, sizeof *s->active_a);
    s->active_b = wci_alloc_array(links + 1, sizeof *s->active_b);
    s->active_block = wci_alloc_array(6 * links + 1, sizeof(double));
    s->active_kv = wci_alloc_array(3 * links + 1, sizeof(double));
    s->active_wb = wci_alloc_array(4 * links + 1, sizeof(double));
    s->row_list = wci_alloc_array((size_t)c->link_start[n] + 1, sizeof *s->row_list);
    s->row_count = wci_alloc_array(n + 1, sizeof *s->row_count);
    if (!ok || !s->end_a || !s->end_b || !s->owner_order || !s->chunk_start || !s->mass_diag ||
        !s->precond || !s->partial || !s->link_product || !s->active_slot || !s->active_link ||
        !s->active_a || !s->active_b || !s->active_block || !s->active_kv || !s->active_wb ||
        !s->row_list || !s->row_count) {
        wci_implicit_state_destroy(s);
        return NULL;
    }
    for (int32_t e = 0; e < st->count; ++e) s->end_a[e] = st->a[e], s->end_b[e] = st->b[e];
    for (int32_t e = 0; e < bd->count; ++e)
        s->end_a[st->count + e] = bd->a[e], s->end_b[st->count + e] = bd->b[e];
    if (order_by_owner(s)) {
        wci_implicit_state_destroy(s);
        return NULL;
    }
    if (wci_multigrid_create(s->n, s->links, s->end_a, s->end_b, st->count, c->link_start,
                            c->link_list, &s->multigrid)) {
        wci_implicit_state_destroy(s);
        return NULL;
    }
    return s;
}

int32_t wci_implicit_last_iterations(const wc_implicit_state *s) { return s->last_iterations; }
double wci_implicit_last_residual(const wc_implicit_state *s) { return s->last_residual; }

/* d|f|/d(compression) of the ramped buckling force, N/m, >= 0 (the force
 * grows as the link shortens): the axial stiffness of a compressed bend
 * link. From the same table as the force: dPhi/dgap is the derivative of
 * the piece's polynomial. In the onset ramp the force is linear in the gap. */
static double buckling_slope(double d, double l, double R)
{
    double gap = (l - d) / l;
    if (!(gap > 0.0)) return 0.0;
    if (gap < WC_BUCKLING_ONSET_RAMP)
        return R / (l * l * l) * wc_buckling_phi_of_gap(WC_BUCKLING_ONSET_RAMP) / WC_BUCKLING_ONSET_RAMP;
    double scaled = gap * WC_BUCKLING_PIECES;
    if (scaled > WC_BUCKLING_PIECES) scaled = WC_BUCKLING_PIECES;
    int k = (int)scaled;
    if (k == WC_BUCKLING_PIECES) k = WC_BUCKLING_PIECES - 1;
    const double *coef = wc_buckling_table[k];
    double t = scaled - k, slope = WC_BUCKLING_DEGREE * coef[WC_BUCKLING_DEGREE];
    for (int i = WC_BUCKLING_DEGREE - 1; i >= 1; --i) slope = slope * t + i * coef[i];
    slope *= WC_BUCKLING_PIECES;
    return slope > 0.0 ? R / (l * l * l) * slope : 0.0;
}

/* What the loops of one step need, each a part of it: the loops run
 * through wci_parallel_for (parallel.h), which passes one pointer. */
typedef struct implicit_pass {
    const wc_cloth *cloth;
    wc_implicit_state *state;
    double h, pin_fraction;
    /* the part of the velocity change that the positions take: x+ = x + h
     * (v0 + share dv), share = (h + h_prev) / 2h (see wci_integrate_implicit) */
    double share;
    /* apply: out = A in; updates: the factor */
    const double *in;
    double *out;
    double factor;
    /* precondition: the coarse levels' solution per aggregate and each
     * particle's aggregate, NULL without coarse levels */
    const double *coarse;
    const int32_t *aggregate;
    /* where a summing loop puts its per-block sums, and where the loops that
     * make a residual put its components' sums (NULL: not needed) */
    double *partial, *residual_sums;
    /* precondition, without coarse levels: the translation's correction,
     * added at every free particle */
    double translation[3];
    /* the solve's residual and where its update goes (they swap) */
    double *r, *r_next;
} implicit_pass;

static void set_block(double *b, double along, double across, double ux, double uy, double uz)
{
    /* along u u^T + across I */
    b[0] = along * ux * ux + across, b[1] = along * ux * uy, b[2] = along * ux * uz;
    b[3] = along * uy * uy + across, b[4] = along * uy * uz, b[5] = along * uz * uz + across;
}

/* Each link's stiffness block K = -df_a/dx_a and B = share h^2 K + h C:
 *   stretch, taut (d > l): K = k [(l/d) u u^T + (1 - l/d) I], positive
 *     definite; slack: none (tension only);
 *   bend, compressed: K = k_b u u^T with k_b the buckling force's slope;
 *     the transverse term -(f/d)(I - u u^T) is left out: the force pushes
 *     the ends apart, so that term is negative and would make M - h^2 df/dx
 *     indefinite (Choi & Ko 2002, section 4.2);
 *   stretch dashpots: C = c u u^T, taut or slack, as in forces.c. */
/* d^2 > STRETCHED_CLEARLY l^2 means d > l whatever the rounding of d^2,
 * l^2 and sqrt (each within a relative 2^-52 or so): a bend link that
 * passes it is longer than at rest, and not compressed. */
#define STRETCHED_CLEARLY (1.0 + 1e-9)

/* Whether link e has a block this step, from its squared length d2: a
 * stretch link that has a dashpot or is taut, a bend link that is
 * compressed. d2 decides where that is clear whatever the rounding, the
 * length itself (as the blocks compute it) where it is not. */
static int link_has_block(const wc_cloth *c, int64_t e, double d2)
{
    const wc_link_set *st = &c->topology.stretch, *bd = &c->topology.bend;
    if (e < st->count) {
        if (!(d2 > 0.0)) return 0;
        if (c->stretch_c && c->stretch_c[e] != 0.0) return 1;
        return sqrt(d2) > st->rest[e];
    }
    double l = bd->rest[e - st->count];
    if (d2 > STRETCHED_CLEARLY * l * l) return 0;
    double d = sqrt(d2);
    return d > 0.0 && l - d > 0.0;
}

static void chunk_bounds(const wc_implicit_state *s, int64_t chunk, int64_t *begin, int64_t *end)
{
    *begin = chunk * PLACE_CHUNK;
    *end = *begin + PLACE_CHUNK < s->links ? *begin + PLACE_CHUNK : s->links;
}

/* Marks the links of chunks [first, last) of owner_order that have a block
 * (active_slot 1, else -1) and counts them per chunk. */
static int mark_links_range(void *context, int64_t first, int64_t last)
{
    const implicit_pass *pass = context;
    const wc_cloth *c = pass->cloth;
    wc_implicit_state *s = pass->state;
    for (int64_t chunk = first; chunk < last; ++chunk) {
        int64_t begin, end;
        chunk_bounds(s, chunk, &begin, &end);
        int32_t count = 0;
        for (int64_t k = begin; k < end; ++k) {
            int32_t e = s->owner_order[k], a = s->end_a[e], b = s->end_b[e];
            double dx = c->x[a] - c->x[b], dy = c->y[a] - c->y[b], dz = c->z[a] - c->z[b];
            int on = link_has_block(c, e, dx * dx + dy * dy + dz * dz);
            s->active_slot[e] = on ? 1 : -1;
            count += on;
        }
        s->chunk_start[chunk + 1] = count;
    }
    return 0;
}

/* The marked links' places, in owner_order, with their index and ends,
 * for chunks [first, last) (chunk_start made). */
static int place_links_range(void *context, int64_t first, int64_t last)
{
    wc_implicit_state *s = ((const implicit_pass *)context)->state;
    for (int64_t chunk = first; chunk < last; ++chunk) {
        int64_t begin, end;
        chunk_bounds(s, chunk, &begin, &end);
        int32_t slot = s->chunk_start[chunk];
        for (int64_t k = begin; k < end; ++k) {
            int32_t e = s->owner_order[k];
            if (s->active_slot[e] < 0) continue;
            s->active_slot[e] = slot;
            s->active_link[slot] = e;
            s->active_a[slot] = s->end_a[e], s->active_b[slot] = s->end_b[e];
            ++slot;
        }
    }
    return 0;
}

/* Links per batch of link_blocks_range: its loops are split so that each
 * has a short body, and the square roots and divisions of a batch's links
 * overlap instead of each link waiting on its own (the forces' bend loop
 * does the same, forces.c). */
#define LINK_BATCH 64

/* A batch's lengths and their reciprocals, and per link its stiffness along
 * u, across and its dashpot. */
typedef struct link_batch {
    double d[LINK_BATCH], inv[LINK_BATCH], along[LINK_BATCH], across[LINK_BATCH];
    double damp[LINK_BATCH], root[LINK_BATCH];
} link_batch;

/* Active link k's kv = K (v0_a - v0_b), K = along u u^T + across I, and
 * its block B = (hh along + h damp) u u^T + hh across I, as six values and
 * as w and beta (active_wb; root = sqrt(hh along + h damp)). */
static void put_link(wc_implicit_state *s, int64_t k, double along, double across, double damp,
                     double root, double hh, double h, const double u[3], const double dv[3])
{
    double *blk = s->active_block + 6 * (size_t)k, *kv = s->active_kv + 3 * (size_t)k;
    double *wb = s->active_wb + 4 * (size_t)k;
    wb[0] = root * u[0], wb[1] = root * u[1], wb[2] = root * u[2], wb[3] = hh * across;
    double along_dv = along * (u[0] * dv[0] + u[1] * dv[1] + u[2] * dv[2]);
    kv[0] = along_dv * u[0] + across * dv[0];
    kv[1] = along_dv * u[1] + across * dv[1];
    kv[2] = along_dv * u[2] + across * dv[2];
    set_block(blk, hh * along + h * damp, hh * across, u[0], u[1], u[2]);
}

/* Active link k's vector x_a - x_b. */
static void link_vector(const wc_cloth *c, const wc_implicit_state *s, int64_t k, double v[3])
{
    int32_t a = s->active_a[k], b = s->active_b[k];
    v[0] = c->x[a] - c->x[b], v[1] = c->y[a] - c->y[b], v[2] = c->z[a] - c->z[b];
}

/* The stiffness of active links [first, first + count) into the batch: for
 * a stretch link, l/d from the reciprocal of its length; a bend link whose
 * buckling slope is not positive (the force's polynomial flattening) gets
 * a zero block, which adds exact zeros. */
static void batch_stiffness(const implicit_pass *pass, int64_t first, int count, link_batch *t)
{
    const wc_cloth *c = pass->cloth;
    const wc_implicit_state *s = pass->state;
    const wc_link_set *st = &c->topology.stretch, *bd = &c->topology.bend;
    for (int j = 0; j < count; ++j) {
        double v[3];
        link_vector(c, s, first + j, v);
        t->d[j] = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    }
    for (int j = 0; j < count; ++j) t->inv[j] = 1.0 / t->d[j];
    for (int j = 0; j < count; ++j) {
        int32_t e = s->active_link[first + j];
        double d = t->d[j], along = 0.0, across = 0.0, damp = 0.0;
        if (e < st->count) {
            double l = st->rest[e], k_e = c->stretch_k[e];
            if (d > l) {
                double ratio = l * t->inv[j];
                along = k_e * ratio, across = k_e * (1.0 - ratio);
            }
            if (c->stretch_c) damp = c->stretch_c[e];
        } else {
            int32_t f = e - st->count;
            along = buckling_slope(d, bd->rest[f], c->bend_r[f]);
        }
        t->along[j] = along, t->across[j] = across, t->damp[j] = damp;
    }
}

/* The blocks of the active links [begin, end) (places), a batch at a time. */
static int link_blocks_range(void *context, int64_t begin, int64_t end)
{
    const implicit_pass *pass = context;
    const wc_cloth *c = pass->cloth;
    wc_implicit_state *s = pass->state;
    double h = pass->h, hh = pass->share * h * h;
    const double *v0 = s->v0;
    link_batch t;
    for (int64_t first = begin; first < end; first += LINK_BATCH) {
        int count = end - first < LINK_BATCH ? (int)(end - first) : LINK_BATCH;
        batch_stiffness(pass, first, count, &t);
        for (int j = 0; j < count; ++j) t.root[j] = sqrt(hh * t.along[j] + h * t.damp[j]);
        for (int j = 0; j < count; ++j) {
            int64_t k = first + j;
            int32_t a = s->active_a[k], b = s->active_b[k];
            double v[3];
            link_vector(c, s, k, v);
            double u[3] = {v[0] * t.inv[j], v[1] * t.inv[j], v[2] * t.inv[j]};
            double dv[3] = {v0[3 * (size_t)a] - v0[3 * (size_t)b],
                            v0[3 * (size_t)a + 1] - v0[3 * (size_t)b + 1],
                            v0[3 * (size_t)a + 2] - v0[3 * (size_t)b + 2]};
            put_link(s, k, t.along[j], t.across[j], t.damp[j], t.root[j], hh, h, u, dv);
        }
    }
    return 0;
}

/* Each particle's entries of the links with a block, in its list's order,
 * as their places among the active links. */
static int rows_range(void *context, int64_t begin, int64_t end)
{
    const implicit_pass *pass = context;
    const wc_cloth *c = pass->cloth;
    wc_implicit_state *s = pass->state;
    for (int64_t i = begin; i < end; ++i) {
        int32_t *row = s->row_list + c->link_start[i], count = 0;
        for (int32_t k = c->link_start[i]; k < c->link_start[i + 1]; ++k) {
            int32_t entry = c->link_list[k];
            int32_t slot = s->active_slot[entry >= 0 ? entry : ~entry];
            if (slot >= 0) row[count++] = entry >= 0 ? slot : ~slot;
        }
        s->row_count[i] = count;
    }
    return 0;
}

/* The step's links: which have a block, their places and rows, and their
 * blocks, written at their places. */
static void active_links(const implicit_pass *pass, int threads)
{
    wc_implicit_state *s = pass->state;
    int chunk_threads = wc_threads_for(s->links, threads);
    wci_parallel_for(s->chunks, chunk_threads, mark_links_range, (void *)pass);
    s->chunk_start[0] = 0;
    for (int32_t k = 0; k < s->chunks; ++k) s->chunk_start[k + 1] += s->chunk_start[k];
    s->active_count = s->chunk_start[s->chunks];
    wci_parallel_for(s->chunks, chunk_threads, place_links_range, (void *)pass);
    wci_parallel_for(s->active_count, wc_threads_for(s->active_count, threads),
                     link_blocks_range, (void *)pass);
    wci_parallel_for(s->n, wc_threads_for(s->n, threads), rows_range, (void *)pass);
}

/* Start velocity (as forces.c computes it) and, for pins, the known change
 * of velocity that takes them to their targets. */
static int start_velocities_range(void *context, int64_t begin, int64_t end)
{
    const implicit_pass *pass = context;
    const wc_cloth *c = pass->cloth;
    wc_implicit_state *s = pass->state;
    double h = pass->h, pin_fraction = pass->pin_fraction;
    int first = !c->has_history;
    double inv_prev = first ? 0.0 : 1.0 / c->dt_prev;
    for (int64_t i = begin; i < end; ++i) {
        double *v = s->v0 + 3 * (size_t)i, *fx = s->fixed + 3 * (size_t)i;
        if (first) {
            v[0] = c->px[i], v[1] = c->py[i], v[2] = c->pz[i];
        } else {
            v[0] = (c->x[i] - c->px[i]) * inv_prev;
            v[1] = (c->y[i] - c->py[i]) * inv_prev;
            v[2] = (c->z[i] - c->pz[i]) * inv_prev;
        }
        fx[0] = fx[1] = fx[2] = 0.0;
        if (c->pin_slot[i] >= 0) {
            double p[3];
            wci_pinned_position(c, c->pin_slot[i], pin_fraction, p);
            double share = pass->share;
            fx[0] = ((p[0] - c->x[i]) / h - v[0]) / share;
            fx[1] = ((p[1] - c->y[i]) / h - v[1]) / share;
            fx[2] = ((p[2] - c->z[i]) / h - v[2]) / share;
        }
    }
    return 0;
}

/* A soft pin's goal spring k = m s, N/m (applied.c), or 0 for a particle
 * without one; soft_pin_slot is NULL when the cloth has no soft pin. */
static double goal_stiffness(const wc_cloth *c, const int32_t *soft_pin_slot, int64_t i)
{
    if (!soft_pin_slot || soft_pin_slot[i] < 0) return 0.0;
    return c->mass[i] * c->pins.stiffness[soft_pin_slot[i]];
}

/* Per free particle, gathered over its links in their fixed order: the
 * right-hand side h f_i + h^2 (df/dx v0)_i plus what the pins' known dv
 * contribute, and the preconditioner (the inverse diagonal block). Pinned
 * rows are zero: their dv is known, not solved for. A soft pin's goal
 * spring, -k (x - T) with df/dx = -k I, enters as a link to a fixed point
 * does: share h^2 k on the diagonal (in mass_diag, which the product and
 * the coarse levels read) and -h^2 k v0 on the right-hand side; its force
 * at x, toward the target at the step's end, is already in f. */
static int rhs_and_preconditioner_range(void *context, int64_t begin, int64_t end)
{
    const implicit_pass *pass = context;
    const wc_cloth *c = pass->cloth;
    wc_implicit_state *s = pass->state;
    double h = pass->h, drag = c->material.air_drag, h2 = h * h;
    const int32_t *soft = c->pins.soft_count ? c->soft_pin_slot : NULL;
    int bad = 0;
    for (int64_t i = begin; i < end; ++i) {
        double *b = s->rhs + 3 * (size_t)i, *pre = s->precond + 6 * (size_t)i;
        if (c->pin_slot[i] >= 0) {
            b[0] = b[1] = b[2] = 0.0;
            for (int k = 0; k < 6; ++k) pre[k] = 0.0;
            continue;
        }
        double md = c->mass[i] + (drag > 0.0 ? h * drag * c->topology.area[i] : 0.0);
        double bx = h * c->fx[i], by = h * c->fy[i], bz = h * c->fz[i];
        double goal = goal_stiffness(c, soft, i);
        if (goal > 0.0) {
            const double *v = s->v0 + 3 * (size_t)i;
            md += pass->share * h2 * goal;
            bx -= h2 * goal * v[0], by -= h2 * goal * v[1], bz -= h2 * goal * v[2];
        }
        s->mass_diag[i] = md;
        double diag[6] = {md, 0.0, 0.0, md, 0.0, md};
        const int32_t *row = s->row_list + c->link_start[i];
        for (int32_t k = 0; k < s->row_count[i]; ++k) {
            int32_t entry = row[k], slot = entry >= 0 ? entry : ~entry;
            int32_t j = entry >= 0 ? s->active_b[slot] : s->active_a[slot];
            const double *blk = s->active_block + 6 * (size_t)slot;
            const double *kv = s->active_kv + 3 * (size_t)slot;
            for (int m = 0; m < 6; ++m) diag[m] += blk[m];
            double sign = entry >= 0 ? -h2 : h2;
            bx += sign * kv[0], by += sign * kv[1], bz += sign * kv[2];
            if (c->pin_slot[j] >= 0) {
                double t[3];
                const double *fj = s->fixed + 3 * (size_t)j;
                wc_sym3_times(blk, fj[0], fj[1], fj[2], t);
                bx += t[0], by += t[1], bz += t[2];
            }
        }
        b[0] = bx, b[1] = by, b[2] = bz;
        bad = bad || !(isfinite(bx) && isfinite(by) && isfinite(bz));
        wci_sym3_inverse(diag, pre);
    }
    return bad;
}

/* The loops of one CG iteration run over fixed blocks of BLOCK particles,
 * each block on one thread, and the dot products the iteration needs are
 * summed inside the loops that make their operands: each block's sum in
 * particle order into partial[block], then the blocks in order (block_sum).
 * The same rounding for any thread count, and one pass over the vectors
 * fewer per dot product. */
static void block_bounds(const wc_implicit_state *s, int64_t block, int64_t *begin, int64_t *end)
{
    *begin = block * BLOCK;
    *end = *begin + BLOCK < s->n ? *begin + BLOCK : s->n;
}

static double block_sum(const wc_implicit_state *s, const double *partial)
{
    double total = 0.0;
    for (int32_t k = 0; k < s->blocks; ++k) total += partial[k];
    return total;
}

/* The product's first pass, per link: B (in_a - in_b) = w (w . d) + beta
 * d (active_wb). Each link's block is applied once, not once from each
 * end's row: half the arithmetic of the product, which is most of an
 * iteration. */
static int link_products_range(void *context, int64_t begin, int64_t end)
{
    const implicit_pass *pass = context;
    wc_implicit_state *s = pass->state;
    const double *in = pass->in;
    for (int64_t k = begin; k < end; ++k) {
        const double *va = in + 3 * (size_t)s->active_a[k], *vb = in + 3 * (size_t)s->active_b[k];
        const double *wb = s->active_wb + 4 * (size_t)k;
        double dx = va[0] - vb[0], dy = va[1] - vb[1], dz = va[2] - vb[2];
        double along = wb[0] * dx + wb[1] * dy + wb[2] * dz, *t = s->link_product + 3 * (size_t)k;
        t[0] = along * wb[0] + wb[3] * dx;
        t[1] = along * wb[1] + wb[3] * dy;
        t[2] = along * wb[2] + wb[3] * dz;
    }
    return 0;
}

/* Its second pass: out = A in, A = M + h drag A_i + sum_links B (in_i -
 * in_j), over free particles, gathered per row in the link list's order;
 * a row's second-end links subtract, B (in_b - in_a) being exactly -B
 * (in_a - in_b). in is zero at pins and so is out. Sums in . out. */
static int apply_range(void *context, int64_t first, int64_t last)
{
    const implicit_pass *pass = context;
    const wc_cloth *c = pass->cloth;
    wc_implicit_state *s = pass->state;
    const double *in = pass->in;
    double *out = pass->out;
    for (int64_t block = first; block < last; ++block) {
        int64_t begin, end;
        block_bounds(s, block, &begin, &end);
        double sum = 0.0;
        for (int64_t i = begin; i < end; ++i) {
            double *o = out + 3 * (size_t)i;
            if (c->pin_slot[i] >= 0) {
                o[0] = o[1] = o[2] = 0.0;
                continue;
            }
            const double *vi = in + 3 * (size_t)i;
            double md = s->mass_diag[i];
            double ox = md * vi[0], oy = md * vi[1], oz = md * vi[2];
            const int32_t *row = s->row_list + c->link_start[i];
            for (int32_t k = 0; k < s->row_count[i]; ++k) {
                int32_t entry = row[k];
                if (entry >= 0) {
                    const double *t = s->link_product + 3 * (size_t)entry;
                    ox += t[0], oy += t[1], oz += t[2];
                } else {
                    const double *t = s->link_product + 3 * (size_t)~entry;
                    ox -= t[0], oy -= t[1], oz -= t[2];
                }
            }
            o[0] = ox, o[1] = oy, o[2] = oz;
            sum += vi[0] * ox;
            sum += vi[1] * oy;
            sum += vi[2] * oz;
        }
        pass->partial[block] = sum;
    }
    return 0;
}

/* z = the preconditioner times r: the block-Jacobi step, plus on a large
 * cloth the coarse levels' correction of each free particle's aggregate
 * (solved before this pass: wci_multigrid_coarse_solve), on a smaller one
 * the translation's (pass->translation). Sums r . z. One pass for the
 * three, so that r and z are read once per iteration. */
static int precondition_range(void *context, int64_t first, int64_t last)
{
    const implicit_pass *pass = context;
    wc_implicit_state *s = pass->state;
    const double *r = pass->r, *precond = s->precond, *coarse = pass->coarse;
    const int32_t *aggregate = pass->aggregate, *pin_slot = pass->cloth->pin_slot;
    double *z = s->z;
    for (int64_t block = first; block < last; ++block) {
        int64_t begin, end;
        block_bounds(s, block, &begin, &end);
        double sum = 0.0;
        for (int64_t i = begin; i < end; ++i) {
            double *zi = z + 3 * (size_t)i;
            const double *ri = r + 3 * (size_t)i;
            wc_sym3_times(precond + 6 * (size_t)i, ri[0], ri[1], ri[2], zi);
            if (coarse && pin_slot[i] < 0) {
                const double *xc = coarse + 3 * (size_t)aggregate[i];
                zi[0] += xc[0], zi[1] += xc[1], zi[2] += xc[2];
            } else if (!coarse && pin_slot[i] < 0) {
                const double *t = pass->translation;
                zi[0] += t[0], zi[1] += t[1], zi[2] += t[2];
            }
            sum += ri[0] * zi[0];
            sum += ri[1] * zi[1];
            sum += ri[2] * zi[2];
        }
        pass->partial[block] = sum;
    }
    return 0;
}

/* A block's residual components summed, where the pass wants them. */
static void put_residual_sums(const implicit_pass *pass, int64_t block, const double sum[3])
{
    if (!pass->residual_sums) return;
    int32_t blocks = pass->state->blocks;
    for (int m = 0; m < 3; ++m) pass->residual_sums[(size_t)m * (size_t)blocks + (size_t)block] = sum[m];
}

/* The solve's start, y = 0 and r = b; sums b . b (and b's components). */
static int start_range(void *context, int64_t first, int64_t last)
{
    const implicit_pass *pass = context;
    wc_implicit_state *s = pass->state;
    for (int64_t block = first; block < last; ++block) {
        int64_t begin, end;
        block_bounds(s, block, &begin, &end);
        double sum = 0.0, components[3] = {0.0, 0.0, 0.0};
        for (int64_t k = begin; k < end; ++k)
            for (int m = 0; m < 3; ++m) {
                int64_t i = 3 * k + m;
                s->y[i] = 0.0;
                pass->r[i] = s->rhs[i];
                sum += s->rhs[i] * s->rhs[i];
                components[m] += s->rhs[i];
            }
        pass->partial[block] = sum;
        put_residual_sums(pass, block, components);
    }
    return 0;
}

/* y += alpha p; r_next = r - alpha q; sums r_next . r_next (and its
 * components). */
static int update_solution_range(void *context, int64_t first, int64_t last)
{
    const implicit_pass *pass = context;
    wc_implicit_state *s = pass->state;
    double alpha = pass->factor;
    for (int64_t block = first; block < last; ++block) {
        int64_t begin, end;
        block_bounds(s, block, &begin, &end);
        double sum = 0.0, components[3] = {0.0, 0.0, 0.0};
        for (int64_t k = begin; k < end; ++k)
            for (int m = 0; m < 3; ++m) {
                int64_t i = 3 * k + m;
                s->y[i] += alpha * s->p[i];
                pass->r_next[i] = pass->r[i] - alpha * s->q[i];
                sum += pass->r_next[i] * pass->r_next[i];
                components[m] += pass->r_next[i];
            }
        pass->partial[block] = sum;
        put_residual_sums(pass, block, components);
    }
    return 0;
}

/* p = z + beta p. */
static int update_direction_range(void *context, int64_t first, int64_t last)
{
    const implicit_pass *pass = context;
    wc_implicit_state *s = pass->state;
    double beta = pass->factor;
    for (int64_t block = first; block < last; ++block) {
        int64_t begin, end;
        block_bounds(s, block, &begin, &end);
        for (int64_t i = 3 * begin; i < 3 * end; ++i) s->p[i] = s->z[i] + beta * s->p[i];
    }
    return 0;
}

/* The first direction, p = z. */
static int first_direction_range(void *context, int64_t first, int64_t last)
{
    const implicit_pass *pass = context;
    wc_implicit_state *s = pass->state;
    int64_t begin, end, unused;
    block_bounds(s, first, &begin, &unused);
    block_bounds(s, last - 1, &unused, &end);
    memcpy(s->p + 3 * begin, s->z + 3 * begin, 3 * (size_t)(end - begin) * sizeof(double));
    return 0;
}

/* The solve runs in one team (parallel.h): each thread takes the same
 * slices of the blocks and of the links in every iteration, a barrier
 * stands wherever a loop reads what other threads wrote, and every thread
 * adds up the block sums itself in block order: the same scalars, and so
 * the same decisions, on every thread. The blocks split from
 * WC_PARALLEL_MIN particles up, as the other per-particle loops do. */
static void team_blocks(implicit_pass *pass, const wc_team *team, wc_range_fn body, int set)
{
    wc_implicit_state *s = pass->state;
    int64_t begin, end;
    wc_team_slice(team, s->blocks, team->threads > 1 && s->n >= WC_PARALLEL_MIN, &begin, &end);
    pass->partial = s->partial + (size_t)set * (size_t)s->blocks;
    if (begin < end) body(pass, begin, end);
}

/* The sum of a set, after the barrier that follows the loop filling it. */
static double set_sum(const wc_implicit_state *s, int set)
{
    return block_sum(s, s->partial + (size_t)set * (size_t)s->blocks);
}

/* z = the preconditioner applied to r: block-Jacobi, plus the coarse
 * levels' correction on a large cloth; the first time also p = z. Returns
 * r . z. The coarse levels read r as r_old - alpha q (r_old: the residual
 * before this iteration's update, complete, as q is; q NULL on the first
 * call, r_old then r itself), so they run in the same phase as the update
 * of r, whose rows block-Jacobi reads on the thread that wrote them. */
static double precondition(implicit_pass *pass, const wc_team *team, int first,
                           const double *r_old, const double *q, double alpha)
{
    wc_implicit_state *s = pass->state;
    if (s->multigrid) {
        wci_multigrid_coarse_solve_team(s->multigrid, r_old, q, alpha, team);
        wci_team_barrier(team);
        pass->coarse = wci_multigrid_coarse_solution(s->multigrid);
        pass->aggregate = wci_multigrid_fine_aggregates(s->multigrid);
    } else {
        /* the residual's sum over the particles, complete after the
         * barrier; every thread solves for the translation itself */
        wci_team_barrier(team);
        double total[3];
        for (int m = 0; m < 3; ++m) total[m] = set_sum(s, PARTIAL_RX + m);
        wc_sym3_times(s->translation_inverse, total[0], total[1], total[2], pass->translation);
    }
    team_blocks(pass, team, precondition_range, PARTIAL_RZ);
    if (first) team_blocks(pass, team, first_direction_range, PARTIAL_RZ);
    wci_team_barrier(team);
    return set_sum(s, PARTIAL_RZ);
}

/* The mass the solve's free particles carry, kg: with the step's
 * velocity tolerance it makes the bound on the error's energy norm. The
 * goal springs' share of the diagonal is stiffness, not mass: counted, it
 * would loosen the bound (by sqrt(1 + h^2 s) on a cloth soft-pinned all
 * over). */
static double free_mass(const implicit_pass *pass)
{
    const wc_cloth *c = pass->cloth;
    const wc_implicit_state *s = pass->state;
    const int32_t *soft = c->pins.soft_count ? c->soft_pin_slot : NULL;
    double mass = 0.0, spring = pass->share * (pass->h * pass->h);
    for (int32_t i = 0; i < s->n; ++i) {
        if (c->pin_slot[i] >= 0) continue;
        double goal = goal_stiffness(c, soft, i);
        mass += goal > 0.0 ? s->mass_diag[i] - spring * goal : s->mass_diag[i];
    }
    return mass;
}

static double sum_of(const double *values, int count)
{
    double sum = 0.0;
    for (int k = 0; k < count; ++k) sum += values[k];
    return sum;
}

typedef struct solve_pass {
    const implicit_pass *pass;
    /* velocity_tolerance^2 times the free mass, 0 without a tolerance */
    double bound;
} solve_pass;

static void solve_body(void *context, const wc_team *team)
{
    const solve_pass *shared = context;
    implicit_pass pass = *shared->pass; /* each thread's own: loops change its fields */
    wc_implicit_state *s = pass.state;
    pass.r = s->r, pass.r_next = s->r_next;
    pass.residual_sums = s->multigrid ? NULL : s->partial + (size_t)PARTIAL_RX * (size_t)s->blocks;
    team_blocks(&pass, team, start_range, PARTIAL_RR);
    wci_team_barrier(team);
    double bb = set_sum(s, PARTIAL_RR), rr = bb, bound = shared->bound;
    int32_t it = 0;
    if (bb > 0.0) {
        double rz = precondition(&pass, team, 1, pass.r, NULL, 0.0);
        double decrease[ESTIMATE_DELAY] = {0.0};
        int64_t link_begin, link_end;
        wc_team_slice(team, s->active_count, team->threads > 1, &link_begin, &link_end);
        pass.in = s->p, pass.out = s->q;
        for (; it < CG_MAX_ITERATIONS && rr > CG_TOLERANCE * CG_TOLERANCE * bb; ++it) {
            if (bound > 0.0 && it >= ESTIMATE_DELAY && sum_of(decrease, ESTIMATE_DELAY) <= bound)
                break;
            if (link_begin < link_end) link_products_range(&pass, link_begin, link_end);
            wci_team_barrier(team);
            team_blocks(&pass, team, apply_range, PARTIAL_PQ);
            wci_team_barrier(team);
            double pq = set_sum(s, PARTIAL_PQ);
            /* A is positive definite, so pq > 0 unless p = 0 or something
             * is not finite: then stop, the caller checks the result */
            if (!(pq > 0.0) || !isfinite(pq)) break;
            double alpha = rz / pq;
            decrease[it % ESTIMATE_DELAY] = alpha * rz;
            pass.factor = alpha;
            team_blocks(&pass, team, update_solution_range, PARTIAL_RR);
            double *r_old = pass.r;
            pass.r = pass.r_next, pass.r_next = r_old;
            double rz_next = precondition(&pass, team, 0, r_old, s->q, alpha);
            rr = set_sum(s, PARTIAL_RR);
            pass.factor = rz_next / rz;
            team_blocks(&pass, team, update_direction_range, PARTIAL_RR);
            wci_team_barrier(team);
            rz = rz_next;
        }
    }
    if (team->thread == 0) {
        s->last_iterations = it;
        s->last_residual = bb > 0.0 ? sqrt(rr / bb) : 0.0;
    }
}

/* Preconditioned conjugate gradients on A y = rhs from y = 0, until the
 * residual is 1e-8 of the right-hand side or, when velocity_tolerance > 0,
 * the error's estimated energy norm is at most velocity_tolerance^2 times
 * the free mass. A >= M (the link blocks are positive semi-definite), so
 * that bounds the mass-weighted RMS velocity error by velocity_tolerance.
 * Why not a looser relative residual: on stiff cloth the right-hand side
 * is mostly stiff link forces that the solution cancels, so a residual
 * small against it can still leave a large error in the soft modes (a
 * relative 1e-5 broke the stiff cloth's energy test). The whole solve is
 * one team (a team of one is a plain call), from WC_PARALLEL_MIN particles
 * up. */
static void solve(implicit_pass *pass, double velocity_tolerance, int threads)
{
    double bound = velocity_tolerance > 0.0
                       ? velocity_tolerance * velocity_tolerance * free_mass(pass)
                       : 0.0;
    solve_pass shared = {pass, bound};
    /* A team only where the particle blocks split too (WC_PARALLEL_MIN
     * particles and more than one block): otherwise every per-particle loop
     * of an iteration runs on the first thread while the others wait at its
     * barriers (a 2,601-particle drape's integration took 61-80 ms per frame
     * on 2 threads against 43 on 1 when its blocks did not split). */
    const wc_implicit_state *s = pass->state;
    wci_parallel_team(s->blocks > 1 ? wc_threads_for(s->n, threads) : 1, solve_body, &shared);
}

/* The matrix restricted to the free particles' common translation, T^T A
 * T with T the free particles' identity blocks stacked: their mass (with
 * drag and goal springs), and the blocks of their links to pins, whose
 * other end does not move with them (links between free particles cancel);
 * inverted into s->translation_inverse. Without it a cloth's motion as a
 * whole is what block-Jacobi resolves last, and a solve stopped at its
 * tolerance keeps part of it unsolved, a stray acceleration of the whole
 * cloth (docs/model.md). Serial: O(particles + links), once per step. */
static void translation_matrix(const wc_cloth *c, wc_implicit_state *s)
{
    double sum[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
    for (int32_t i = 0; i < s->n; ++i) {
        if (c->pin_slot[i] >= 0) continue;
        sum[0] += s->mass_diag[i], sum[3] += s->mass_diag[i], sum[5] += s->mass_diag[i];
        const int32_t *row = s->row_list + c->link_start[i];
        for (int32_t k = 0; k < s->row_count[i]; ++k) {
            int32_t entry = row[k], slot = entry >= 0 ? entry : ~entry;
            int32_t j = entry >= 0 ? s->active_b[slot] : s->active_a[slot];
            if (c->pin_slot[j] < 0) continue;
            for (int m = 0; m < 6; ++m) sum[m] += s->active_block[6 * (size_t)slot + m];
        }
    }
    wci_sym3_inverse(sum, s->translation_inverse);
}

/* First particle whose right-hand side is not finite, -1 if none. Forces
 * that overflowed make it so, and CG would not notice: the norm of such a
 * right-hand side is not > 0, so the solve would return no change and the
 * step a finite but wrong state. */
static int32_t first_non_finite_rhs(const wc_implicit_state *s)
{
    for (int32_t i = 0; i < s->n; ++i) {
        const double *b = s->rhs + 3 * (size_t)i;
        if (!isfinite(b[0]) || !isfinite(b[1]) || !isfinite(b[2])) return i;
    }
    return -1;
}

/* x1 = x + h (v0 + share dv); pins exactly at their targets. */
typedef struct positions_pass {
    wc_cloth *cloth;
    const wc_implicit_state *state;
    double dt, pin_fraction, share;
} positions_pass;

static int positions_range(void *context, int64_t begin, int64_t end)
{
    const positions_pass *pass = context;
    wc_cloth *c = pass->cloth;
    const wc_implicit_state *s = pass->state;
    double dt = pass->dt, share = pass->share;
    int bad = 0;
    for (int64_t i = begin; i < end; ++i) {
        if (c->pin_slot[i] >= 0) {
            double p[3];
            wci_pinned_position(c, c->pin_slot[i], pass->pin_fraction, p);
            c->nx[i] = p[0], c->ny[i] = p[1], c->nz[i] = p[2];
            bad = bad || !(isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]));
            continue;
        }
        const double *v = s->v0 + 3 * (size_t)i, *y = s->y + 3 * (size_t)i;
        c->nx[i] = c->x[i] + dt * (v[0] + share * y[0]);
        c->ny[i] = c->y[i] + dt * (v[1] + share * y[1]);
        c->nz[i] = c->z[i] + dt * (v[2] + share * y[2]);
        bad = bad || !(isfinite(c->nx[i]) && isfinite(c->ny[i]) && isfinite(c->nz[i]));
    }
    return bad;
}

int32_t wci_integrate_implicit(wc_cloth *c, double dt, double pin_fraction, double tolerance,
                              int threads)
{
    WC_ASSERT(c->implicit != NULL);
    WC_ASSERT(dt > 0.0 && pin_fraction >= 0.0 && pin_fraction <= 1.0 && tolerance >= 0.0 &&
              threads >= 1);
    wc_implicit_state *s = c->implicit;
    int32_t n = c->particle_count;
    int particle_threads = wc_threads_for(n, threads);
    /* The start velocity is the last step's chord (x - x_prev) / h_prev,
     * the velocity half that step back, not at the step's start: moving
     * the positions by h (v0 + dv) would put the velocity change (h_prev +
     * h) / 2 too early, and a cloth falling from rest (h_prev = 0, v0 the
     * velocity set) would lead free fall by g t h / 2 for ever. Positions
     * take the share (h + h_prev) / 2h of dv, as Verlet takes its
     * acceleration over (h + h_prev) / 2 (integrate.c), and the stiffness
     * term of the matrix the same share; with equal steps it is 1, plain
     * backward Euler. */
    double h_prev = c->has_history ? c->dt_prev : 0.0;
    implicit_pass pass;
    memset(&pass, 0, sizeof pass);
    pass.cloth = c, pass.state = s, pass.h = dt, pass.pin_fraction = pin_fraction;
    pass.share = (dt + h_prev) / (2.0 * dt);
    wci_parallel_for(n, particle_threads, start_velocities_range, &pass);
    active_links(&pass, threads);
    /* the first particle with a non-finite right-hand side looked for only
     * when the loop found one */
    if (wci_parallel_for(n, particle_threads, rhs_and_preconditioner_range, &pass)) {
        int32_t bad = first_non_finite_rhs(s);
        if (bad >= 0) return bad;
    }
    if (s->multigrid)
        wci_multigrid_update(s->multigrid, s->mass_diag, s->active_block, s->active_slot,
                             c->pins.count > c->pins.soft_count ? c->pin_slot : NULL, threads);
    else
        translation_matrix(c, s);
    solve(&pass, tolerance * dt, threads);
    positions_pass positions = {c, s, dt, pin_fraction, pass.share};
    if (!wci_parallel_for(n, particle_threads, positions_range, &positions)) return -1;
    return wci_first_non_finite_xyz(c->nx, c->ny, c->nz, n);
}
