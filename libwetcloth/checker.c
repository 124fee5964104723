/* The intersection checker (SPEC 2, "Penetration checker"): counts
 * intersecting triangle pairs in a world's current state. It shares no code
 * with the collision solver on purpose, so a solver bug cannot hide from it:
 * its own triangle-triangle test (exact orientation predicates, after
 * Guigue & Devillers 2003; coplanar pairs by exact 2D edge and containment
 * tests) and its own broadphase (sort and sweep, in bands). The
 * one shared piece is the convex shapes' GJK triangle test (convex.c),
 * which the solver itself does not use. */
#include "checker.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "alloc.h"
#include "cloth.h"
#include "collider.h"
#include "convex.h"
#include "parallel.h"
#include "predicates.h"
#include "status.h"
#include "world.h"

/* ------------------------------------------------------------------------ */
/* Triangle-triangle                                                          */
/* ------------------------------------------------------------------------ */

/* fmin/fmax are library calls that handle NaN; these compile to single
 * instructions, which matters in the broadphase's inner loops. Inputs here
 * are finite. */
static double min2(double a, double b) { return a < b ? a : b; }
static double max2(double a, double b) { return a > b ? a : b; }

/* The test decides every question by the sign of an exact orientation
 * predicate (predicates.h), so its answer is the exact one for the
 * triangles as given: close is not touching, touching counts as
 * intersecting. Before, it compared floating-point plane distances with
 * tolerances, and near-parallel layers a rounding error apart could read as
 * crossing (a leaning 40 x 40 cloth crumpling onto a floor showed one
 * cloth-cloth intersection for 29 frames that two exact segment-triangle
 * tests did not confirm). Non-degenerate pairs: Guigue & Devillers 2003,
 * "Fast and robust triangle-triangle overlap test using orientation
 * predicates"; coplanar pairs and degenerate (collinear) triangles by exact
 * segment and point tests. */

/* The 2D point of p with axis `drop` left out. */
static void project(const double p[3], int drop, double out[2])
{
    int i = drop == 0 ? 1 : 0, j = drop == 2 ? 1 : 2;
    out[0] = p[i], out[1] = p[j];
}

/* Whether c, exactly collinear with a-b, lies on the closed segment a-b. */
static int between2d(const double a[2], const double b[2], const double c[2])
{
    return min2(a[0], b[0]) <= c[0] && c[0] <= max2(a[0], b[0]) && min2(a[1], b[1]) <= c[1] &&
           c[1] <= max2(a[1], b[1]);
}

/* Closed 2D segments a-b and c-d meet (touching and collinear overlap count;
 * a segment may be a point). */
static int segments_meet2d(const double a[2], const double b[2], const double c[2], const double d[2])
{
    int o1 = wci_orient2d(a, b, c), o2 = wci_orient2d(a, b, d);
    int o3 = wci_orient2d(c, d, a), o4 = wci_orient2d(c, d, b);
    if (o1 * o2 < 0 && o3 * o4 < 0) return 1;
    return (o1 == 0 && between2d(a, b, c)) || (o2 == 0 && between2d(a, b, d)) ||
           (o3 == 0 && between2d(c, d, a)) || (o4 == 0 && between2d(c, d, b));
}

/* p inside or on the 2D triangle (a, b, c) of either orientation. */
static int inside2d(const double p[2], const double a[2], const double b[2], const double c[2])
{
    int o1 = wci_orient2d(a, b, p), o2 = wci_orient2d(b, c, p), o3 = wci_orient2d(c, a, p);
    return (o1 >= 0 && o2 >= 0 && o3 >= 0) || (o1 <= 0 && o2 <= 0 && o3 <= 0);
}

/* The axis to leave out when projecting triangle t: the largest component
 * of its (floating-point) normal, along which a non-degenerate triangle's
 * projection keeps its area. */
static int drop_axis(const double *const t[3])
{
    double e[3], f[3], n[3];
    for (int k = 0; k < 3; ++k) e[k] = t[1][k] - t[0][k], f[k] = t[2][k] - t[0][k];
    n[0] = e[1] * f[2] - e[2] * f[1], n[1] = e[2] * f[0] - e[0] * f[2], n[2] = e[0] * f[1] - e[1] * f[0];
    double ax = fabs(n[0]), ay = fabs(n[1]), az = fabs(n[2]);
    return ax >= ay && ax >= az ? 0 : ay >= az ? 1 : 2;
}

/* Coplanar triangles (t non-degenerate, its plane holding both): they meet
 * when an edge of one meets an edge of the other, or one holds a vertex of
 * the other, in the projection that keeps t's area. */
static int coplanar_triangles(const double *const p[3], const double *const q[3], int drop)
{
    double P[3][2], Q[3][2];
    for (int i = 0; i < 3; ++i) project(p[i], drop, P[i]), project(q[i], drop, Q[i]);
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            if (segments_meet2d(P[i], P[(i + 1) % 3], Q[j], Q[(j + 1) % 3])) return 1;
    return inside2d(P[0], Q[0], Q[1], Q[2]) || inside2d(Q[0], P[0], P[1], P[2]);
}

/* Whether triangle t is degenerate (its corners collinear): exactly, in all
 * three coordinate projections. */
static int degenerate(const double *const t[3])
{
    for (int drop = 0; drop < 3; ++drop) {
        double a[2], b[2], c[2];
        project(t[0], drop, a), project(t[1], drop, b), project(t[2], drop, c);
        if (wci_orient2d(a, b, c) != 0) return 0;
    }
    return 1;
}

/* Closed 3D segments a-b and c-d meet (either may be a point). Coplanar
 * segments meet exactly when they meet in every coordinate projection: one
 * of them keeps their plane (or line) undistorted. */
static int segments_meet3d(const double a[3], const double b[3], const double c[3], const double d[3])
{
    if (wci_orient3d(a, b, c, d) != 0) return 0;
    for (int drop = 0; drop < 3; ++drop) {
        double A[2], B[2], C[2], D[2];
        project(a, drop, A), project(b, drop, B), project(c, drop, C), project(d, drop, D);
        if (!segments_meet2d(A, B, C, D)) return 0;
    }
    return 1;
}

/* Closed segment a-b (maybe a point) meets the non-degenerate triangle t. */
static int segment_meets_triangle(const double a[3], const double b[3], const double *const t[3])
{
    int sa = wci_orient3d(t[0], t[1], t[2], a), sb = wci_orient3d(t[0], t[1], t[2], b);
    if (sa * sb > 0) return 0;
    if (sa == 0 && sb == 0) {
        int drop = drop_axis(t);
        double A[2], B[2], T[3][2];
        project(a, drop, A), project(b, drop, B);
        for (int i = 0; i < 3; ++i) project(t[i], drop, T[i]);
        for (int i = 0; i < 3; ++i)
            if (segments_meet2d(A, B, T[i], T[(i + 1) % 3])) return 1;
        return inside2d(A, T[0], T[1], T[2]);
    }
    /* it reaches the plane: where it does must be in the triangle, that is
     * the line a-b passes t's three edges on the same side */
    int s1 = wci_orient3d(a, b, t[0], t[1]), s2 = wci_orient3d(a, b, t[1], t[2]);
    int s3 = wci_orient3d(a, b, t[2], t[0]);
    return (s1 >= 0 && s2 >= 0 && s3 >= 0) || (s1 <= 0 && s2 <= 0 && s3 <= 0);
}

/* Pairs with a degenerate triangle: a degenerate triangle is its edges. */
static int degenerate_pair(const double *const p[3], const double *const q[3], int p_flat, int q_flat)
{
    for (int i = 0; i < 3; ++i) {
        const double *a = p[i], *b = p[(i + 1) % 3];
        if (!p_flat) a = q[i], b = q[(i + 1) % 3];
        if (p_flat && q_flat) {
            for (int j = 0; j < 3; ++j)
                if (segments_meet3d(a, b, q[j], q[(j + 1) % 3])) return 1;
        } else if (segment_meets_triangle(a, b, p_flat ? q : p)) {
            return 1;
        }
    }
    return 0;
}

/* The two triangles' intervals on the line where their planes meet overlap
 * (Guigue-Devillers' final test), with p1 alone on its side of q's plane
 * and p2 alone on its side of p's, both seeing the other on the positive
 * side. */
static int intervals_overlap(const double *p1, const double *q1, const double *r1, const double *p2,
                             const double *q2, const double *r2)
{
    if (wci_orient3d(q1, p2, p1, q2) > 0) return 0;
    if (wci_orient3d(p1, p2, r1, r2) > 0) return 0;
    return 1;
}

/* Second triangle's vertices permuted so that p2 is alone on its side of
 * the first's plane (dp2, dq2, dr2 the signs), then the interval test. */
static int second_alone(const double *p1, const double *q1, const double *r1, const double *p2,
                        const double *q2, const double *r2, int dp2, int dq2, int dr2, int drop)
{
    const double *const tp[3] = {p1, q1, r1}, *const tq[3] = {p2, q2, r2};
    if (dp2 > 0) {
        if (dq2 > 0) return intervals_overlap(p1, r1, q1, r2, p2, q2);
        if (dr2 > 0) return intervals_overlap(p1, r1, q1, q2, r2, p2);
        return intervals_overlap(p1, q1, r1, p2, q2, r2);
    }
    if (dp2 < 0) {
        if (dq2 < 0) return intervals_overlap(p1, q1, r1, r2, p2, q2);
        if (dr2 < 0) return intervals_overlap(p1, q1, r1, q2, r2, p2);
        return intervals_overlap(p1, r1, q1, p2, q2, r2);
    }
    if (dq2 < 0) {
        if (dr2 >= 0) return intervals_overlap(p1, r1, q1, q2, r2, p2);
        return intervals_overlap(p1, q1, r1, p2, q2, r2);
    }
    if (dq2 > 0) {
        if (dr2 > 0) return intervals_overlap(p1, r1, q1, p2, q2, r2);
        return intervals_overlap(p1, q1, r1, q2, r2, p2);
    }
    if (dr2 > 0) return intervals_overlap(p1, q1, r1, r2, p2, q2);
    if (dr2 < 0) return intervals_overlap(p1, r1, q1, r2, p2, q2);
    return coplanar_triangles(tp, tq, drop);
}

int wci_triangles_intersect(const double p0[3], const double p1[3], const double p2[3],
                           const double q0[3], const double q1[3], const double q2[3])
{
    const double *const p[3] = {p0, p1, p2};
    const double *const q[3] = {q0, q1, q2};
    /* Boxes first: cheap, exact, and most pairs end here. */
    for (int k = 0; k < 3; ++k) {
        double plo = min2(p0[k], min2(p1[k], p2[k])), phi = max2(p0[k], max2(p1[k], p2[k]));
        double qlo = min2(q0[k], min2(q1[k], q2[k])), qhi = max2(q0[k], max2(q1[k], q2[k]));
        if (phi < qlo || qhi < plo) return 0;
    }
    int p_flat = degenerate(p), q_flat = degenerate(q);
    if (p_flat || q_flat) return degenerate_pair(p, q, p_flat, q_flat);
    int dp1 = wci_orient3d(q0, q1, q2, p0), dq1 = wci_orient3d(q0, q1, q2, p1);
    int dr1 = wci_orient3d(q0, q1, q2, p2);
    if (dp1 * dq1 > 0 && dp1 * dr1 > 0) return 0;
    int dp2 = wci_orient3d(p0, p1, p2, q0), dq2 = wci_orient3d(p0, p1, p2, q1);
    int dr2 = wci_orient3d(p0, p1, p2, q2);
    if (dp2 * dq2 > 0 && dp2 * dr2 > 0) return 0;
    int drop = drop_axis(p);
    /* p0 made alone on its side of q's plane, q's order flipped when p0 is
     * on the negative side, so that the interval test sees both the same
     * way round */
    if (dp1 > 0) {
        if (dq1 > 0) return second_alone(p2, p0, p1, q0, q2, q1, dp2, dr2, dq2, drop);
        if (dr1 > 0) return second_alone(p1, p2, p0, q0, q2, q1, dp2, dr2, dq2, drop);
        return second_alone(p0, p1, p2, q0, q1, q2, dp2, dq2, dr2, drop);
    }
    if (dp1 < 0) {
        if (dq1 < 0) return second_alone(p2, p0, p1, q0, q1, q2, dp2, dq2, dr2, drop);
        if (dr1 < 0) return second_alone(p1, p2, p0, q0, q1, q2, dp2, dq2, dr2, drop);
        return second_alone(p0, p1, p2, q0, q2, q1, dp2, dr2, dq2, drop);
    }
    if (dq1 < 0) {
        if (dr1 >= 0) return second_alone(p1, p2, p0, q0, q2, q1, dp2, dr2, dq2, drop);
        return second_alone(p0, p1, p2, q0, q1, q2, dp2, dq2, dr2, drop);
    }
    if (dq1 > 0) {
        if (dr1 > 0) return second_alone(p0, p1, p2, q0, q2, q1, dp2, dr2, dq2, drop);
        return second_alone(p1, p2, p0, q0, q1, q2, dp2, dq2, dr2, drop);
    }
    if (dr1 > 0) return second_alone(p2, p0, p1, q0, q1, q2, dp2, dq2, dr2, drop);
    if (dr1 < 0) return second_alone(p2, p0, p1, q0, q2, q1, dp2, dr2, dq2, drop);
    return coplanar_triangles(p, q, drop);
}

/* ------------------------------------------------------------------------ */
/* Broadphase: sort and sweep in bands                                        */
/* ------------------------------------------------------------------------ */

/* One box to sweep: a cloth triangle, a mesh collider triangle, or a convex
 * collider (its bounding ball at the current pose). */
typedef struct item {
    double lo[3], hi[3];
    /* cloth index >= 0, or -1 - collider index */
    int32_t owner;
    /* triangle index; -1 for a convex collider */
    int32_t tri;
} item;

typedef struct key_id {
    double key;
    int32_t id;
} key_id;

static int compare_keys(const void *pa, const void *pb)
{
    const key_id *a = pa, *b = pb;
    if (a->key != b->key) return a->key < b->key ? -1 : 1;
    return (a->id > b->id) - (a->id < b->id);
}

static void box_of(item *it, const double *a, const double *b, const double *c)
{
    for (int k = 0; k < 3; ++k) {
        it->lo[k] = min2(a[k], min2(b[k], c[k]));
        it->hi[k] = max2(a[k], max2(b[k], c[k]));
    }
}

static void cloth_vertex(const wc_cloth *c, int32_t v, double out[3])
{
    out[0] = c->x[v], out[1] = c->y[v], out[2] = c->z[v];
}

static int collider_triangle_flat(const wc_collider *c, int32_t t)
{
    const int32_t *v = c->triangles + 3 * (size_t)t;
    const double *const pts[3] = {c->current + 3 * (size_t)v[0], c->current + 3 * (size_t)v[1],
                                  c->current + 3 * (size_t)v[2]};
    return degenerate(pts);
}

/* The exact test for a pair of boxes that overlap: 1 cloth-cloth, 2
 * cloth-collider, 0 for no intersection (or a pair not counted). */
static int test_pair(const wc_world *w, const item *a, const item *b)
{
    if (a->owner < 0 && b->owner < 0) return 0; /* collider against collider */
    if (a->owner < 0) {
        const item *t = a;
        a = b, b = t;
    }
    const wc_cloth *ca = w->cloths[a->owner];
    const int32_t *ta = ca->topology.triangles + 3 * (size_t)a->tri;
    double pa[3][3];
    for (int i = 0; i < 3; ++i) cloth_vertex(ca, ta[i], pa[i]);
    if (b->owner >= 0) {
        const wc_cloth *cb = w->cloths[b->owner];
        const int32_t *tb = cb->topology.triangles + 3 * (size_t)b->tri;
        if (a->owner == b->owner)
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j)
                    if (ta[i] == tb[j]) return 0; /* neighbours share a vertex */
        double pb[3][3];
        for (int i = 0; i < 3; ++i) cloth_vertex(cb, tb[i], pb[i]);
        return wci_triangles_intersect(pa[0], pa[1], pa[2], pb[0], pb[1], pb[2]) ? 1 : 0;
    }
    const wc_collider *c = w->colliders[-1 - b->owner];
    if (!c->is_mesh)
        return wci_convex_triangle_intersects(&c->convex, &c->pose_current, pa[0], pa[1], pa[2]) ? 2 : 0;
    const int32_t *tb = c->triangles + 3 * (size_t)b->tri;
    return wci_triangles_intersect(pa[0], pa[1], pa[2], c->current + 3 * (size_t)tb[0],
                                  c->current + 3 * (size_t)tb[1], c->current + 3 * (size_t)tb[2])
               ? 2
               : 0;
}

/* Band of a coordinate: bands of width `width` from `origin`, clamped to
 * [0, bands - 1]. Written so that no out-of-range double is ever converted
 * to an integer. */
static int64_t band_of(double value, double origin, double width, int64_t bands)
{
    double f = (value - origin) / width;
    if (!(f > 0.0)) return 0;
    if (f >= (double)(bands - 1)) return bands - 1;
    return (int64_t)f;
}

static int overlap(const item *a, const item *b, int axis)
{
    return a->lo[axis] <= b->hi[axis] && b->lo[axis] <= a->hi[axis];
}

wc_status wc_world_count_intersections(const wc_world *world, wc_intersection_counts *out)
{
    if (!world) return WC_ERROR_INVALID_ARGUMENT;
    wc_message *msg = wci_world_message(world);
    if (!out)
        return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT, "wc_world_count_intersections: out_counts is NULL");

    /* Gather the boxes. */
    int64_t n64 = 0;
    for (int32_t c = 0; c < world->cloth_count; ++c) n64 += world->cloths[c]->topology.triangle_count;
    for (int32_t c = 0; c < world->collider_count; ++c)
        n64 += world->colliders[c]->is_mesh ? world->colliders[c]->triangle_count : 1;
    if (n64 > INT32_MAX / 4)
        return wci_fail(msg, WC_ERROR_OUT_OF_MEMORY,
                       "wc_world_count_intersections: %lld triangles are too many to check",
                       (long long)n64);
    int32_t n = (int32_t)n64;
    item *items = wci_alloc_array((size_t)n, sizeof *items);
    if (!items)
        return wci_fail(msg, WC_ERROR_OUT_OF_MEMORY,
                       "wc_world_count_intersections: out of memory for %d boxes", (int)n);
    int32_t m = 0;
    for (int32_t c = 0; c < world->cloth_count; ++c) {
        const wc_cloth *cl = world->cloths[c];
        for (int32_t t = 0; t < cl->topology.triangle_count; ++t) {
            const int32_t *v = cl->topology.triangles + 3 * (size_t)t;
            double a[3], b[3], d[3];
            cloth_vertex(cl, v[0], a);
            cloth_vertex(cl, v[1], b);
            cloth_vertex(cl, v[2], d);
            item *it = items + m++;
            box_of(it, a, b, d);
            it->owner = c, it->tri = t;
        }
    }
    for (int32_t c = 0; c < world->collider_count; ++c) {
        const wc_collider *col = world->colliders[c];
        if (!col->is_mesh) {
            item *it = items + m++;
            for (int k = 0; k < 3; ++k) {
                it->lo[k] = col->pose_current.position[k] - col->convex.bound_radius;
                it->hi[k] = col->pose_current.position[k] + col->convex.bound_radius;
            }
            it->owner = -1 - c, it->tri = -1;
            continue;
        }
        for (int32_t t = 0; t < col->triangle_count; ++t) {
            if (collider_triangle_flat(col, t)) continue; /* animation may flatten some */
            const int32_t *v = col->triangles + 3 * (size_t)t;
            item *it = items + m++;
            box_of(it, col->current + 3 * (size_t)v[0], col->current + 3 * (size_t)v[1],
                   col->current + 3 * (size_t)v[2]);
            it->owner = -1 - c, it->tri = t;
        }
    }
    n = m;

    /* Axes: bands across the longest extent of the scene, sweeps along the
     * second longest. A plain one-axis sweep on a flat sheet compares every
     * triangle with a whole column of others (n^1.5 box tests); bands one
     * typical box wide bring that down to a few rows. */
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    double mean_extent[3] = {0, 0, 0};
    for (int32_t i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k) {
            lo[k] = min2(lo[k], items[i].lo[k]);
            hi[k] = max2(hi[k], items[i].hi[k]);
            mean_extent[k] += (items[i].hi[k] - items[i].lo[k]) / (double)n;
        }
    int band_axis = 0, sweep_axis = 1;
    {
        double e[3] = {hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]};
        int axes[3] = {0, 1, 2};
        for (int i = 0; i < 3; ++i)
            for (int j = i + 1; j < 3; ++j)
                if (e[axes[j]] > e[axes[i]]) {
                    int t = axes[i];
                    axes[i] = axes[j], axes[j] = t;
                }
        band_axis = axes[0], sweep_axis = axes[1];
    }
    int other_axis = 3 - band_axis - sweep_axis;
    double span = n > 0 ? hi[band_axis] - lo[band_axis] : 0.0;
    double width = mean_extent[band_axis];
    int64_t bands = 1;
    if (n > 1 && span > 0.0 && width > 0.0) {
        double q = span / width; /* may be inf: then as many bands as boxes */
        bands = q < (double)(n - 1) ? (int64_t)q + 1 : n;
    }
    /* Boxes much larger than the typical one sit in many bands; widen the
     * bands until the copies stay within a few per box. */
    int64_t copies;
    for (;;) {
        copies = 0;
        double w = bands > 1 ? span / (double)bands : 1.0;
        for (int32_t i = 0; i < n && bands > 1; ++i)
            copies += band_of(items[i].hi[band_axis], lo[band_axis], w, bands) -
                      band_of(items[i].lo[band_axis], lo[band_axis], w, bands) + 1;
        if (bands <= 1 || copies <= 4 * (int64_t)n + 16) break;
        bands = bands / 2 > 1 ? bands / 2 : 1;
    }
    if (bands <= 1) copies = n;
    double bw = bands > 1 ? span / (double)bands : 1.0;

    int64_t *start = wci_alloc_array((size_t)bands + 1, sizeof *start);
    int64_t *fill = wci_alloc_array((size_t)bands, sizeof *fill);
    int32_t *first_band = wci_alloc_array((size_t)n, sizeof *first_band);
    key_id *order = wci_alloc_array((size_t)n, sizeof *order);
    key_id *members = wci_alloc_array((size_t)copies, sizeof *members);
    if (!start || !fill || !first_band || !order || !members) {
        wci_free(items);
        wci_free(start);
        wci_free(fill);
        wci_free(first_band);
        wci_free(order);
        wci_free(members);
        return wci_fail(msg, WC_ERROR_OUT_OF_MEMORY,
                       "wc_world_count_intersections: out of memory for %lld band entries",
                       (long long)copies);
    }
    /* Counting sort of the box copies into bands. */
    for (int32_t i = 0; i < n; ++i) {
        int64_t b0 = 0, b1 = 0;
        if (bands > 1) {
            b0 = band_of(items[i].lo[band_axis], lo[band_axis], bw, bands);
            b1 = band_of(items[i].hi[band_axis], lo[band_axis], bw, bands);
        }
        first_band[i] = (int32_t)b0;
        for (int64_t b = b0; b <= b1; ++b) ++start[b + 1];
    }
    for (int64_t b = 0; b < bands; ++b) start[b + 1] += start[b];
    /* One sort along the sweep axis for all boxes; distributing them into
     * bands in that order leaves every band sorted. Ties break on the index,
     * so the order never depends on the sort's implementation. */
    for (int32_t i = 0; i < n; ++i) order[i].key = items[i].lo[sweep_axis], order[i].id = i;
    qsort(order, (size_t)n, sizeof *order, compare_keys);
    memcpy(fill, start, (size_t)bands * sizeof *fill);
    for (int32_t k = 0; k < n; ++k) {
        int32_t i = order[k].id;
        int64_t b0 = first_band[i], b1 = b0;
        if (bands > 1) b1 = band_of(items[i].hi[band_axis], lo[band_axis], bw, bands);
        for (int64_t b = b0; b <= b1; ++b) members[fill[b]++] = order[k];
    }

    /* Sweep each band. A pair that shares several bands is tested only in
     * the first of them they share: the band of the larger of their lower
     * ends. Bands are independent, so they run in parallel; the counts are
     * integers, so the sum does not depend on the thread count. */
    int64_t cloth_cloth = 0, cloth_collider = 0;
    int threads = wci_thread_count(world->def.thread_count);
    (void)threads;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) if (n >= 4096) \
    reduction(+ : cloth_cloth, cloth_collider)
    for (int64_t b = 0; b < bands; ++b) {
        key_id *list = members + start[b];
        int64_t count = start[b + 1] - start[b];
        for (int64_t i = 0; i < count; ++i) {
            const item *a = items + list[i].id;
            for (int64_t j = i + 1; j < count && list[j].key <= a->hi[sweep_axis]; ++j) {
                const item *c = items + list[j].id;
                if (!overlap(a, c, other_axis) || !overlap(a, c, band_axis)) continue;
                int32_t fb = first_band[list[i].id] > first_band[list[j].id] ? first_band[list[i].id]
                                                                              : first_band[list[j].id];
                if (fb != b) continue;
                int kind = test_pair(world, a, c);
                if (kind == 1) ++cloth_cloth;
                else if (kind == 2) ++cloth_collider;
            }
        }
    }
    wci_free(items);
    wci_free(start);
    wci_free(fill);
    wci_free(first_band);
    wci_free(order);
    wci_free(members);
    out->cloth_cloth = cloth_cloth > INT32_MAX ? INT32_MAX : (int32_t)cloth_cloth;
    out->cloth_collider = cloth_collider > INT32_MAX ? INT32_MAX : (int32_t)cloth_collider;
    return WC_OK;
}
