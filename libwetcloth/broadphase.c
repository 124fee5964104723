#include "broadphase.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "alloc.h"

/* Deeper than a median-split tree over 2^27 items can get (27 levels). */
#define STACK_DEPTH 96


void wci_bvh_destroy(wc_bvh *b)
{
    wci_free(b->nodes);
    wci_free(b->order);
    memset(b, 0, sizeof *b);
}

static void empty_box(double box[6])
{
    for (int k = 0; k < 3; ++k) box[k] = INFINITY, box[k + 3] = -INFINITY;
}

/* Plain comparisons: a NaN bound leaves the box as it was. */
static void union_box(double box[6], const double add[6])
{
    for (int k = 0; k < 3; ++k) {
        if (add[k] < box[k]) box[k] = add[k];
        if (add[k + 3] > box[k + 3]) box[k + 3] = add[k + 3];
    }
}

/* Twice the centre of item i along an axis; NaN sorts last. The build
 * reads them from `keys` (xyz per item, made once): a node's split then
 * reads one number per item, where the boxes cost two and a box union. */
static double key(const double *boxes, int32_t i, int axis)
{
    double k = boxes[6 * (size_t)i + axis] + boxes[6 * (size_t)i + axis + 3];
    return k == k ? k : INFINITY;
}

static int before(const double *keys, int32_t a, int32_t b, int axis)
{
    double ka = keys[3 * (size_t)a + axis], kb = keys[3 * (size_t)b + axis];
    return ka < kb || (ka == kb && a < b);
}

/* Reorders items[0 .. n) so that items[m] is the one a full sort would put
 * there, smaller ones before it and larger after (quickselect, middle
 * pivot; deterministic). */
static void select_median(const double *keys, int32_t *items, int32_t n, int32_t m, int axis)
{
    int32_t lo = 0, hi = n - 1;
    while (lo < hi) {
        int32_t pivot = items[lo + (hi - lo) / 2], i = lo, j = hi;
        while (i <= j) {
            while (before(keys, items[i], pivot, axis)) ++i;
            while (before(keys, pivot, items[j], axis)) --j;
            if (i <= j) {
                int32_t t = items[i];
                items[i] = items[j], items[j] = t;
                ++i, --j;
            }
        }
        if (m <= j) hi = j;
        else if (m >= i) lo = i;
        else return;
    }
}

/* The axis along which the centres of items[0 .. n) spread most. */
static int split_axis(const double *keys, const int32_t *items, int32_t n)
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int32_t k = 0; k < n; ++k) {
        for (int a = 0; a < 3; ++a) {
            double c = keys[3 * (size_t)items[k] + a];
            if (c == INFINITY) continue;
            if (c < lo[a]) lo[a] = c;
            if (c > hi[a]) hi[a] = c;
        }
    }
    int axis = 0;
    for (int a = 1; a < 3; ++a)
        if (hi[a] - lo[a] > hi[axis] - lo[axis]) axis = a;
    return axis;
}

wc_status wci_bvh_create(wc_bvh *b, const double *boxes, int32_t count)
{
    wci_bvh_destroy(b);
    b->boxes = boxes;
    if (count <= 0) return WC_OK;
    b->order = wci_alloc_array((size_t)count, sizeof *b->order);
    b->nodes = wci_alloc_array(2 * (size_t)count, sizeof *b->nodes);
    double *keys = wci_alloc_array(3 * (size_t)count, sizeof *keys);
    if (!b->order || !b->nodes || !keys) {
        wci_free(keys);
        wci_bvh_destroy(b);
        return WC_ERROR_OUT_OF_MEMORY;
    }
    b->item_count = count;
    for (int32_t i = 0; i < count; ++i) {
        b->order[i] = i;
        for (int a = 0; a < 3; ++a) keys[3 * (size_t)i + a] = key(boxes, i, a);
    }
    /* Top-down: a node holds a run of `order`; one with more than a leaf's
     * worth is split at the median of its centres along its widest axis,
     * its children taking the two halves (allocated as a pair, after it:
     * refit relies on children coming after their parent). */
    int32_t stack[STACK_DEPTH], depth = 0;
    b->nodes[0].first = 0, b->nodes[0].count = count;
    b->node_count = 1;
    stack[depth++] = 0;
    while (depth > 0) {
        wc_bvh_node *node = b->nodes + stack[--depth];
        int32_t first = node->first, n = node->count;
        if (n <= WC_BVH_LEAF || depth + 2 > STACK_DEPTH) continue;
        int axis = split_axis(keys, b->order + first, n);
        int32_t half = n / 2;
        select_median(keys, b->order + first, n, half, axis);
        int32_t left = b->node_count;
        b->node_count += 2;
        b->nodes[left].first = first, b->nodes[left].count = half;
        b->nodes[left + 1].first = first + half, b->nodes[left + 1].count = n - half;
        node->first = left, node->count = 0;
        stack[depth++] = left + 1;
        stack[depth++] = left;
    }
    wci_free(keys);
    /* every node's box, leaves first */
    wci_bvh_refit(b);
    return WC_OK;
}

void wci_bvh_refit(wc_bvh *b)
{
    for (int32_t k = b->node_count - 1; k >= 0; --k) {
        wc_bvh_node *node = b->nodes + k;
        empty_box(node->box);
        if (node->count == 0) {
            union_box(node->box, b->nodes[node->first].box);
            union_box(node->box, b->nodes[node->first + 1].box);
        } else {
            for (int32_t j = 0; j < node->count; ++j)
                union_box(node->box, b->boxes + 6 * (size_t)b->order[node->first + j]);
        }
    }
}

static int overlap(const double a[6], const double b[6])
{
    return a[0] <= b[3] && b[0] <= a[3] && a[1] <= b[4] && b[1] <= a[4] && a[2] <= b[5] &&
           b[2] <= a[5];
}

static void swap_items(int32_t *a, int32_t i, int32_t j)
{
    int32_t t = a[i];
    a[i] = a[j], a[j] = t;
}

static void insertion_sort(int32_t *items, int32_t n)
{
    for (int32_t i = 1; i < n; ++i) {
        int32_t v = items[i], j = i;
        for (; j > 0 && items[j - 1] > v; --j) items[j] = items[j - 1];
        items[j] = v;
    }
}

/* Ascending, in place. A query's items are distinct, so the order is the
 * same whatever the sort; a typed quicksort (median of three, the smaller
 * side first so the stack stays shallow) costs a fraction of qsort's calls
 * through a comparison pointer, which particles outside their lists' cover
 * felt on a dense collider (5 % of its collision time). */
static void sort_items(int32_t *items, int32_t n)
{
    int32_t lo_stack[STACK_DEPTH], hi_stack[STACK_DEPTH], depth = 0, lo = 0, hi = n;
    for (;;) {
        while (hi - lo > 24 && depth < STACK_DEPTH) {
            int32_t *a = items + lo, m = (hi - lo) / 2, last = hi - lo - 1;
            /* median of the first, middle and last item, into the middle */
            if (a[m] < a[0]) swap_items(a, m, 0);
            if (a[last] < a[m]) swap_items(a, last, m);
            if (a[m] < a[0]) swap_items(a, m, 0);
            int32_t pivot = a[m], i = 0, j = last;
            while (i <= j) {
                while (a[i] < pivot) ++i;
                while (a[j] > pivot) --j;
                if (i <= j) swap_items(a, i++, j--);
            }
            /* [lo, lo + j] and [lo + i, hi): the larger waits on the stack */
            if (j + 1 < (hi - lo) - i) {
                lo_stack[depth] = lo + i, hi_stack[depth++] = hi;
                hi = lo + j + 1;
            } else {
                lo_stack[depth] = lo, hi_stack[depth++] = lo + j + 1;
                lo = lo + i;
            }
        }
        insertion_sort(items + lo, hi - lo);
        if (depth == 0) return;
        --depth;
        lo = lo_stack[depth], hi = hi_stack[depth];
    }
}

int32_t wci_bvh_collect(const wc_bvh *b, const double box[6], int32_t *out, int32_t capacity)
{
    if (b->node_count == 0) return 0;
    int32_t stack[STACK_DEPTH], depth = 0, found = 0;
    stack[depth++] = 0;
    while (depth > 0) {
        const wc_bvh_node *node = b->nodes + stack[--depth];
        if (!overlap(node->box, box)) continue;
        if (node->count == 0) {
            stack[depth++] = node->first + 1;
            stack[depth++] = node->first;
            continue;
        }
        for (int32_t j = 0; j < node->count; ++j) {
            int32_t item = b->order[node->first + j];
            if (!overlap(b->boxes + 6 * (size_t)item, box)) continue;
            if (found < capacity) out[found] = item;
            ++found;
        }
    }
    return found;
}

int32_t wci_bvh_query(const wc_bvh *b, const double box[6], int32_t *out, int32_t capacity)
{
    int32_t found = wci_bvh_collect(b, box, out, capacity);
    /* only a complete answer is sorted; the caller asks again with room */
    if (found <= capacity) sort_items(out, found);
    return found;
}

static void box_join(double *into, const double *box)
{
    for (int k = 0; k < 3; ++k) {
        if (box[k] < into[k]) into[k] = box[k];
        if (box[k + 3] > into[k + 3]) into[k + 3] = box[k + 3];
    }
}

static int box_holds(const double *outer, const double *inner)
{
    for (int k = 0; k < 3; ++k)
        if (inner[k] < outer[k] || inner[k + 3] > outer[k + 3]) return 0;
    return 1;
}

static void box_empty(double *box)
{
    for (int k = 0; k < 3; ++k) box[k] = INFINITY, box[k + 3] = -INFINITY;
}

void wci_bvh_fold_boxes(const wc_bvh *b, const double *item_boxes, double *node_boxes)
{
    /* children come after their parent (wci_bvh_create) */
    for (int32_t k = b->node_count - 1; k >= 0; --k) {
        const wc_bvh_node *node = b->nodes + k;
        double *out = node_boxes + 6 * (size_t)k;
        box_empty(out);
        if (node->count == 0) {
            box_join(out, node_boxes + 6 * (size_t)node->first);
            box_join(out, node_boxes + 6 * ((size_t)node->first + 1));
        } else {
            for (int32_t j = 0; j < node->count; ++j)
                box_join(out, item_boxes + 6 * (size_t)b->order[node->first + j]);
        }
    }
}

/* Whether every side of a box is at most `size`. */
static int box_within_size(const double *box, double size)
{
    return box[3] - box[0] <= size && box[4] - box[1] <= size && box[5] - box[2] <= size;
}

int wci_bvh_union_within(const wc_bvh *b, const double *item_boxes, const double *node_boxes,
                         const double box[6], double whole_below, double out[6])
{
    box_empty(out);
    if (b->node_count == 0) return 0;
    int32_t stack[STACK_DEPTH], depth = 0;
    int any = 0;
    stack[depth++] = 0;
    while (depth > 0) {
        int32_t k = stack[--depth];
        const wc_bvh_node *node = b->nodes + k;
        if ((any && box_holds(out, node_boxes + 6 * (size_t)k)) || !overlap(node->box, box)) continue;
        /* a node inside the box: every item of it overlaps, its value box is
         * theirs; a small one is taken whole too */
        if (box_holds(box, node->box) || box_within_size(node->box, whole_below)) {
            box_join(out, node_boxes + 6 * (size_t)k), any = 1;
            continue;
        }
        if (node->count == 0) {
            stack[depth++] = node->first + 1;
            stack[depth++] = node->first;
            continue;
        }
        for (int32_t j = 0; j < node->count; ++j) {
            int32_t item = b->order[node->first + j];
            if (overlap(b->boxes + 6 * (size_t)item, box)) box_join(out, item_boxes + 6 * (size_t)item), any = 1;
        }
    }
    return any;
}

double wci_bvh_root_distance(const wc_bvh *b, const double p[3])
{
    if (b->node_count == 0) return INFINITY;
    const double *box = b->nodes[0].box;
    double g2 = 0.0;
    for (int k = 0; k < 3; ++k) {
        double g = box[k] - p[k] > p[k] - box[k + 3] ? box[k] - p[k] : p[k] - box[k + 3];
        if (g > 0.0) g2 += g * g;
    }
    return sqrt(g2);
}
