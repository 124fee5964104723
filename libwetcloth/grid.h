/* Broadphase: a uniform grid stored as a spatial hash. Items are axis-aligned
 * boxes; a query returns every item whose box overlaps the query box, in
 * ascending order, without duplicates. Building is serial and in item order,
 * queries only read, so results are the same for any thread count. */
#ifndef WC_GRID_H
#define WC_GRID_H

#include <stdint.h>

#include "wetcloth.h"

typedef struct wc_grid {
    double cell_size;
    int32_t item_count;
    /// The boxes the grid was built from, 6 doubles per item (min xyz, max xyz).
    const double *boxes;
    /// Hash table: items of bucket b are items[start[b] .. start[b+1]).
    uint32_t bucket_mask;
    int32_t *start;
    int32_t *items;
    /// Per item, the cell holding its lowest corner (3 per item), so a
    /// query tells in integers from which of its cells an item is reported.
    int32_t *corner;
    /// Items too large to hash cell by cell; every query tests them.
    int32_t *large;
    int32_t large_count;
    int64_t table_capacity;
    int64_t entry_capacity;
    int64_t corner_capacity;
} wc_grid;

/// Empty grid (no memory).
void wci_grid_destroy(wc_grid *grid);

/// (Re)builds the grid over `count` boxes (6 doubles each, kept by pointer:
/// they must outlive the queries) with cubic cells of cell_size metres.
/// Reuses its memory when large enough. WC_ERROR_OUT_OF_MEMORY on failure.
wc_status wci_grid_update(wc_grid *grid, const double *boxes, int32_t count, double cell_size);

/// Writes into out (up to capacity) the items overlapping box, ascending and
/// unique, and returns how many there are (which may exceed capacity).
int32_t wci_grid_query(const wc_grid *grid, const double box[6], int32_t *out, int32_t capacity);

/// Whether two boxes overlap (touching counts). Inline: the collision
/// passes call it for every candidate pair.
static inline int wc_boxes_overlap(const double a[6], const double b[6])
{
    return a[0] <= b[3] && b[0] <= a[3] && a[1] <= b[4] && b[1] <= a[4] && a[2] <= b[5] &&
           b[2] <= a[5];
}

#endif
