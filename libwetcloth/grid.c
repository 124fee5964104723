#include "grid.h"

#include <math.h>
#include <string.h>

#include "alloc.h"

/* An item spanning more cells than this along the three axes together is
 * kept in the `large` list instead of being written into every cell. */
#define MAX_CELLS_PER_ITEM 64
/* A query spanning more cells than this scans all items instead. */
#define MAX_CELLS_PER_QUERY 4096


void wci_grid_destroy(wc_grid *g)
{
    wci_free(g->start);
    wci_free(g->items);
    wci_free(g->large);
    wci_free(g->corner);
    memset(g, 0, sizeof *g);
}

/* Cell coordinate of a value; clamped so huge coordinates cannot overflow,
 * and NaN (a step going non-finite, caught after collision) goes to the
 * low end instead of an undefined conversion. */
static int32_t cell_of(double value, double inv_cell)
{
    double c = floor(value * inv_cell);
    if (!(c >= -1e9)) c = -1e9;
    if (c > 1e9) c = 1e9;
    return (int32_t)c;
}

static uint32_t bucket_of(const wc_grid *g, int32_t ix, int32_t iy, int32_t iz)
{
    uint32_t h = ((uint32_t)ix * 73856093u) ^ ((uint32_t)iy * 19349663u) ^ ((uint32_t)iz * 83492791u);
    return h & g->bucket_mask;
}

static void cell_range(const double box[6], double inv_cell, int32_t lo[3], int32_t hi[3])
{
    for (int k = 0; k < 3; ++k) {
        lo[k] = cell_of(box[k], inv_cell);
        hi[k] = cell_of(box[k + 3], inv_cell);
    }
}

/* Cells in a range, saturated: the product of three spans of up to 2e9+1
 * cells each (clamped coordinates of an exploded or huge box) overflows
 * int64, and a wrapped count once sent such a query cell by cell through
 * ~1e27 cells. Any span over CELLS_SATURATE makes the range count as that
 * many cells, far above both limits below. */
#define CELLS_SATURATE ((int64_t)1 << 20)
static int64_t cells_in(const int32_t lo[3], const int32_t hi[3])
{
    int64_t cells = 1;
    for (int k = 0; k < 3; ++k) {
        int64_t span = (int64_t)hi[k] - lo[k] + 1;
        /* An empty box (min above max on an axis: the box of corners whose
         * coordinates there are all NaN) covers no cell. Its negative span
         * once went into the entry count while the insertion loops wrote
         * the other items' cells past the end (found by fuzzing). */
        if (span <= 0) return 0;
        if (span > CELLS_SATURATE) return CELLS_SATURATE;
        cells *= span;
        if (cells > CELLS_SATURATE) return CELLS_SATURATE;
    }
    return cells;
}

/* Visits every cell of an item's range: pass 0 counts, pass 1 writes. */
static void insert_item(wc_grid *g, int32_t item, const int32_t lo[3], const int32_t hi[3],
                        int32_t *fill, int pass)
{
    for (int32_t z = lo[2]; z <= hi[2]; ++z)
        for (int32_t y = lo[1]; y <= hi[1]; ++y)
            for (int32_t x = lo[0]; x <= hi[0]; ++x) {
                uint32_t b = bucket_of(g, x, y, z);
                if (pass == 0) {
                    g->start[b + 1]++;
                } else {
                    int32_t at = g->start[b] + fill[b];
                    /* two cells of one item may share a bucket: store it once */
                    if (fill[b] > 0 && g->items[at - 1] == item) continue;
                    g->items[at] = item;
                    fill[b]++;
                }
            }
}

wc_status wci_grid_update(wc_grid *g, const double *boxes, int32_t count, double cell_size)
{
    g->boxes = boxes;
    g->item_count = count;
    g->cell_size = cell_size;
    double inv = 1.0 / cell_size;
    int64_t buckets = 64;
    while (buckets < 2 * (int64_t)count) buckets *= 2;
    if (buckets > g->table_capacity) {
        wci_free(g->start);
        g->start = wci_alloc_array((size_t)buckets + 1, sizeof *g->start);
        g->table_capacity = g->start ? buckets : 0;
        if (!g->start) return WC_ERROR_OUT_OF_MEMORY;
    }
    g->bucket_mask = (uint32_t)(buckets - 1);
    if (count > g->corner_capacity) {
        wci_free(g->corner);
        g->corner = wci_alloc_array(3 * (size_t)count, sizeof *g->corner);
        g->corner_capacity = g->corner ? count : 0;
        if (!g->corner) return WC_ERROR_OUT_OF_MEMORY;
    }
    memset(g->start, 0, ((size_t)buckets + 1) * sizeof *g->start);
    int64_t entries = 0, large = 0;
    for (int32_t i = 0; i < count; ++i) {
        int32_t lo[3], hi[3];
        cell_range(boxes + 6 * (size_t)i, inv, lo, hi);
        memcpy(g->corner + 3 * (size_t)i, lo, sizeof lo);
        int64_t cells = cells_in(lo, hi);
        if (cells == 0) continue; /* empty: in no cell, and no loop over its other axes */
        if (cells > MAX_CELLS_PER_ITEM) {
            ++large;
            continue;
        }
        entries += cells;
        insert_item(g, i, lo, hi, NULL, 0);
    }
    if (entries > g->entry_capacity || large > 0) {
        if (entries > g->entry_capacity) {
            wci_free(g->items);
            g->items = wci_alloc_array((size_t)entries, sizeof *g->items);
            g->entry_capacity = g->items ? entries : 0;
        }
        wci_free(g->large);
        g->large = large ? wci_alloc_array((size_t)large, sizeof *g->large) : NULL;
        if ((entries && !g->items) || (large && !g->large)) return WC_ERROR_OUT_OF_MEMORY;
    }
    int32_t *fill = wci_alloc_array((size_t)buckets, sizeof *fill);
    if (!fill) return WC_ERROR_OUT_OF_MEMORY;
    for (int64_t b = 0; b < buckets; ++b) g->start[b + 1] += g->start[b];
    g->large_count = 0;
    for (int32_t i = 0; i < count; ++i) {
        int32_t lo[3], hi[3];
        cell_range(boxes + 6 * (size_t)i, inv, lo, hi);
        int64_t cells = cells_in(lo, hi);
        if (cells > MAX_CELLS_PER_ITEM) g->large[g->large_count++] = i;
        else if (cells > 0) insert_item(g, i, lo, hi, fill, 1);
    }
    /* Duplicates skipped in pass 1 leave gaps at bucket ends; close them so
     * start[] describes the filled entries exactly. */
    int32_t write = 0;
    for (int64_t b = 0; b < (int64_t)buckets; ++b) {
        int32_t begin = g->start[b];
        g->start[b] = write;
        for (int32_t k = 0; k < fill[b]; ++k) g->items[write++] = g->items[begin + k];
    }
    g->start[buckets] = write;
    wci_free(fill);
    return WC_OK;
}

/* Sorts out[0 .. n) (short lists: insertion sort). */
static void sort_items(int32_t *out, int32_t n)
{
    for (int32_t i = 1; i < n; ++i) {
        int32_t item = out[i], j = i;
        while (j > 0 && out[j - 1] > item) out[j] = out[j - 1], --j;
        out[j] = item;
    }
}

/* Writes an item if there is room; returns the new count either way. */
static int32_t emit(int32_t *out, int32_t n, int32_t capacity, int32_t item)
{
    if (n < capacity) out[n] = item;
    return n + 1;
}

/* An item overlapping several cells of the query is reported only from the
 * first of them (the lowest corner of the overlap), so no item comes twice
 * and nothing has to be searched or merged while collecting. A hash
 * collision can put an item into a bucket of a cell it does not touch; the
 * corner test rejects it there, because that cell is not its corner. */
static int reported_here(const wc_grid *g, int32_t item, const int32_t query_lo[3], int32_t x,
                         int32_t y, int32_t z)
{
    const int32_t *corner = g->corner + 3 * (size_t)item;
    int32_t cx = corner[0] > query_lo[0] ? corner[0] : query_lo[0];
    int32_t cy = corner[1] > query_lo[1] ? corner[1] : query_lo[1];
    int32_t cz = corner[2] > query_lo[2] ? corner[2] : query_lo[2];
    return cx == x && cy == y && cz == z;
}

/* A query inside one cell reads one bucket. Its items are unique (an item
 * is stored once per bucket) and ascending (stored in item order), and the
 * overlap test drops what a hash collision put there, so it needs neither
 * the corner test nor sorting. */
static int32_t query_one_cell(const wc_grid *g, const double box[6], const int32_t cell[3],
                              int32_t *out, int32_t n, int32_t capacity)
{
    uint32_t b = bucket_of(g, cell[0], cell[1], cell[2]);
    for (int32_t k = g->start[b]; k < g->start[b + 1]; ++k)
        if (wc_boxes_overlap(box, g->boxes + 6 * (size_t)g->items[k])) n = emit(out, n, capacity, g->items[k]);
    return n;
}

int32_t wci_grid_query(const wc_grid *g, const double box[6], int32_t *out, int32_t capacity)
{
    int32_t n = 0;
    for (int32_t k = 0; k < g->large_count; ++k)
        if (wc_boxes_overlap(box, g->boxes + 6 * (size_t)g->large[k])) n = emit(out, n, capacity, g->large[k]);
    int32_t lo[3], hi[3];
    cell_range(box, 1.0 / g->cell_size, lo, hi);
    int64_t cells = cells_in(lo, hi);
    /* An empty query box (min above max on an axis) meets nothing; looping
     * over its other axes, up to 2e9 cells each, never ended (found by
     * fuzzing). */
    if (cells == 0) return n;
    if (cells > MAX_CELLS_PER_QUERY) {
        n = 0; /* scan all instead, in order (the large items come again) */
        for (int32_t i = 0; i < g->item_count; ++i)
            if (wc_boxes_overlap(box, g->boxes + 6 * (size_t)i)) n = emit(out, n, capacity, i);
        return n;
    }
    if (lo[0] == hi[0] && lo[1] == hi[1] && lo[2] == hi[2]) {
        n = query_one_cell(g, box, lo, out, n, capacity);
        if (g->large_count && n <= capacity) sort_items(out, n);
        return n;
    }
    for (int32_t z = lo[2]; z <= hi[2]; ++z)
        for (int32_t y = lo[1]; y <= hi[1]; ++y)
            for (int32_t x = lo[0]; x <= hi[0]; ++x) {
                uint32_t b = bucket_of(g, x, y, z);
                for (int32_t k = g->start[b]; k < g->start[b + 1]; ++k) {
                    int32_t item = g->items[k];
                    if (wc_boxes_overlap(box, g->boxes + 6 * (size_t)item) &&
                        reported_here(g, item, lo, x, y, z))
                        n = emit(out, n, capacity, item);
                }
            }
    if (n <= capacity) sort_items(out, n);
    return n;
}
