#include "multigrid.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "alloc.h"
#include "parallel.h"
#include "primitives.h"

/* Coarsening stops at this many nodes: the coarsest level's sweeps then
 * reach across it. */
#define COARSEST_NODES 32
/* ... or when a level would keep more than this share of its nodes:
 * aggregates that small would not pay for the level. */
#define LEAST_REDUCTION 0.75
#define MAX_LEVELS 16
/* Damped block-Jacobi: D_full (D plus the link blocks at a node) satisfies
 * A <= 2 D_full, so with this weight the sweep's eigenvalues lie in
 * (-1/3, 1): convergent, and it damps the high frequencies of a
 * Laplacian-like matrix best. */
#define SMOOTHING_WEIGHT (2.0 / 3.0)
#define COARSEST_SWEEPS 4
/* The coarsest level is solved exactly (a dense Cholesky factor, made once
 * per step) when it has at most this many nodes, as it has on every cloth
 * whose aggregation does not stall: COARSEST_NODES or fewer. Why: the
 * coarsest level holds the cloth's motion as a whole, and sweeps leave part
 * of it unsolved, which a solve stopped at its tolerance then keeps as a
 * stray acceleration of the whole cloth (a cloth sliding down a slope slid
 * 2.9 % short at 16 m/s^2 with the sweeps, as far as the closed form with
 * the exact solve: docs/model.md). 64 nodes are 192 unknowns, a factor of
 * about 1.2 million multiply-adds a step. */
#define EXACT_COARSEST_NODES 64
/* A level's loops (the restriction to it too) split across the solve's
 * threads from this many nodes up, far below WC_PARALLEL_MIN: every CG
 * iteration runs them back to back with the solve's own loops, and left on
 * one thread the first coarse level of a 10,201-particle cloth (1,133
 * nodes) had the other thread waiting through them. */
#define LEVEL_PARALLEL_MIN 256

typedef struct level {
    int32_t n, links;
    /* structure: borrowed at the finest level, owned above (own_ints) */
    const int32_t *end_a, *end_b, *adj_start, *adj;
    int32_t *own_ints[4];
    /* values: at the finest level the mass (one number per node), the link
     * blocks and the pins, all borrowed; above, D, B and the inverse of
     * D_full, 6 numbers per node or link */
    const double *mass, *block;
    const int32_t *block_slot, *pin_slot;
    double *diag, *own_block, *inv;
    /* toward the next coarser level: each node's aggregate, each
     * aggregate's nodes (CSR), each coarse link's fine links (CSR) */
    int32_t *agg, *member_start, *members, *fine_start, *fine_links;
    /* cycle vectors, 3 per node (coarse levels): solution, right-hand
     * side, residual, the solution after the last sweep of a level above
     * the coarsest (cycle_solution), and the solution with the coarser
     * level's correction (correct_smooth); 3 per link: the product's
     * B (x_a - x_b) */
    double *x, *b, *r, *post, *corrected, *link_product;
} level;

struct wc_multigrid {
    int32_t levels;
    level level[MAX_LEVELS];
    /* The coarsest level's matrix as a dense lower Cholesky factor, row
     * major (3 n x 3 n), NULL when that level is too large; `factored`:
     * whether the step's factor succeeded (it falls back to the sweeps). */
    double *factor;
    int factored;
};

static void level_free(level *l)
{
    for (int k = 0; k < 4; ++k) wci_free(l->own_ints[k]);
    int32_t *ints[] = {l->agg, l->member_start, l->members, l->fine_start, l->fine_links};
    for (size_t k = 0; k < sizeof ints / sizeof ints[0]; ++k) wci_free(ints[k]);
    double *doubles[] = {l->diag, l->own_block, l->inv, l->x, l->b, l->r, l->post,
                         l->corrected, l->link_product};
    for (size_t k = 0; k < sizeof doubles / sizeof doubles[0]; ++k) wci_free(doubles[k]);
}

void wci_multigrid_destroy(wc_multigrid *mg)
{
    if (!mg) return;
    for (int32_t k = 0; k < mg->levels; ++k) level_free(&mg->level[k]);
    wci_free(mg->factor);
    wci_free(mg);
}

int32_t wci_multigrid_levels(const wc_multigrid *mg) { return mg->levels; }

/* ------------------------------------------------------------------------ */
/* Structure, once per cloth                                                */
/* ------------------------------------------------------------------------ */

static int32_t link_of(int32_t entry) { return entry >= 0 ? entry : ~entry; }

/* The node at the other end of an adjacency entry. */
static int32_t other_end(const level *l, int32_t entry)
{
    return entry >= 0 ? l->end_b[entry] : l->end_a[~entry];
}

/* Whether adjacency entry k of node i joins a neighbour for aggregation. */
static int neighbour_entry(const level *l, int32_t k, int32_t neighbour_links)
{
    return link_of(l->adj[k]) < neighbour_links;
}

/* Greedy aggregation in index order (Vanek, Mandel & Brezina 1996): a node
 * whose neighbours are all unassigned starts an aggregate with them; every
 * other node joins the aggregate of its first neighbour assigned in that
 * first pass; a node with none left starts one of its own. Returns the
 * number of aggregates. */
static int32_t aggregate(const level *l, int32_t neighbour_links, int32_t *agg)
{
    int32_t n = l->n, count = 0;
    for (int32_t i = 0; i < n; ++i) agg[i] = -1;
    for (int32_t i = 0; i < n; ++i) {
        int ready = 1;
        for (int32_t k = l->adj_start[i]; ready && k < l->adj_start[i + 1]; ++k)
            if (neighbour_entry(l, k, neighbour_links)) ready = agg[other_end(l, l->adj[k])] < 0;
        if (!ready || agg[i] >= 0) continue;
        agg[i] = count;
        for (int32_t k = l->adj_start[i]; k < l->adj_start[i + 1]; ++k)
            if (neighbour_entry(l, k, neighbour_links)) agg[other_end(l, l->adj[k])] = count;
        ++count;
    }
    /* joined in a second pass, marked -2 - aggregate meanwhile so that no
     * node joins through a node that joined in this same pass */
    for (int32_t i = 0; i < n; ++i) {
        if (agg[i] != -1) continue;
        for (int32_t k = l->adj_start[i]; k < l->adj_start[i + 1]; ++k) {
            int32_t j = other_end(l, l->adj[k]);
            if (neighbour_entry(l, k, neighbour_links) && agg[j] >= 0) {
                agg[i] = -2 - agg[j];
                break;
            }
        }
    }
    for (int32_t i = 0; i < n; ++i)
        if (agg[i] <= -2) agg[i] = -2 - agg[i];
    for (int32_t i = 0; i < n; ++i)
        if (agg[i] < 0) agg[i] = count++;
    return count;
}

/* Each aggregate's nodes, ascending (a counting sort). */
static int build_members(level *f, int32_t nc)
{
    f->member_start = wci_alloc_array((size_t)nc + 1, sizeof(int32_t));
    f->members = wci_alloc_array((size_t)f->n, sizeof(int32_t));
    int32_t *fill = wci_alloc_array((size_t)nc, sizeof(int32_t));
    int failed = !f->member_start || !f->members || !fill;
    if (!failed) {
        for (int32_t i = 0; i < f->n; ++i) ++f->member_start[f->agg[i] + 1];
        for (int32_t a = 0; a < nc; ++a) f->member_start[a + 1] += f->member_start[a];
        for (int32_t i = 0; i < f->n; ++i)
            f->members[f->member_start[f->agg[i]] + fill[f->agg[i]]++] = i;
    }
    wci_free(fill);
    return failed;
}

/* A fine link between two aggregates, sorted by the pair and then by the
 * fine link: that order fixes the coarse links and the order of each one's
 * sum. */
typedef struct cross_link {
    int32_t lo, hi, fine;
} cross_link;

static int compare_cross(const void *pa, const void *pb)
{
    const cross_link *a = pa, *b = pb;
    if (a->lo != b->lo) return a->lo < b->lo ? -1 : 1;
    if (a->hi != b->hi) return a->hi < b->hi ? -1 : 1;
    return (a->fine > b->fine) - (a->fine < b->fine);
}

/* The fine links between different aggregates, sorted. NULL when out of
 * memory. */
static cross_link *sorted_cross_links(const level *f, int32_t *count)
{
    int32_t m = 0;
    for (int32_t e = 0; e < f->links; ++e) m += f->agg[f->end_a[e]] != f->agg[f->end_b[e]];
    cross_link *cross = wci_alloc_array((size_t)m + 1, sizeof *cross);
    if (!cross) return NULL;
    m = 0;
    for (int32_t e = 0; e < f->links; ++e) {
        int32_t a = f->agg[f->end_a[e]], b = f->agg[f->end_b[e]];
        if (a == b) continue;
        cross[m].lo = a < b ? a : b, cross[m].hi = a < b ? b : a, cross[m].fine = e;
        ++m;
    }
    qsort(cross, (size_t)m, sizeof *cross, compare_cross);
    *count = m;
    return cross;
}

static int new_pair(const cross_link *cross, int32_t k)
{
    return k == 0 || cross[k].lo != cross[k - 1].lo || cross[k].hi != cross[k - 1].hi;
}

/* The coarse level's links: one per pair of aggregates that fine links
 * join, with those fine links (f->fine_start, f->fine_links). */
static int build_coarse_links(level *f, level *c)
{
    int32_t m = 0, links = 0;
    cross_link *cross = sorted_cross_links(f, &m);
    if (!cross) return 1;
    for (int32_t k = 0; k < m; ++k) links += new_pair(cross, k);
    int32_t *end_a = c->own_ints[0] = wci_alloc_array((size_t)links + 1, sizeof(int32_t));
    int32_t *end_b = c->own_ints[1] = wci_alloc_array((size_t)links + 1, sizeof(int32_t));
    f->fine_start = wci_alloc_array((size_t)links + 1, sizeof(int32_t));
    f->fine_links = wci_alloc_array((size_t)m + 1, sizeof(int32_t));
    int failed = !end_a || !end_b || !f->fine_start || !f->fine_links;
    if (!failed) {
        int32_t e = -1;
        for (int32_t k = 0; k < m; ++k) {
            if (new_pair(cross, k)) {
                ++e;
                end_a[e] = cross[k].lo, end_b[e] = cross[k].hi, f->fine_start[e] = k;
            }
            f->fine_links[k] = cross[k].fine;
        }
        f->fine_start[links] = m;
        c->links = links, c->end_a = end_a, c->end_b = end_b;
    }
    wci_free(cross);
    return failed;
}

/* The coarse level's adjacency, in the fine form: ascending links, k for
 * the first end, ~k for the second. */
static int build_coarse_adjacency(level *c)
{
    int32_t *start = c->own_ints[2] = wci_alloc_array((size_t)c->n + 1, sizeof(int32_t));
    int32_t *adj = c->own_ints[3] = wci_alloc_array(2 * (size_t)c->links + 1, sizeof(int32_t));
    int32_t *fill = wci_alloc_array((size_t)c->n + 1, sizeof(int32_t));
    int failed = !start || !adj || !fill;
    if (!failed) {
        for (int32_t k = 0; k < c->links; ++k) ++start[c->end_a[k] + 1], ++start[c->end_b[k] + 1];
        for (int32_t a = 0; a < c->n; ++a) start[a + 1] += start[a];
        for (int32_t k = 0; k < c->links; ++k) {
            adj[start[c->end_a[k]] + fill[c->end_a[k]]++] = k;
            adj[start[c->end_b[k]] + fill[c->end_b[k]]++] = ~k;
        }
        c->adj_start = start, c->adj = adj;
    }
    wci_free(fill);
    return failed;
}

static int allocate_values(level *c)
{
    size_t n = (size_t)c->n;
    c->diag = wci_alloc_array(6 * n, sizeof(double));
    c->inv = wci_alloc_array(6 * n, sizeof(double));
    c->own_block = wci_alloc_array(6 * (size_t)c->links + 1, sizeof(double));
    c->block = c->own_block;
    c->x = wci_alloc_array(3 * n, sizeof(double));
    c->b = wci_alloc_array(3 * n, sizeof(double));
    c->r = wci_alloc_array(3 * n, sizeof(double));
    c->post = wci_alloc_array(3 * n, sizeof(double));
    c->corrected = wci_alloc_array(3 * n, sizeof(double));
    c->link_product = wci_alloc_array(3 * (size_t)c->links + 1, sizeof(double));
    return !c->diag || !c->inv || !c->own_block || !c->x || !c->b || !c->r || !c->post ||
           !c->corrected || !c->link_product;
}

/* Adds the level above the top one, unless the top one is small enough or
 * would not shrink enough (*added = 0). Returns 1 when out of memory. */
static int coarsen(wc_multigrid *mg, int32_t neighbour_links, int *added)
{
    level *f = &mg->level[mg->levels - 1];
    *added = 0;
    if (f->n <= COARSEST_NODES || mg->levels == MAX_LEVELS) return 0;
    f->agg = wci_alloc_array((size_t)f->n, sizeof(int32_t));
    if (!f->agg) return 1;
    int32_t nc = aggregate(f, neighbour_links, f->agg);
    if (nc > LEAST_REDUCTION * f->n) {
        wci_free(f->agg);
        f->agg = NULL;
        return 0;
    }
    level *c = &mg->level[mg->levels++];
    c->n = nc;
    *added = 1;
    return build_members(f, nc) || build_coarse_links(f, c) || build_coarse_adjacency(c) ||
           allocate_values(c);
}

int wci_multigrid_create(int32_t n, int32_t links, const int32_t *end_a, const int32_t *end_b,
                        int32_t neighbour_links, const int32_t *adj_start, const int32_t *adj,
                        wc_multigrid **out)
{
    *out = NULL;
    if (n < WC_MULTIGRID_MIN_PARTICLES) return 0;
    wc_multigrid *mg = wci_alloc_array(1, sizeof *mg);
    if (!mg) return 1;
    level *fine = &mg->level[0];
    fine->n = n, fine->links = links, fine->end_a = end_a, fine->end_b = end_b;
    fine->adj_start = adj_start, fine->adj = adj;
    mg->levels = 1;
    int failed = 0, added = 1;
    while (!failed && added) {
        failed = coarsen(mg, neighbour_links, &added);
        /* above the finest level every link joins neighbours */
        neighbour_links = mg->level[mg->levels - 1].links;
    }
    if (!failed && mg->levels > 1) {
        int32_t m = 3 * mg->level[mg->levels - 1].n;
        if (m <= 3 * EXACT_COARSEST_NODES) {
            mg->factor = wci_alloc_array((size_t)m * (size_t)m, sizeof(double));
            failed = mg->factor == NULL;
        }
    }
    if (failed || mg->levels == 1) {
        wci_multigrid_destroy(mg);
        return failed;
    }
    *out = mg;
    return 0;
}

/* ------------------------------------------------------------------------ */
/* Values, once per step                                                    */
/* ------------------------------------------------------------------------ */

/* One loop over a level's nodes or links: its level, the coarser one, and
 * the vectors it reads and writes. A restriction with `minus` reads in -
 * factor minus instead of in. */
typedef struct mg_pass {
    level *fine, *coarse;
    const double *in;
    double *out;
    const double *minus;
    double factor;
} mg_pass;

static int pinned(const level *l, int32_t i) { return l->pin_slot && l->pin_slot[i] >= 0; }

static void add_block(double *to, const double *b)
{
    for (int k = 0; k < 6; ++k) to[k] += b[k];
}

/* Link e's block, NULL when it has none this step (block_slot, at the
 * finest level: wci_multigrid_update). */
static const double *link_block(const level *l, int32_t e)
{
    if (!l->block_slot) return l->block + 6 * (size_t)e;
    int32_t slot = l->block_slot[e];
    return slot >= 0 ? l->block + 6 * (size_t)slot : NULL;
}

/* A coarse link's block: the sum of its fine links' blocks, those between
 * free particles (a link to a pin acts on its free end's diagonal). */
static int coarse_links_range(void *context, int64_t begin, int64_t end)
{
    const mg_pass *p = context;
    const level *f = p->fine;
    level *c = p->coarse;
    for (int64_t e = begin; e < end; ++e) {
        double *b = c->own_block + 6 * (size_t)e;
        for (int k = 0; k < 6; ++k) b[k] = 0.0;
        for (int32_t k = f->fine_start[e]; k < f->fine_start[e + 1]; ++k) {
            int32_t fe = f->fine_links[k];
            const double *fine = link_block(f, fe);
            if (!fine || pinned(f, f->end_a[fe]) || pinned(f, f->end_b[fe])) continue;
            add_block(b, fine);
        }
    }
    return 0;
}

/* What a free fine node adds to its aggregate's D: its own D (at the
 * finest level its mass, and the blocks of its links to pins). */
static void add_member_diag(const level *f, int32_t i, double *d)
{
    if (!f->mass) {
        add_block(d, f->diag + 6 * (size_t)i);
        return;
    }
    d[0] += f->mass[i], d[3] += f->mass[i], d[5] += f->mass[i];
    if (!f->pin_slot) return;
    for (int32_t k = f->adj_start[i]; k < f->adj_start[i + 1]; ++k) {
        const double *b = link_block(f, link_of(f->adj[k]));
        if (b && pinned(f, other_end(f, f->adj[k]))) add_block(d, b);
    }
}

/* An aggregate's D, and the inverse of its D_full for the smoother. */
static int coarse_nodes_range(void *context, int64_t begin, int64_t end)
{
    const mg_pass *p = context;
    const level *f = p->fine;
    level *c = p->coarse;
    for (int64_t a = begin; a < end; ++a) {
        double *d = c->diag + 6 * (size_t)a, whole[6];
        for (int k = 0; k < 6; ++k) d[k] = 0.0;
        for (int32_t m = f->member_start[a]; m < f->member_start[a + 1]; ++m)
            if (!pinned(f, f->members[m])) add_member_diag(f, f->members[m], d);
        memcpy(whole, d, sizeof whole);
        for (int32_t k = c->adj_start[a]; k < c->adj_start[a + 1]; ++k)
            add_block(whole, c->block + 6 * (size_t)link_of(c->adj[k]));
        wci_sym3_inverse(whole, c->inv + 6 * (size_t)a);
    }
    return 0;
}

/* Entry (r, c) of a symmetric m x m matrix kept as its lower triangle, row
 * major: (c, r) when r < c. */
static double *lower(double *a, int32_t m, int32_t r, int32_t c)
{
    return r < c ? a + (size_t)c * (size_t)m + (size_t)r : a + (size_t)r * (size_t)m + (size_t)c;
}

/* Adds the symmetric 3 x 3 block b (xx, xy, xz, yy, yz, zz) times sign at
 * rows 3i.., columns 3j.. of the dense lower triangle a (m columns). */
static void add_dense_block(double *a, int32_t m, int32_t i, int32_t j, const double *b, double sign)
{
    static const int ROW[6] = {0, 0, 0, 1, 1, 2}, COL[6] = {0, 1, 2, 1, 2, 2};
    for (int k = 0; k < 6; ++k) {
        *lower(a, m, 3 * i + ROW[k], 3 * j + COL[k]) += sign * b[k];
        if (ROW[k] != COL[k] && i != j) *lower(a, m, 3 * i + COL[k], 3 * j + ROW[k]) += sign * b[k];
    }
}

/* The coarsest level's matrix, D_i on the diagonal and each link's B at
 * (a, a), (b, b) and -B at (a, b), factored in place as L L^T. Returns 0
 * when a pivot is not positive and finite (the matrix is positive definite
 * in exact arithmetic: its D holds the aggregates' masses). */
static int factor_coarsest(wc_multigrid *mg)
{
    const level *l = &mg->level[mg->levels - 1];
    int32_t m = 3 * l->n;
    double *a = mg->factor;
    memset(a, 0, (size_t)m * (size_t)m * sizeof *a);
    for (int32_t i = 0; i < l->n; ++i) add_dense_block(a, m, i, i, l->diag + 6 * (size_t)i, 1.0);
    for (int32_t e = 0; e < l->links; ++e) {
        const double *b = l->block + 6 * (size_t)e;
        int32_t i = l->end_a[e], j = l->end_b[e];
        add_dense_block(a, m, i, i, b, 1.0);
        add_dense_block(a, m, j, j, b, 1.0);
        add_dense_block(a, m, i > j ? i : j, i > j ? j : i, b, -1.0);
    }
    /* an aggregate of pinned particles only has an empty row and column
     * (its restricted residual is zero): 1 on its diagonal keeps its
     * solution 0 and the factor defined */
    for (int32_t j = 0; j < m; ++j) {
        int empty = 1;
        for (int32_t k = 0; empty && k < m; ++k) empty = *lower(a, m, j, k) == 0.0;
        if (empty) *lower(a, m, j, j) = 1.0;
    }
    for (int32_t j = 0; j < m; ++j) {
        double *row_j = a + (size_t)j * (size_t)m, pivot = row_j[j];
        for (int32_t k = 0; k < j; ++k) pivot -= row_j[k] * row_j[k];
        if (!(pivot > 0.0) || !isfinite(pivot)) return 0;
        row_j[j] = sqrt(pivot);
        for (int32_t i = j + 1; i < m; ++i) {
            double *row_i = a + (size_t)i * (size_t)m, v = row_i[j];
            for (int32_t k = 0; k < j; ++k) v -= row_i[k] * row_j[k];
            row_i[j] = v / row_j[j];
        }
    }
    return 1;
}

/* x = A^-1 b on the coarsest level, by the factor: L y = b, L^T x = y. */
static void solve_coarsest(const wc_multigrid *mg, level *l)
{
    int32_t m = 3 * l->n;
    double *a = mg->factor;
    for (int32_t i = 0; i < m; ++i) {
        const double *row = a + (size_t)i * (size_t)m;
        double v = l->b[i];
        for (int32_t k = 0; k < i; ++k) v -= row[k] * l->x[k];
        l->x[i] = v / row[i];
    }
    for (int32_t i = m - 1; i >= 0; --i) {
        double v = l->x[i];
        for (int32_t k = i + 1; k < m; ++k) v -= *lower(a, m, k, i) * l->x[k];
        l->x[i] = v / *lower(a, m, i, i);
    }
}

void wci_multigrid_update(wc_multigrid *mg, const double *mass_diag, const double *block,
                         const int32_t *block_slot, const int32_t *pin_slot, int threads)
{
    level *fine = &mg->level[0];
    fine->mass = mass_diag, fine->block = block, fine->block_slot = block_slot;
    fine->pin_slot = pin_slot;
    for (int32_t k = 0; k + 1 < mg->levels; ++k) {
        mg_pass p = {&mg->level[k], &mg->level[k + 1], NULL, NULL, NULL, 0.0};
        int32_t links = p.coarse->links, nodes = p.coarse->n;
        wci_parallel_for(links, wc_threads_for(links, threads), coarse_links_range, &p);
        wci_parallel_for(nodes, wc_threads_for(nodes, threads), coarse_nodes_range, &p);
    }
    mg->factored = mg->factor && factor_coarsest(mg);
}

/* ------------------------------------------------------------------------ */
/* The correction                                                           */
/* ------------------------------------------------------------------------ */

/* A coarse level's product with x = p->in, first pass: per link B (x_a -
 * x_b), each block applied once (half the arithmetic of applying it from
 * both ends' rows). */
static int link_products_range(void *context, int64_t begin, int64_t end)
{
    const mg_pass *p = context;
    level *l = p->fine;
    for (int64_t e = begin; e < end; ++e) {
        const double *xa = p->in + 3 * (size_t)l->end_a[e], *xb = p->in + 3 * (size_t)l->end_b[e];
        wc_sym3_times(l->block + 6 * (size_t)e, xa[0] - xb[0], xa[1] - xb[1], xa[2] - xb[2],
                      l->link_product + 3 * (size_t)e);
    }
    return 0;
}

/* Its second pass at node i: (A x)_i = D x_i + the node's links' products,
 * added at their first end and subtracted at their second (B (x_b - x_a)
 * is exactly -B (x_a - x_b)): the bits of applying each block from the
 * node's row, in the adjacency's order. */
static void product_row(const level *l, const double *x, int32_t i, double ax[3])
{
    const double *xi = x + 3 * (size_t)i;
    wc_sym3_times(l->diag + 6 * (size_t)i, xi[0], xi[1], xi[2], ax);
    for (int32_t k = l->adj_start[i]; k < l->adj_start[i + 1]; ++k) {
        int32_t entry = l->adj[k];
        const double *t = l->link_product + 3 * (size_t)link_of(entry);
        if (entry >= 0) {
            ax[0] += t[0], ax[1] += t[1], ax[2] += t[2];
        } else {
            ax[0] -= t[0], ax[1] -= t[1], ax[2] -= t[2];
        }
    }
}

/* r = b - A x on a coarse level, after link_products_range on x. */
static int residual_range(void *context, int64_t begin, int64_t end)
{
    const mg_pass *p = context;
    level *l = p->fine;
    for (int64_t i = begin; i < end; ++i) {
        double ax[3];
        product_row(l, l->x, (int32_t)i, ax);
        const double *b = l->b + 3 * (size_t)i;
        double *r = l->r + 3 * (size_t)i;
        r[0] = b[0] - ax[0], r[1] = b[1] - ax[1], r[2] = b[2] - ax[2];
    }
    return 0;
}

/* One damped block-Jacobi sweep, x += w D_full^-1 res, with res = p->in:
 * the residual l->r, or l->b for the first sweep, which starts from x = 0
 * (where the residual is b, so it needs no product). */
static int sweep_range(void *context, int64_t begin, int64_t end)
{
    const mg_pass *p = context;
    level *l = p->fine;
    int from_zero = p->in == l->b;
    for (int64_t i = begin; i < end; ++i) {
        double *x = l->x + 3 * (size_t)i, t[3];
        const double *res = p->in + 3 * (size_t)i;
        wc_sym3_times(l->inv + 6 * (size_t)i, res[0], res[1], res[2], t);
        if (from_zero) x[0] = x[1] = x[2] = 0.0;
        x[0] += SMOOTHING_WEIGHT * t[0];
        x[1] += SMOOTHING_WEIGHT * t[1];
        x[2] += SMOOTHING_WEIGHT * t[2];
    }
    return 0;
}

/* The coarse right-hand side: each aggregate sums its free members'
 * residuals `in`. */
static int restrict_range(void *context, int64_t begin, int64_t end)
{
    const mg_pass *p = context;
    const level *f = p->fine;
    for (int64_t a = begin; a < end; ++a) {
        double s[3] = {0.0, 0.0, 0.0};
        for (int32_t m = f->member_start[a]; m < f->member_start[a + 1]; ++m) {
            int32_t i = f->members[m];
            if (pinned(f, i)) continue;
            const double *r = p->in + 3 * (size_t)i;
            if (p->minus) {
                const double *m = p->minus + 3 * (size_t)i;
                double f = p->factor, v[3] = {r[0] - f * m[0], r[1] - f * m[1], r[2] - f * m[2]};
                s[0] += v[0], s[1] += v[1], s[2] += v[2];
            } else {
                s[0] += r[0], s[1] += r[1], s[2] += r[2];
            }
        }
        memcpy(p->out + 3 * (size_t)a, s, sizeof s);
    }
    return 0;
}

/* out += P in, in the coarse level's solution: each free node takes its
 * aggregate's correction. */
static int prolong_range(void *context, int64_t begin, int64_t end)
{
    const mg_pass *p = context;
    const level *f = p->fine;
    for (int64_t i = begin; i < end; ++i) {
        if (pinned(f, (int32_t)i)) continue;
        const double *xc = p->in + 3 * (size_t)f->agg[i];
        double *x = p->out + 3 * (size_t)i;
        x[0] += xc[0], x[1] += xc[1], x[2] += xc[2];
    }
    return 0;
}

/* x' = x + P in, the coarse correction taken at each node as
 * prolong_range adds it, into l->corrected. */
static int corrected_range(void *context, int64_t begin, int64_t end)
{
    const mg_pass *p = context;
    level *l = p->fine;
    for (int64_t i = begin; i < end; ++i) {
        const double *x = l->x + 3 * (size_t)i;
        double *out = l->corrected + 3 * (size_t)i;
        out[0] = x[0], out[1] = x[1], out[2] = x[2];
        if (pinned(l, (int32_t)i)) continue;
        const double *xc = p->in + 3 * (size_t)l->agg[i];
        out[0] += xc[0], out[1] += xc[1], out[2] += xc[2];
    }
    return 0;
}

/* The sweep after the coarse correction, post = x' + w D_full^-1 (b - A
 * x'), after link_products_range on x' (l->corrected): the same arithmetic
 * as prolong_range, residual_range and sweep_range one after the other,
 * with the sweep writing post, not the x that other nodes' rows read. */
static int correct_smooth_range(void *context, int64_t begin, int64_t end)
{
    const mg_pass *p = context;
    level *l = p->fine;
    for (int64_t i = begin; i < end; ++i) {
        double ax[3], r[3], t[3];
        product_row(l, l->corrected, (int32_t)i, ax);
        const double *b = l->b + 3 * (size_t)i, *xi = l->corrected + 3 * (size_t)i;
        r[0] = b[0] - ax[0], r[1] = b[1] - ax[1], r[2] = b[2] - ax[2];
        wc_sym3_times(l->inv + 6 * (size_t)i, r[0], r[1], r[2], t);
        double *x = p->out + 3 * (size_t)i;
        x[0] = xi[0], x[1] = xi[1], x[2] = xi[2];
        x[0] += SMOOTHING_WEIGHT * t[0];
        x[1] += SMOOTHING_WEIGHT * t[1];
        x[2] += SMOOTHING_WEIGHT * t[2];
    }
    return 0;
}

/* Where level k's cycle leaves its solution: the coarsest level's sweeps
 * update x in place, a level above it ends in post (correct_smooth_range). */
static double *cycle_solution(const wc_multigrid *mg, int32_t k)
{
    return k + 1 == mg->levels ? mg->level[k].x : mg->level[k].post;
}

/* The restriction to a level and that level's first sweep, from x = 0,
 * in one loop: the sweep at aggregate a reads only the b[a] just summed,
 * so no thread waits between them. */
static int restrict_sweep_range(void *context, int64_t begin, int64_t end)
{
    const mg_pass *p = context;
    mg_pass sweep = {p->coarse, NULL, p->coarse->b, NULL, NULL, 0.0};
    restrict_range(context, begin, end);
    return sweep_range(&sweep, begin, end);
}

/* The cycle's loops run inside the caller's team (parallel.h): a level's
 * loops split across the team from LEVEL_PARALLEL_MIN nodes up, a smaller
 * level's run on the team's first thread. */
static int level_split(const wc_team *team, const level *l)
{
    return team->threads > 1 && l->n >= LEVEL_PARALLEL_MIN;
}

static void team_loop(const wc_team *team, int split, wc_range_fn body, level *l, level *c,
                      const double *in, double *out, int64_t count)
{
    mg_pass p = {l, c, in, out, NULL, 0.0};
    int64_t begin, end;
    wc_team_slice(team, count, split, &begin, &end);
    if (begin < end) body(&p, begin, end);
}

/* Between a loop and the next one that reads what it wrote at other
 * nodes, or writes what it read there: a barrier, unless both ran on the
 * first thread alone. */
static void sync_loops(const wc_team *team, int split_before, int split_after)
{
    if (split_before || split_after) wci_team_barrier(team);
}

/* r = b - A x on level l: the product's two passes, the second making r. */
static void residual(level *l, int split, const wc_team *team)
{
    team_loop(team, split, link_products_range, l, NULL, l->x, NULL, l->links);
    sync_loops(team, split, split);
    team_loop(team, split, residual_range, l, NULL, NULL, NULL, l->n);
}

/* One smoothing sweep after the first: the residual, then the sweep from
 * it. The sweep writes x, which the other nodes' residuals read. */
static void smooth(level *l, int split, const wc_team *team)
{
    residual(l, split, team);
    sync_loops(team, split, split);
    team_loop(team, split, sweep_range, l, NULL, l->r, NULL, l->n);
}

/* cycle_solution(k) = the V-cycle from coarse level k applied to the
 * restriction of `in` (minus `factor` times `minus`, when not NULL), the
 * finer level's residual (complete on entry).
 * Every loop of level k splits as level_split(team, level k), the
 * restriction to it too: a small level's whole cycle then runs on the
 * first thread without a barrier. The caller waits for the last loop. */
static void cycle(wc_multigrid *mg, int32_t k, const double *in, const double *minus,
                  double factor, const wc_team *team)
{
    level *f = &mg->level[k - 1], *l = &mg->level[k];
    int split = level_split(team, l);
    mg_pass restriction = {f, l, in, l->b, minus, factor};
    int64_t begin, end;
    wc_team_slice(team, l->n, split, &begin, &end);
    if (k + 1 == mg->levels && mg->factored) {
        /* at most EXACT_COARSEST_NODES nodes, below LEVEL_PARALLEL_MIN: the
         * first thread restricts and solves, alone */
        if (begin < end) restrict_range(&restriction, begin, end);
        if (begin < end) solve_coarsest(mg, l);
        return;
    }
    if (begin < end) restrict_sweep_range(&restriction, begin, end);
    sync_loops(team, split, split);
    if (k + 1 == mg->levels) {
        for (int s = 1; s < COARSEST_SWEEPS; ++s) {
            if (s > 1) sync_loops(team, split, split);
            smooth(l, split, team);
        }
        return;
    }
    level *c = &mg->level[k + 1];
    int split_c = level_split(team, c);
    residual(l, split, team);
    sync_loops(team, split, split_c);
    cycle(mg, k + 1, l->r, NULL, 0.0, team);
    sync_loops(team, split_c, split);
    team_loop(team, split, corrected_range, l, c, cycle_solution(mg, k + 1), NULL, l->n);
    sync_loops(team, split, split);
    team_loop(team, split, link_products_range, l, NULL, l->corrected, NULL, l->links);
    sync_loops(team, split, split);
    team_loop(team, split, correct_smooth_range, l, c, NULL, l->post, l->n);
}

void wci_multigrid_coarse_solve_team(wc_multigrid *mg, const double *r, const double *q,
                                    double alpha, const wc_team *team)
{
    cycle(mg, 1, r, q, alpha, team);
}

typedef struct coarse_solve_pass {
    wc_multigrid *mg;
    const double *r;
} coarse_solve_pass;

static void coarse_solve_body(void *context, const wc_team *team)
{
    const coarse_solve_pass *p = context;
    wci_multigrid_coarse_solve_team(p->mg, p->r, NULL, 0.0, team);
}

void wci_multigrid_coarse_solve(wc_multigrid *mg, const double *r, int threads)
{
    coarse_solve_pass p = {mg, r};
    wci_parallel_team(threads, coarse_solve_body, &p);
}

const double *wci_multigrid_coarse_solution(const wc_multigrid *mg)
{
    return cycle_solution(mg, 1);
}

const int32_t *wci_multigrid_fine_aggregates(const wc_multigrid *mg) { return mg->level[0].agg; }

void wci_multigrid_add_correction(wc_multigrid *mg, const double *r, double *z, int threads)
{
    wci_multigrid_coarse_solve(mg, r, threads);
    mg_pass p = {&mg->level[0], &mg->level[1], cycle_solution(mg, 1), z, NULL, 0.0};
    wci_parallel_for(mg->level[0].n, mg->level[0].n >= LEVEL_PARALLEL_MIN ? threads : 1,
                    prolong_range, &p);
}

int32_t wci_multigrid_level_size(const wc_multigrid *mg, int32_t k) { return mg->level[k].n; }

int32_t wci_multigrid_aggregate(const wc_multigrid *mg, int32_t k, int32_t node)
{
    return mg->level[k].agg[node];
}

/* With b = 0 the residual is -A x. */
void wci_multigrid_level_product(wc_multigrid *mg, int32_t k, const double *in, double *out)
{
    level *l = &mg->level[k];
    size_t len = 3 * (size_t)l->n;
    memcpy(l->x, in, len * sizeof *in);
    memset(l->b, 0, len * sizeof *l->b);
    mg_pass p = {l, NULL, l->x, NULL, NULL, 0.0};
    link_products_range(&p, 0, l->links);
    residual_range(&p, 0, l->n);
    for (size_t k = 0; k < len; ++k) out[k] = -l->r[k];
}
