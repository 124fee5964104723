/* Broadphase: a bounding volume hierarchy over axis-aligned boxes (a
 * collider's triangles). Built once from the boxes, top-down by median
 * splits of the box centres; when the boxes change (a deforming collider)
 * it is refit, not rebuilt: the tree keeps its shape and every node's box
 * becomes the union of its children's again. A refit tree stays correct
 * however far the items move (only its culling gets looser), so a collider
 * whose vertices are animated pays one pass over its triangles per frame,
 * not a rebuild per substep.
 *
 * Why a tree and not a grid sized by one cell: a query's cost should follow
 * what it finds. A uniform grid sized by the triangles visits every cell of
 * a query box, and a query box as large as the contact distance (0.02 m, a
 * few mm of cloth thickness) around a collider of 1 cm triangles is a
 * hundred cells; the tree visits only nodes whose boxes meet it.
 *
 * Building is serial and deterministic (ties by item index); queries only
 * read, and return the items in ascending order, so results do not depend on
 * the thread count or on the tree's shape. */
#ifndef WC_BROADPHASE_H
#define WC_BROADPHASE_H

#include <stdint.h>

#include "wetcloth.h"

/// Items per leaf at most.
#define WC_BVH_LEAF 4

typedef struct wc_bvh_node {
    double box[6];
    /// Internal node: its children are nodes `first` and `first + 1`
    /// (count 0). Leaf: items order[first .. first + count).
    int32_t first;
    int32_t count;
} wc_bvh_node;

typedef struct wc_bvh {
    int32_t item_count;
    int32_t node_count;
    wc_bvh_node *nodes;
    /// Items in leaf order.
    int32_t *order;
    /// The item boxes (6 doubles each: min xyz, max xyz), kept by pointer:
    /// they must outlive the queries and be current when refit is called.
    const double *boxes;
} wc_bvh;

/// A zeroed wc_bvh is the empty tree (no memory); this frees its memory and
/// leaves it zeroed, empty again.
void wci_bvh_destroy(wc_bvh *bvh);

/// Builds the tree over `count` boxes. Non-finite boxes are allowed (they
/// meet no query). WC_ERROR_OUT_OF_MEMORY on failure (the tree is then empty).
wc_status wci_bvh_create(wc_bvh *bvh, const double *boxes, int32_t count);

/// After the boxes changed in place: every node's box made from them again.
void wci_bvh_refit(wc_bvh *bvh);

/// Items whose boxes overlap `box` (touching counts), ascending, into out (up
/// to capacity); returns how many there are (which may exceed capacity).
int32_t wci_bvh_query(const wc_bvh *bvh, const double box[6], int32_t *out, int32_t capacity);

/// The same, in the tree's order (not sorted): for callers that sort what
/// they keep of it themselves.
int32_t wci_bvh_collect(const wc_bvh *bvh, const double box[6], int32_t *out, int32_t capacity);

/// After the items' value boxes changed: each node's value box becomes the
/// union of its items' (`item_boxes` and `node_boxes` hold 6 doubles each,
/// min xyz then max xyz). A value box is any box attached to an item, apart
/// from the item's box in space: the collider's is the box of its
/// vertices' displacements in a step (collider.h).
void wci_bvh_fold_boxes(const wc_bvh *bvh, const double *item_boxes, double *node_boxes);

/// The union of the value boxes of the items whose boxes overlap `box`, into
/// `out`, and perhaps of some more: a node whose box overlaps `box` and has
/// no side longer than `whole_below` is taken whole (0: none is). Returns
/// 0 (and leaves `out` empty: min > max) if there are none. Uses the node
/// value boxes that wci_bvh_fold_boxes made from the same item boxes to
/// skip every node whose value box the union already holds.
int wci_bvh_union_within(const wc_bvh *bvh, const double *item_boxes, const double *node_boxes,
                         const double box[6], double whole_below, double out[6]);

/// Distance from point p to the tree's root box (0 inside it; +inf for an
/// empty tree): no item is nearer.
double wci_bvh_root_distance(const wc_bvh *bvh, const double p[3]);

#endif
