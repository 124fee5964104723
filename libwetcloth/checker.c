/* The intersection checker (SPEC 2, "Penetration checker"): counts
 * intersecting triangle pairs in a world's current state. It shares no code
 * with the collision solver on purpose, so a solver bug cannot hide from it:
 * its own triangle-triangle test (plane sides, then intervals on the line
 * where the planes meet, after Moller 1997; coplanar pairs by 2D edge and
 * containment tests) and its own broadphase (sort and sweep, in bands). The
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
#include "status.h"
#include "world.h"

/* Points closer than this to a plane, relative to the size of the pair (plus
 * the rounding of their coordinates), count as on it: touching counts as
 * intersecting, and a flat sheet that is not axis-aligned must be found
 * coplanar rather than crossing itself by rounding noise. */
#define PLANE_EPS 1e-12
/* Two triangles whose vertices all lie within this fraction of the pair's
 * size of the other's plane are compared as coplanar (in 2D). Their planes
 * then meet at an angle of at most ~1e-7 rad along a line their tiny,
 * rounding-noisy distances place badly: a flat sheet falling freely (its
 * heights differ by ~1e-11 m after a few hundred steps of rounding) showed
 * pairs half a cell apart as crossing. 1e-7 of a 3 cm pair is 3 nm. */
#define COPLANAR_EPS 1e-7
/* A triangle whose area is below this fraction of its longest edge squared
 * has no usable plane: it is treated as a segment. */
#define FLAT_EPS 1e-12

/* ------------------------------------------------------------------------ */
/* Triangle-triangle                                                          */
/* ------------------------------------------------------------------------ */

static void sub3(const double a[3], const double b[3], double out[3])
{
    out[0] = a[0] - b[0], out[1] = a[1] - b[1], out[2] = a[2] - b[2];
}

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross3(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

/* fmin/fmax are library calls that handle NaN; these compile to single
 * instructions, which matters in the broadphase's inner loops. Inputs here
 * are finite. */
static double min2(double a, double b) { return a < b ? a : b; }
static double max2(double a, double b) { return a > b ? a : b; }

/* Index of the largest component of |n|: dropping it projects a plane with
 * normal n onto the coordinate plane where it is least distorted. */
static int dominant_axis(const double n[3])
{
    double ax = fabs(n[0]), ay = fabs(n[1]), az = fabs(n[2]);
    return ax >= ay && ax >= az ? 0 : ay >= az ? 1 : 2;
}

/* 2D points: the two coordinates left after dropping an axis. */
static void project(const double p[3], int drop, double out[2])
{
    int i = drop == 0 ? 1 : 0, j = drop == 2 ? 1 : 2;
    out[0] = p[i], out[1] = p[j];
}

/* Twice the signed area of (a, b, c): > 0 counter-clockwise. */
static double orient2d(const double a[2], const double b[2], const double c[2])
{
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

/* Whether c, known to be collinear with a-b, lies on segment a-b. */
static int on_segment2d(const double a[2], const double b[2], const double c[2])
{
    return min2(a[0], b[0]) <= c[0] && c[0] <= max2(a[0], b[0]) && min2(a[1], b[1]) <= c[1] &&
           c[1] <= max2(a[1], b[1]);
}

/* Closed segments a-b and c-d in 2D meet (touching and overlapping
 * collinear segments count). */
static int segments_meet2d(const double a[2], const double b[2], const double c[2], const double d[2])
{
    double o1 = orient2d(a, b, c), o2 = orient2d(a, b, d);
    double o3 = orient2d(c, d, a), o4 = orient2d(c, d, b);
    if (((o1 > 0 && o2 < 0) || (o1 < 0 && o2 > 0)) && ((o3 > 0 && o4 < 0) || (o3 < 0 && o4 > 0)))
        return 1;
    return (o1 == 0 && on_segment2d(a, b, c)) || (o2 == 0 && on_segment2d(a, b, d)) ||
           (o3 == 0 && on_segment2d(c, d, a)) || (o4 == 0 && on_segment2d(c, d, b));
}

/* p inside or on the 2D triangle (a, b, c) of either orientation. */
static int inside2d(const double p[2], const double a[2], const double b[2], const double c[2])
{
    double o1 = orient2d(a, b, p), o2 = orient2d(b, c, p), o3 = orient2d(c, a, p);
    return (o1 >= 0 && o2 >= 0 && o3 >= 0) || (o1 <= 0 && o2 <= 0 && o3 <= 0);
}

/* Coplanar triangles, projected to 2D: two convex polygons are disjoint
 * exactly when the normal of one of their edges separates them (separating
 * axis theorem). Projections that only touch do not separate: touching
 * counts. A zero-length edge gives a zero axis, which separates nothing. */
static int coplanar_triangles(const double *const p[3], const double *const q[3], const double n[3])
{
    int drop = dominant_axis(n);
    double P[3][2], Q[3][2];
    for (int i = 0; i < 3; ++i) {
        project(p[i], drop, P[i]);
        project(q[i], drop, Q[i]);
    }
    for (int t = 0; t < 2; ++t) {
        for (int e = 0; e < 3; ++e) {
            const double *a = t ? Q[e] : P[e], *b = t ? Q[(e + 1) % 3] : P[(e + 1) % 3];
            double ax = a[1] - b[1], ay = b[0] - a[0];
            double plo = INFINITY, phi = -INFINITY, qlo = INFINITY, qhi = -INFINITY;
            for (int i = 0; i < 3; ++i) {
                double sp = (P[i][0] - a[0]) * ax + (P[i][1] - a[1]) * ay;
                double sq = (Q[i][0] - a[0]) * ax + (Q[i][1] - a[1]) * ay;
                plo = min2(plo, sp), phi = max2(phi, sp);
                qlo = min2(qlo, sq), qhi = max2(qhi, sq);
            }
            if (phi < qlo || qhi < plo) return 0;
        }
    }
    return 1;
}

/* Where a triangle with signed plane distances d[] (not all of one strict
 * sign, not all zero) meets that plane: one or two points, written to out.
 * Returns how many. Vertices on the plane are taken as they are; crossing
 * edges by interpolation, which stays inside the triangle whatever the
 * rounding. */
static int plane_crossing(const double *const t[3], const double d[3], double out[2][3])
{
    int n = 0;
    for (int i = 0; i < 3 && n < 2; ++i)
        if (d[i] == 0.0) memcpy(out[n++], t[i], 3 * sizeof(double));
    for (int i = 0; i < 3 && n < 2; ++i) {
        int j = (i + 1) % 3;
        if ((d[i] > 0 && d[j] < 0) || (d[i] < 0 && d[j] > 0)) {
            double s = d[i] / (d[i] - d[j]);
            for (int k = 0; k < 3; ++k) out[n][k] = t[i][k] + (t[j][k] - t[i][k]) * s;
            ++n;
        }
    }
    if (n == 1) memcpy(out[1], out[0], 3 * sizeof(double));
    return n;
}

/* Signed distances of t[] from the plane through o with normal n (unit),
 * snapped to zero within tol. Returns -1 when all are strictly negative,
 * +1 when all strictly positive, 0 otherwise. */
static int plane_side(const double *const t[3], const double o[3], const double n[3], double tol,
                      double d[3])
{
    int pos = 0, neg = 0;
    for (int i = 0; i < 3; ++i) {
        double v[3];
        sub3(t[i], o, v);
        d[i] = dot3(n, v);
        if (fabs(d[i]) <= tol) d[i] = 0.0;
        pos += d[i] > 0, neg += d[i] < 0;
    }
    return pos == 3 ? 1 : neg == 3 ? -1 : 0;
}

/* Closed segments a-b and c-d in 3D meet (within tol). */
static int segments_meet3d(const double a[3], const double b[3], const double c[3], const double d[3],
                           double tol)
{
    double u[3], v[3], w[3];
    sub3(b, a, u);
    sub3(d, c, v);
    sub3(a, c, w);
    double uu = dot3(u, u), uv = dot3(u, v), vv = dot3(v, v), uw = dot3(u, w), vw = dot3(v, w);
    double den = uu * vv - uv * uv, s = 0.0, t = 0.0;
    /* clamped closest-point parameters (Ericson 5.1.9) */
    if (uu <= 0.0 && vv <= 0.0) {
        s = t = 0.0;
    } else if (uu <= 0.0) {
        t = min2(max2(vw / vv, 0.0), 1.0);
    } else if (vv <= 0.0) {
        s = min2(max2(-uw / uu, 0.0), 1.0);
    } else {
        s = den > 0.0 ? min2(max2((uv * vw - vv * uw) / den, 0.0), 1.0) : 0.0;
        t = (uv * s + vw) / vv;
        if (t < 0.0) t = 0.0, s = min2(max2(-uw / uu, 0.0), 1.0);
        else if (t > 1.0) t = 1.0, s = min2(max2((uv - uw) / uu, 0.0), 1.0);
    }
    double g[3];
    for (int k = 0; k < 3; ++k) g[k] = (a[k] + u[k] * s) - (c[k] + v[k] * t);
    return dot3(g, g) <= tol * tol;
}

/* Closed segment a-b meets the (non-flat) triangle t with unit normal n. */
static int segment_meets_triangle(const double a[3], const double b[3], const double *const t[3],
                                  const double n[3], double tol)
{
    double va[3], vb[3];
    sub3(a, t[0], va);
    sub3(b, t[0], vb);
    double da = dot3(n, va), db = dot3(n, vb);
    if (fabs(da) <= tol) da = 0.0;
    if (fabs(db) <= tol) db = 0.0;
    if ((da > 0 && db > 0) || (da < 0 && db < 0)) return 0;
    int drop = dominant_axis(n);
    double T[3][2], A[2], B[2];
    for (int i = 0; i < 3; ++i) project(t[i], drop, T[i]);
    if (da == 0.0 && db == 0.0) {
        project(a, drop, A);
        project(b, drop, B);
        for (int i = 0; i < 3; ++i)
            if (segments_meet2d(A, B, T[i], T[(i + 1) % 3])) return 1;
        return inside2d(A, T[0], T[1], T[2]);
    }
    double s = da == db ? 0.0 : da / (da - db), x[3];
    for (int k = 0; k < 3; ++k) x[k] = a[k] + (b[k] - a[k]) * s;
    project(x, drop, A);
    return inside2d(A, T[0], T[1], T[2]);
}

/* The longest edge of a flat triangle: the segment it is. */
static void longest_edge(const double *const t[3], const double **a, const double **b)
{
    double best = -1.0;
    *a = t[0], *b = t[1];
    for (int i = 0; i < 3; ++i) {
        double e[3];
        sub3(t[(i + 1) % 3], t[i], e);
        double l = dot3(e, e);
        if (l > best) best = l, *a = t[i], *b = t[(i + 1) % 3];
    }
}

/* Unit normal of t; returns 0 (and leaves n unset) when t is flat. */
static int unit_normal(const double *const t[3], double n[3])
{
    double e1[3], e2[3], e3[3];
    sub3(t[1], t[0], e1);
    sub3(t[2], t[0], e2);
    sub3(t[2], t[1], e3);
    cross3(e1, e2, n);
    double len = sqrt(dot3(n, n));
    double edge2 = max2(dot3(e1, e1), max2(dot3(e2, e2), dot3(e3, e3)));
    if (!(len > FLAT_EPS * edge2)) return 0;
    for (int k = 0; k < 3; ++k) n[k] /= len;
    return 1;
}

int wc_triangles_intersect(const double p0[3], const double p1[3], const double p2[3],
                           const double q0[3], const double q1[3], const double q2[3])
{
    const double *const p[3] = {p0, p1, p2};
    const double *const q[3] = {q0, q1, q2};
    /* Boxes first: cheap, exact, and most pairs end here. */
    double lo[3], hi[3], mag = 0.0;
    for (int k = 0; k < 3; ++k) {
        double plo = min2(p0[k], min2(p1[k], p2[k])), phi = max2(p0[k], max2(p1[k], p2[k]));
        double qlo = min2(q0[k], min2(q1[k], q2[k])), qhi = max2(q0[k], max2(q1[k], q2[k]));
        if (phi < qlo || qhi < plo) return 0;
        lo[k] = min2(plo, qlo), hi[k] = max2(phi, qhi);
        mag = max2(mag, max2(fabs(lo[k]), fabs(hi[k])));
    }
    double size = max2(hi[0] - lo[0], max2(hi[1] - lo[1], hi[2] - lo[2]));
    double tol = PLANE_EPS * size + 8.0 * DBL_EPSILON * mag;

    double np[3], nq[3];
    int p_ok = unit_normal(p, np), q_ok = unit_normal(q, nq);
    if (!p_ok || !q_ok) {
        /* A flat triangle is (at most) its longest edge. */
        const double *a, *b, *c, *d;
        longest_edge(p, &a, &b);
        longest_edge(q, &c, &d);
        if (!p_ok && !q_ok) return segments_meet3d(a, b, c, d, tol);
        if (!p_ok) return segment_meets_triangle(a, b, q, nq, tol);
        return segment_meets_triangle(c, d, p, np, tol);
    }

    double dq[3], dp[3];
    if (plane_side(q, p0, np, tol, dq)) return 0;
    if (plane_side(p, q0, nq, tol, dp)) return 0;
    if (dq[0] == 0.0 && dq[1] == 0.0 && dq[2] == 0.0) return coplanar_triangles(p, q, np);
    if (dp[0] == 0.0 && dp[1] == 0.0 && dp[2] == 0.0) return coplanar_triangles(p, q, nq);
    double flat = COPLANAR_EPS * size, off = 0.0;
    for (int i = 0; i < 3; ++i) off = max2(off, max2(fabs(dq[i]), fabs(dp[i])));
    if (off <= flat) return coplanar_triangles(p, q, np);

    /* Each triangle meets the other's plane in a segment; both segments lie
     * on the line where the planes meet, and the triangles intersect when
     * the two overlap along it. */
    double line[3];
    cross3(np, nq, line);
    if (!(dot3(line, line) > 1e-24)) return coplanar_triangles(p, q, np);
    double sp[2][3], sq[2][3];
    plane_crossing(p, dp, sp);
    plane_crossing(q, dq, sq);
    double a0 = dot3(line, sp[0]), a1 = dot3(line, sp[1]);
    double b0 = dot3(line, sq[0]), b1 = dot3(line, sq[1]);
    if (a0 > a1) {
        double t = a0;
        a0 = a1, a1 = t;
    }
    if (b0 > b1) {
        double t = b0;
        b0 = b1, b1 = t;
    }
    double slack = tol * sqrt(dot3(line, line));
    return max2(a0, b0) <= min2(a1, b1) + slack;
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
    double n[3];
    return !unit_normal(pts, n);
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
        return wc_triangles_intersect(pa[0], pa[1], pa[2], pb[0], pb[1], pb[2]) ? 1 : 0;
    }
    const wc_collider *c = w->colliders[-1 - b->owner];
    if (!c->is_mesh)
        return wc_convex_triangle_intersects(&c->convex, &c->pose_current, pa[0], pa[1], pa[2]) ? 2 : 0;
    const int32_t *tb = c->triangles + 3 * (size_t)b->tri;
    return wc_triangles_intersect(pa[0], pa[1], pa[2], c->current + 3 * (size_t)tb[0],
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
    wc_message *msg = wc_world_message(world);
    if (!out)
        return wc_fail(msg, WC_ERROR_INVALID_ARGUMENT, "wc_world_count_intersections: out_counts is NULL");

    /* Gather the boxes. */
    int64_t n64 = 0;
    for (int32_t c = 0; c < world->cloth_count; ++c) n64 += world->cloths[c]->topology.triangle_count;
    for (int32_t c = 0; c < world->collider_count; ++c)
        n64 += world->colliders[c]->is_mesh ? world->colliders[c]->triangle_count : 1;
    if (n64 > INT32_MAX / 4)
        return wc_fail(msg, WC_ERROR_OUT_OF_MEMORY,
                       "wc_world_count_intersections: %lld triangles are too many to check",
                       (long long)n64);
    int32_t n = (int32_t)n64;
    item *items = wc_alloc_array((size_t)n, sizeof *items);
    if (!items)
        return wc_fail(msg, WC_ERROR_OUT_OF_MEMORY,
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

    int64_t *start = wc_alloc_array((size_t)bands + 1, sizeof *start);
    int64_t *fill = wc_alloc_array((size_t)bands, sizeof *fill);
    int32_t *first_band = wc_alloc_array((size_t)n, sizeof *first_band);
    key_id *order = wc_alloc_array((size_t)n, sizeof *order);
    key_id *members = wc_alloc_array((size_t)copies, sizeof *members);
    if (!start || !fill || !first_band || !order || !members) {
        wc_free(items);
        wc_free(start);
        wc_free(fill);
        wc_free(first_band);
        wc_free(order);
        wc_free(members);
        return wc_fail(msg, WC_ERROR_OUT_OF_MEMORY,
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
    int threads = wc_thread_count(world->def.thread_count);
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
    wc_free(items);
    wc_free(start);
    wc_free(fill);
    wc_free(first_band);
    wc_free(order);
    wc_free(members);
    out->cloth_cloth = cloth_cloth > INT32_MAX ? INT32_MAX : (int32_t)cloth_cloth;
    out->cloth_collider = cloth_collider > INT32_MAX ? INT32_MAX : (int32_t)cloth_collider;
    return WC_OK;
}
