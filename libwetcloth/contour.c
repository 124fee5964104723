/* The contour condition of the normal-cone cull: see contour.h for the
 * argument. */
#include "contour.h"

#include <math.h>
#include <stdlib.h>

#include "vec3.h"

/* Relative size of the margins that keep a comparison from being decided by
 * rounding: projected coordinates carry errors of a few ulps of the
 * positions, far below this fraction of an edge. */
#define ROUNDING 1e-9
/* Above this many segments the pairs are found by sorting. */
#define SWEEP_FROM 64

static int compare_halves(const void *pa, const void *pb)
{
    const wc_half_edge *p = pa, *q = pb;
    if (p->lo != q->lo) return p->lo < q->lo ? -1 : 1;
    if (p->hi != q->hi) return p->hi < q->hi ? -1 : 1;
    return p->from < q->from ? -1 : (p->from > q->from);
}

static int compare_from(const void *pa, const void *pb)
{
    const wc_half_edge *p = pa, *q = pb;
    return p->from < q->from ? -1 : (p->from > q->from);
}

static int compare_int32(const void *pa, const void *pb)
{
    int32_t p = *(const int32_t *)pa, q = *(const int32_t *)pb;
    return p < q ? -1 : (p > q);
}

static int32_t find_root(int32_t *parent, int32_t i)
{
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
}

/* Position in halves[0 .. count) (sorted by from) of the half-edge leaving
 * particle v, or -1. */
static int32_t leaving(const wc_half_edge *halves, int32_t count, int32_t v)
{
    int32_t lo = 0, hi = count;
    while (lo < hi) {
        int32_t mid = lo + (hi - lo) / 2;
        if (halves[mid].from < v) lo = mid + 1;
        else hi = mid;
    }
    return lo < count && halves[lo].from == v ? lo : -1;
}

/* Whether the boundary half-edges halves[0 .. count), sorted by from, leave
 * each vertex once and follow each other round one loop through all. */
static int one_loop(const wc_half_edge *halves, int32_t count)
{
    if (count < 3) return 0;
    for (int32_t k = 1; k < count; ++k)
        if (halves[k].from == halves[k - 1].from) return 0;
    /* With each vertex left once, "next" is a function on the half-edges;
     * coming back to the first after exactly count steps, and not before,
     * makes it one cycle through all of them. */
    int32_t at = 0;
    for (int32_t steps = 1; steps <= count; ++steps) {
        at = leaving(halves, count, halves[at].to);
        if (at < 0) return 0;
        if (at == 0) return steps == count;
    }
    return 0;
}

int wci_region_is_disk(const int32_t *triangles, const int32_t *list, int32_t count,
                       wc_half_edge *halves, int32_t *vertices)
{
    if (count <= 0) return 0;
    int32_t m = 3 * count;
    for (int32_t k = 0; k < count; ++k) {
        const int32_t *tri = triangles + 3 * (size_t)list[k];
        for (int j = 0; j < 3; ++j) {
            int32_t a = tri[j], b = tri[(j + 1) % 3];
            if (a == b) return 0;
            wc_half_edge *h = halves + 3 * k + j;
            h->lo = a < b ? a : b, h->hi = a < b ? b : a, h->from = a, h->to = b, h->owner = k;
            vertices[3 * k + j] = a;
        }
    }
    qsort(vertices, (size_t)m, sizeof *vertices, compare_int32);
    int32_t vertex_count = 0;
    for (int32_t k = 0; k < m; ++k) vertex_count += k == 0 || vertices[k] != vertices[k - 1];

    /* Edges: one half-edge is boundary; two must run opposite ways (the
     * triangles are oriented alike) and join their triangles; more is not a
     * surface. Boundary half-edges are compacted to the front as they are
     * found (never past the group being read). */
    int32_t *parent = vertices; /* the vertex count is taken: reuse for union-find */
    for (int32_t k = 0; k < count; ++k) parent[k] = k;
    qsort(halves, (size_t)m, sizeof *halves, compare_halves);
    int32_t edge_count = 0, boundary = 0;
    for (int32_t i = 0; i < m;) {
        int32_t j = i + 1;
        while (j < m && halves[j].lo == halves[i].lo && halves[j].hi == halves[i].hi) ++j;
        ++edge_count;
        if (j - i > 2) return 0;
        if (j - i == 2) {
            if (halves[i].from == halves[i + 1].from) return 0;
            int32_t a = find_root(parent, halves[i].owner), b = find_root(parent, halves[i + 1].owner);
            if (a != b) parent[a < b ? b : a] = a < b ? a : b;
        } else {
            halves[boundary++] = halves[i];
        }
        i = j;
    }
    for (int32_t k = 1; k < count; ++k)
        if (find_root(parent, k) != find_root(parent, 0)) return 0;
    if (vertex_count - edge_count + count != 1) return 0;
    /* Connected, oriented, one boundary loop through its vertices once and
     * Euler characteristic 1 = 2 - 2 genus - loops: genus 0, a disk. (A
     * pinch at an inner vertex would lower the characteristic below what
     * a surface with a boundary can have.) */
    qsort(halves, (size_t)boundary, sizeof *halves, compare_from);
    return one_loop(halves, boundary);
}

/* Two unit vectors across d, so that (e1, e2, d) is right-handed. */
static void plane_basis(const double d[3], double e1[3], double e2[3])
{
    double a[3] = {0.0, 0.0, 0.0};
    double x = fabs(d[0]), y = fabs(d[1]), z = fabs(d[2]);
    a[x <= y ? (x <= z ? 0 : 2) : (y <= z ? 1 : 2)] = 1.0;
    cross3(d, a, e1);
    normalize3(e1);
    cross3(d, e1, e2);
}

static void project(const double e1[3], const double e2[3], double px, double py, double pz,
                    double out[2])
{
    double p[3] = {px, py, pz};
    out[0] = dot3(p, e1), out[1] = dot3(p, e2);
}

static double cross2(const double a[2], const double b[2]) { return a[0] * b[1] - a[1] * b[0]; }
static double dot2(const double a[2], const double b[2]) { return a[0] * b[0] + a[1] * b[1]; }

static double orient2(const double a[2], const double b[2], const double c[2])
{
    double u[2] = {b[0] - a[0], b[1] - a[1]}, v[2] = {c[0] - a[0], c[1] - a[1]};
    return cross2(u, v);
}

static double point_segment2(const double p[2], const double a[2], const double b[2])
{
    double ab[2] = {b[0] - a[0], b[1] - a[1]}, ap[2] = {p[0] - a[0], p[1] - a[1]};
    double len2 = dot2(ab, ab), t = len2 > 0.0 ? dot2(ap, ab) / len2 : 0.0;
    t = t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t;
    double d[2] = {ap[0] - ab[0] * t, ap[1] - ab[1] * t};
    return sqrt(dot2(d, d));
}

/* The cross product of two vectors moving linearly over the step, a0 -> a1
 * and b0 -> b1, is the quadratic (1-t)^2 k0 + 2t(1-t) k1 + t^2 k2 (k1 the
 * mean of the mixed terms) and stays between its Bernstein coefficients k;
 * returns a rounding tolerance for them, relative to the vectors' sizes. */
static double cross_bounds(const double a0[2], const double a1[2], const double b0[2],
                           const double b1[2], double k[3])
{
    k[0] = cross2(a0, b0), k[1] = 0.5 * (cross2(a0, b1) + cross2(a1, b0)), k[2] = cross2(a1, b1);
    return ROUNDING * (dot2(a0, a0) + dot2(b0, b0) + dot2(a1, a1) + dot2(b1, b1));
}

/* Distance between segments ab and cd: 0 when they cross, else the least
 * distance from an end to the other segment. A crossing that rounding hides
 * has an end within rounding of the other segment, so the distance found is
 * about as small. */
static double segment_distance(const double a[2], const double b[2], const double c[2],
                               const double d[2])
{
    double o1 = orient2(a, b, c), o2 = orient2(a, b, d), o3 = orient2(c, d, a), o4 = orient2(c, d, b);
    if (((o1 > 0.0 && o2 < 0.0) || (o1 < 0.0 && o2 > 0.0)) &&
        ((o3 > 0.0 && o4 < 0.0) || (o3 < 0.0 && o4 > 0.0)))
        return 0.0;
    return min2(min2(point_segment2(a, c, d), point_segment2(b, c, d)),
                min2(point_segment2(c, a, b), point_segment2(d, a, b)));
}

/* Whether two segments with no common end stay apart over the step: every
 * point of a segment moves by at most its ends' larger displacement (a convex
 * combination of them), so their distance falls by at most the sum of the
 * two; more than the distance at the start is left. */
static int stay_apart(const wc_contour_segment *s, const wc_contour_segment *t, double margin)
{
    return segment_distance(s->a0, s->b0, t->a0, t->b0) > s->reach + t->reach + margin;
}

/* The end of a segment other than v at the start of the step and its
 * displacement, relative to v's. */
static void arm(const wc_contour_segment *s, int32_t v, double start[2], double end[2])
{
    const double *o0 = s->from == v ? s->b0 : s->a0, *od = s->from == v ? s->db : s->da;
    const double *v0 = s->from == v ? s->a0 : s->b0, *vd = s->from == v ? s->da : s->db;
    for (int k = 0; k < 2; ++k) start[k] = o0[k] - v0[k], end[k] = start[k] + od[k] - vd[k];
}

/* Whether two segments sharing the end v never lie along each other over the
 * step. They can meet away from v only pointing the same way from it, which
 * takes a zero cross product and a positive dot product of their arms A and
 * B at once. Both are quadratics in time, (1-t)^2 P0 + 2t(1-t) P1 + t^2 P2
 * with P1 the mean of the mixed terms, and stay between their Bernstein
 * coefficients: all of one sign for the cross product, or all negative for
 * the dot product, rules the fold out. */
static int no_fold(const wc_contour_segment *s, const wc_contour_segment *t, int32_t v)
{
    double a0[2], a1[2], b0[2], b1[2], k[3];
    arm(s, v, a0, a1);
    arm(t, v, b0, b1);
    double tol = cross_bounds(a0, a1, b0, b1, k);
    if (min2(k[0], min2(k[1], k[2])) > tol || max2(k[0], max2(k[1], k[2])) < -tol) return 1;
    double c0 = dot2(a0, b0), c1 = 0.5 * (dot2(a0, b1) + dot2(a1, b0)), c2 = dot2(a1, b1);
    return max2(c0, max2(c1, c2)) < -tol;
}

/* Whether two segments whose swept boxes overlap stay apart (no common end)
 * or never fold onto each other (one). */
static int compatible(const wc_contour_segment *s, const wc_contour_segment *t, double margin)
{
    int from_shared = s->from == t->from || s->from == t->to;
    int to_shared = s->to == t->from || s->to == t->to;
    if (from_shared && to_shared) return 0;
    if (from_shared || to_shared) return no_fold(s, t, from_shared ? s->from : s->to);
    return stay_apart(s, t, 2.0 * margin);
}

/* Whether the boundary is star-shaped around a point c over the whole step:
 * every segment turns the same way round c all along (the cross product of
 * its ends relative to c, a quadratic in time, has Bernstein coefficients of
 * one sign), and at the start the loop goes round c once (a ray from c
 * crosses it once). Then the polar angle round c rises along every segment
 * and by 2 pi in all: the loop is the graph of a radius over the angle,
 * simple. A patch of cloth, two side by side or three in a row or an L,
 * seen along its cone's axis is star-shaped round the mean of its boundary
 * vertices unless it is crushed: O(segments), where the general test pairs
 * segments up. The boundary runs counter-clockwise (its triangles face d). */
static int star_shaped(const wc_contour_segment *segments, int32_t count)
{
    double c[2] = {0.0, 0.0};
    for (int32_t k = 0; k < count; ++k) c[0] += segments[k].a0[0], c[1] += segments[k].a0[1];
    c[0] /= count, c[1] /= count;
    int32_t crossings = 0;
    for (int32_t k = 0; k < count; ++k) {
        const wc_contour_segment *s = segments + k;
        double a0[2] = {s->a0[0] - c[0], s->a0[1] - c[1]}, b0[2] = {s->b0[0] - c[0], s->b0[1] - c[1]};
        double a1[2] = {a0[0] + s->da[0], a0[1] + s->da[1]}, b1[2] = {b0[0] + s->db[0], b0[1] + s->db[1]};
        double k[3], tol = cross_bounds(a0, a1, b0, b1, k);
        if (!(min2(k[0], min2(k[1], k[2])) > tol)) return 0;
        /* the ray from c along +x: with the segment turning counter-clockwise
         * round c it can only cross upward, at x > 0 where a0 is below and
         * b0 on or above the axis (half-open, so a vertex counts once) */
        crossings += a0[1] < 0.0 && b0[1] >= 0.0;
    }
    return crossings == 1;
}

static int compare_segments(const void *pa, const void *pb)
{
    const wc_contour_segment *p = pa, *q = pb;
    if (p->box[0] != q->box[0]) return p->box[0] < q->box[0] ? -1 : 1;
    return p->from < q->from ? -1 : (p->from > q->from);
}

int wci_contour_simple(wc_contour_segment *segments, int32_t count, const double d[3],
                       const double *x, const double *y, const double *z, const double *nx,
                       const double *ny, const double *nz, double scale)
{
    if (count < 3) return 0; /* no loop */
    double e1[3], e2[3], drift[2] = {0.0, 0.0};
    plane_basis(d, e1, e2);
    for (int32_t k = 0; k < count; ++k) {
        wc_contour_segment *s = segments + k;
        int32_t a = s->from, b = s->to;
        double a1[2], b1[2];
        project(e1, e2, x[a], y[a], z[a], s->a0);
        project(e1, e2, x[b], y[b], z[b], s->b0);
        project(e1, e2, nx[a], ny[a], nz[a], a1);
        project(e1, e2, nx[b], ny[b], nz[b], b1);
        for (int m = 0; m < 2; ++m) s->da[m] = a1[m] - s->a0[m], s->db[m] = b1[m] - s->b0[m];
        drift[0] += s->da[0], drift[1] += s->da[1];
    }
    /* Whether a curve is simple does not change when the whole plane moves:
     * the tests below look at the motion relative to the boundary's mean
     * one (every boundary vertex starts one segment), so a region falling or
     * sliding as a whole moves by little, however fast it goes. */
    drift[0] /= count, drift[1] /= count;
    double largest = 0.0;
    for (int32_t k = 0; k < count; ++k) {
        wc_contour_segment *s = segments + k;
        for (int m = 0; m < 2; ++m) {
            s->da[m] -= drift[m], s->db[m] -= drift[m];
            double a1 = s->a0[m] + s->da[m], b1 = s->b0[m] + s->db[m];
            s->box[m] = min2(min2(s->a0[m], a1), min2(s->b0[m], b1));
            s->box[m + 2] = max2(max2(s->a0[m], a1), max2(s->b0[m], b1));
            largest = max2(largest, max2(fabs(s->box[m]), fabs(s->box[m + 2])));
        }
        s->reach = sqrt(max2(dot2(s->da, s->da), dot2(s->db, s->db)));
    }
    /* Projected coordinates are off by a few ulps of the largest one; a
     * margin of ROUNDING edges (and far more ulps) covers them. */
    double margin = ROUNDING * scale + 1e-12 * largest;
    if (!(margin > 0.0) || !isfinite(margin)) return 0;
    for (int32_t k = 0; k < count; ++k)
        for (int m = 0; m < 2; ++m) segments[k].box[m] -= margin, segments[k].box[m + 2] += margin;
    if (star_shaped(segments, count)) return 1;
    /* Only segments whose swept boxes overlap can meet. A few dozen
     * segments (a region of cloth patches) are cheaper to pair up directly
     * than to sort; more are swept along the first axis. The answer is the
     * same either way: every overlapping pair is tested. */
    int sweep = count > SWEEP_FROM;
    if (sweep) qsort(segments, (size_t)count, sizeof *segments, compare_segments);
    for (int32_t i = 0; i < count; ++i) {
        const wc_contour_segment *s = segments + i;
        for (int32_t j = i + 1; j < count; ++j) {
            const wc_contour_segment *t = segments + j;
            if (t->box[0] > s->box[2]) {
                if (sweep) break;
                continue;
            }
            if (t->box[2] < s->box[0] || t->box[1] > s->box[3] || t->box[3] < s->box[1]) continue;
            if (!compatible(s, t, margin)) return 0;
        }
    }
    return 1;
}
