/* Coarse levels for the implicit integrator's preconditioner (implicit.c):
 * a correction over coarser copies of the cloth added to block-Jacobi.
 *
 * Why: with block-Jacobi alone the conjugate gradients' iteration count
 * grows with the cloth's resolution (38 per step at 20 x 20, 165 at
 * 101 x 101 on the thesis drape at 12 steps per frame), because a correction
 * travels about one link per iteration. The coarse levels carry it across
 * the cloth in one application.
 *
 * The matrix of every level has the form
 *   (A x)_i = D_i x_i + sum over the links e = (i, j) at i of B_e (x_i - x_j)
 * with D_i and B_e symmetric 3 x 3 blocks; at the finest level D is the
 * mass (with drag) and B the links' h^2 K + h C blocks. Nodes are grouped
 * into aggregates (a node and its neighbours, greedily in index order), and
 * a coarse matrix is the Galerkin product P^T A P with P constant over each
 * aggregate (unsmoothed aggregation). For this form the product has the
 * same form: an aggregate's D is the sum of its members' D (plus the blocks
 * of their links to pinned particles, whose values are known), a coarse
 * link's B the sum of the blocks of the fine links between its two
 * aggregates, and links inside an aggregate cancel. So the structure is
 * built once from the topology, and each step only sums blocks.
 *
 * The preconditioner is additive at the finest level,
 *   z = D_full^-1 r + P C P^T r,
 * with C a V-cycle over the coarse levels (one damped block-Jacobi sweep
 * before and after each coarse correction, four on the coarsest level).
 * The additive form needs no product with the fine matrix, which is most of
 * an iteration's cost: a full V-cycle from the finest level cut the
 * iterations further but cost more than it saved (docs/model.md). With it
 * the drape's iterations fall 1.5x at 5,041 particles and 1.7x at 10,201. Equal
 * sweeps before and after make C symmetric positive definite, and so is z's
 * operator, as conjugate gradients need. Every loop gathers per node in a
 * fixed order: the same bits for any thread count. */
#ifndef WC_MULTIGRID_H
#define WC_MULTIGRID_H

#include <stdint.h>

#include "parallel.h"

/// Cloths with fewer particles get no coarse levels: below about this size
/// the coarse levels cost more per iteration than they save in iterations
/// (measured on the thesis drape at 12 steps per frame: 7 % slower at 2,500
/// particles, 1.2x and 1.3-1.45x faster at 5,041 and 10,201; docs/model.md).
#define WC_MULTIGRID_MIN_PARTICLES 4096

typedef struct wc_multigrid wc_multigrid;

/// The coarse levels of a cloth of n particles: the links' ends (`links` of
/// them), each particle's links as CSR (`adj_start`, n + 1 entries; an entry
/// k >= 0 is link k with the particle at its first end, ~k at its second),
/// and how many of the first links define the neighbours that aggregates
/// are made of (the stretch links: the bend links reach one particle further
/// and would make aggregates too large). The arrays are borrowed and must
/// outlive the result. Sets *out to NULL when the cloth is too small to
/// coarsen (or does not shrink); returns 1 when out of memory, else 0.
int wci_multigrid_create(int32_t n, int32_t links, const int32_t *end_a, const int32_t *end_b,
                        int32_t neighbour_links, const int32_t *adj_start, const int32_t *adj,
                        wc_multigrid **out);
void wci_multigrid_destroy(wc_multigrid *mg);

/// Levels including the finest.
int32_t wci_multigrid_levels(const wc_multigrid *mg);

/// The step's matrix: per particle the mass with drag (`mass_diag`, a
/// multiple of the identity), the link blocks (6 values: xx, xy, xz, yy,
/// yz, zz), link e's at `block_slot[e]` (-1: e has none this step), or at e
/// when `block_slot` is NULL, and the pins (`pin_slot` >= 0: pinned; their
/// rows and columns are removed; NULL when nothing is pinned, which spares
/// the levels' updates and restrictions their checks). The arrays are
/// borrowed until the next update.
void wci_multigrid_update(wc_multigrid *mg, const double *mass_diag, const double *block,
                         const int32_t *block_slot, const int32_t *pin_slot, int threads);

/// z += P C P^T r, the coarse levels' part of the preconditioner; r is
/// zero at pins and z is left unchanged there.
void wci_multigrid_add_correction(wc_multigrid *mg, const double *r, double *z, int threads);

/// The same in two halves, for a caller that adds the correction in a pass
/// of its own over the fine nodes (implicit.c, with its block-Jacobi step
/// and a dot product): C P^T r, 3 values per aggregate of the finest
/// level, valid until the next call; a free fine node i adds entry
/// aggregates[i] of it (P), a pinned node nothing.
void wci_multigrid_coarse_solve(wc_multigrid *mg, const double *r, int threads);
/// The same on a team already running (wci_parallel_team), every thread
/// calling it, for the residual r - alpha q (q NULL: r), computed where it
/// is read as (r - alpha * q) is: r and q must be complete on entry (a
/// barrier after the loops that wrote them), and the solution is complete
/// after the caller's next wci_team_barrier. So a caller can update r out
/// of place in the same phase.
void wci_multigrid_coarse_solve_team(wc_multigrid *mg, const double *r, const double *q,
                                    double alpha, const wc_team *team);
const double *wci_multigrid_coarse_solution(const wc_multigrid *mg);
const int32_t *wci_multigrid_fine_aggregates(const wc_multigrid *mg);

/* For tests (tests/test_multigrid.c): a level's node count, the aggregate
 * (node of level + 1) of one of its nodes, and the product with a coarse
 * level's matrix, out = A in (level >= 1, after an update). */
int32_t wci_multigrid_level_size(const wc_multigrid *mg, int32_t level);
int32_t wci_multigrid_aggregate(const wc_multigrid *mg, int32_t level, int32_t node);
void wci_multigrid_level_product(wc_multigrid *mg, int32_t level, const double *in, double *out);

#endif
