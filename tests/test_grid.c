/* The broadphase grid (grid.c) and the colliders' tree (broadphase.c): on
 * randomised scenes, every query returns exactly the items a brute-force
 * scan finds (ascending, no duplicates), including items far larger than a
 * cell, queries larger than the grid allows cell by cell, and boxes that
 * merely touch; the tree also after its boxes moved and it was refit. */
#include <string.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "broadphase.h"
#include "grid.h"
#include "test_util.h"

static uint64_t rng = 0x2545F4914F6CDD1Dull;

static double uniform(double lo, double hi)
{
    rng ^= rng << 13, rng ^= rng >> 7, rng ^= rng << 17;
    return lo + (hi - lo) * (double)(rng >> 11) / 9007199254740992.0;
}

static void random_box(double box[6], double extent, double size)
{
    for (int k = 0; k < 3; ++k) {
        double c = uniform(-extent, extent), h = uniform(0.0, size);
        box[k] = c - h, box[k + 3] = c + h;
    }
}

/* One scene: n items of the given size, cells of cell_size, q queries. */
static void scene(int32_t n, double item_size, double cell_size, double query_size, int queries)
{
    double *boxes = malloc(6 * sizeof(double) * (size_t)n);
    int32_t *found = malloc(sizeof(int32_t) * (size_t)n), *expect = malloc(sizeof(int32_t) * (size_t)n);
    for (int32_t i = 0; i < n; ++i) random_box(boxes + 6 * i, 1.0, item_size * (i % 50 == 0 ? 20.0 : 1.0));
    wc_grid g;
    memset(&g, 0, sizeof g);
    CHECK(wci_grid_update(&g, boxes, n, cell_size) == WC_OK, "build failed");
    int mismatches = 0;
    long total = 0;
    for (int q = 0; q < queries; ++q) {
        double box[6];
        random_box(box, 1.2, query_size);
        if (q % 10 == 0) /* touching an item exactly counts */
            for (int k = 0; k < 3; ++k) box[k] = boxes[6 * (q % n) + k + 3], box[k + 3] = box[k] + 0.01;
        int32_t m = 0;
        for (int32_t i = 0; i < n; ++i)
            if (wc_boxes_overlap(box, boxes + 6 * i)) expect[m++] = i;
        int32_t got = wci_grid_query(&g, box, found, n);
        total += got;
        int same = got == m;
        for (int32_t k = 0; same && k < m; ++k) same = found[k] == expect[k];
        if (!same && mismatches++ < 3)
            fprintf(stderr, "query %d: grid found %d items, brute force %d\n", q, (int)got, (int)m);
    }
    printf("grid: %d items (size %.3f, cell %.3f), %d queries (size %.3f): %.1f items per query, "
           "%d mismatches\n", (int)n, item_size, cell_size, queries, query_size,
           (double)total / queries, mismatches);
    CHECK(mismatches == 0, "%d queries differ from brute force", mismatches);
    /* a capacity smaller than the result still reports the full count */
    double all[6] = {-2, -2, -2, 2, 2, 2};
    CHECK(wci_grid_query(&g, all, found, 3) == n, "count with a small buffer");
    wci_grid_destroy(&g);
    free(boxes);
    free(found);
    free(expect);
}

/* Boxes as large as an exploded cloth makes them (1e12 m, 1e300 m across):
 * the query must answer with the brute-force result, at once, rather than
 * walk its cells (a cell count that overflowed once made it hang). The
 * huge item goes to the large list; the huge query scans. */
static void huge_boxes(void)
{
    double boxes[18] = {0.0, 0.0, 0.0, 0.1, 0.1, 0.1,
                        -1e12, -1e12, -1e12, 1e12, 1e12, 1e12,
                        5.0, 5.0, 5.0, 5.1, 5.1, 5.1};
    wc_grid g;
    memset(&g, 0, sizeof g);
    CHECK(wci_grid_update(&g, boxes, 3, 0.05) == WC_OK, "build failed");
    double query[6] = {-1e300, -1e300, -1e300, 1e300, 1e300, 1e300}, small[6] = {0.05, 0.05, 0.05, 0.06, 0.06, 0.06};
    int32_t found[3] = {-1, -1, -1};
    int32_t n = wci_grid_query(&g, query, found, 3);
    CHECK(n == 3 && found[0] == 0 && found[1] == 1 && found[2] == 2, "huge query: %d items", (int)n);
    n = wci_grid_query(&g, small, found, 3);
    CHECK(n == 2 && found[0] == 0 && found[1] == 1, "small query: %d items", (int)n);
    wci_grid_destroy(&g);
}

/* The tree over n boxes: queries against brute force, then the boxes
 * moved far (a deforming collider) and the tree refit, queries again. */
static void tree(int32_t n, double item_size, double query_size, int queries)
{
    double *boxes = malloc(6 * sizeof(double) * (size_t)n);
    int32_t *found = malloc(sizeof(int32_t) * (size_t)n), *expect = malloc(sizeof(int32_t) * (size_t)n);
    for (int32_t i = 0; i < n; ++i) random_box(boxes + 6 * i, 1.0, item_size);
    wc_bvh b;
    memset(&b, 0, sizeof b);
    CHECK(wci_bvh_create(&b, boxes, n) == WC_OK, "tree build failed");
    int mismatches = 0;
    long total = 0;
    for (int round = 0; round < 2; ++round) {
        if (round == 1) {
            /* every box moves by up to half the scene: the shape stays, the
             * answers must not change from brute force */
            for (int32_t i = 0; i < n; ++i) {
                double shift[3] = {uniform(-0.5, 0.5), uniform(-0.5, 0.5), uniform(-0.5, 0.5)};
                for (int k = 0; k < 3; ++k) boxes[6 * i + k] += shift[k], boxes[6 * i + k + 3] += shift[k];
            }
            wci_bvh_refit(&b);
        }
        for (int q = 0; q < queries; ++q) {
            double box[6];
            random_box(box, 1.2, query_size);
            int32_t got = wci_bvh_query(&b, box, found, n), want = 0;
            for (int32_t i = 0; i < n; ++i)
                if (wc_boxes_overlap(box, boxes + 6 * i)) expect[want++] = i;
            total += want;
            if (got != want) {
                ++mismatches;
                continue;
            }
            for (int32_t k = 0; k < got; ++k)
                if (found[k] != expect[k]) {
                    ++mismatches;
                    break;
                }
        }
    }
    /* a full buffer: the count without overrun */
    double all[6] = {-10, -10, -10, 10, 10, 10};
    CHECK(wci_bvh_query(&b, all, found, 1) == n, "a query with a small buffer must still count all");
    /* every item at once: the sort's largest input, in the tree's order */
    int32_t every = wci_bvh_query(&b, all, found, n), out_of_order = every != n;
    for (int32_t k = 0; k < every && !out_of_order; ++k) out_of_order = found[k] != k;
    CHECK(!out_of_order, "a query of every item must give 0 .. %d in order", (int)n - 1);
    printf("tree: %d items, %d queries twice (after a refit), %ld hits, %d mismatches\n", (int)n,
           queries, total, mismatches);
    CHECK(mismatches == 0, "tree queries differ from brute force");
    wci_bvh_destroy(&b);
    free(boxes), free(found), free(expect);
}

int main(void)
{
    huge_boxes();
    tree(3000, 0.02, 0.1, 2000);
    tree(7, 0.3, 0.5, 200);
    tree(1, 0.1, 0.5, 100);
    scene(2000, 0.02, 0.05, 0.05, 3000);  /* cloth-like: small items, small queries */
    scene(500, 0.1, 0.02, 0.1, 2000);     /* items spanning many cells (the large list) */
    scene(3000, 0.01, 0.03, 1.5, 40);     /* queries spanning the whole grid (the scan) */
    scene(1, 0.1, 0.1, 0.5, 100);         /* a single item */
    return test_report("test_grid");
}
