#include "narrowphase.h"

#include <math.h>
#include <string.h>

#include "convex.h"
#include "primitives.h"
#include "vec3.h"

static void vertex_of(const double *xyz, int32_t v, double out[3])
{
    out[0] = xyz[3 * (size_t)v], out[1] = xyz[3 * (size_t)v + 1], out[2] = xyz[3 * (size_t)v + 2];
}

static void bary_point(const double a[3], const double b[3], const double c[3], const double w[3],
                       double out[3])
{
    for (int k = 0; k < 3; ++k) out[k] = w[0] * a[k] + w[1] * b[k] + w[2] * c[k];
}

static void start_of(const wc_particle_arrays *p, int32_t i, double out[3])
{
    out[0] = p->x[i], out[1] = p->y[i], out[2] = p->z[i];
}

static void end_of(const wc_particle_arrays *p, int32_t i, double out[3])
{
    out[0] = p->nx[i], out[1] = p->ny[i], out[2] = p->nz[i];
}

/* A record with nothing in it but its source. */
static void clear_contact(wc_contact *k)
{
    memset(k, 0, sizeof *k);
    k->source = WC_SOURCE_COLLIDER;
}

/* ------------------------------------------------------------------------ */
/* A particle against a collider face                                       */
/* ------------------------------------------------------------------------ */

/* Collider triangle t at the start and the end of the step, with its unit
 * normals (zero when degenerate). A static collider's normals were made
 * once (collider.c); a moving one's are made here, for the few triangles
 * the filter leaves, rather than for every triangle at every step. */
static void triangle_motion(const wc_collider *c, int32_t t, double t0[3][3], double t1[3][3],
                            double n0[3], double n1[3])
{
    for (int k = 0; k < 3; ++k) {
        vertex_of(c->current, c->triangles[3 * (size_t)t + k], t0[k]);
        vertex_of(c->next, c->triangles[3 * (size_t)t + k], t1[k]);
    }
    if (!c->moving) {
        memcpy(n0, c->normals + 3 * (size_t)t, 3 * sizeof *n0);
        memcpy(n1, n0, 3 * sizeof *n1);
        return;
    }
    wci_triangle_normal(t0[0], t0[1], t0[2], n0);
    wci_triangle_normal(t1[0], t1[1], t1[2], n1);
}

/* Which side of a triangle the particle belongs on: the side it was on at
 * the start of the step (it never crossed before), else the side it is on
 * now, else the front. */
static double side_of(const double start[3], const double corner0[3], const double n0[3],
                      const double end_offset[3], const double n1[3])
{
    double rel[3] = {start[0] - corner0[0], start[1] - corner0[1], start[2] - corner0[2]};
    double s = dot3(rel, n0);
    if (s == 0.0) s = dot3(end_offset, n1);
    return s < 0.0 ? -1.0 : 1.0;
}

/* Static triangle: the thesis' test (eq. 2.5-2.6). The motion crosses the
 * plane when the signed distances at its two ends differ in sign; the
 * crossing point C = start + d_s / (d_s + d_e) (end - start) must lie in the
 * triangle (within the contact distance). Linear: no cubic for a collider
 * that stands still. */
static int crosses_static(const double start[3], const double end[3], double t0[3][3],
                          const double n[3], double r, double w[3])
{
    double ds = (start[0] - t0[0][0]) * n[0] + (start[1] - t0[0][1]) * n[1] + (start[2] - t0[0][2]) * n[2];
    double de = (end[0] - t0[0][0]) * n[0] + (end[1] - t0[0][1]) * n[1] + (end[2] - t0[0][2]) * n[2];
    if (ds * de > 0.0 || (ds == 0.0 && de == 0.0)) return 0;
    double f = ds / (ds - de), cross[3];
    for (int k = 0; k < 3; ++k) cross[k] = start[k] + (end[k] - start[k]) * f;
    return wci_point_triangle_closest(cross, t0[0], t0[1], t0[2], w) <= r * r;
}

/* The record of a particle touching the surface point `surface` (end of
 * the step) along n, the point having moved by `motion` over the step: the
 * response puts the particle at r from it along n. */
static void surface_contact(int32_t particle, const double end[3], const double surface[3],
                            const double n[3], const double motion[3], double r, wc_contact *out)
{
    clear_contact(out);
    out->count = 1;
    out->particle[0] = particle;
    out->weight[0] = 1.0;
    double offset[3] = {end[0] - surface[0], end[1] - surface[1], end[2] - surface[2]};
    out->distance = dot3(offset, n);
    out->target = r;
    for (int k = 0; k < 3; ++k) {
        out->normal[k] = n[k];
        out->surface_motion[k] = motion[k];
        /* from the end to over the surface point: across the normal only */
        out->place[k] = -offset[k] + out->distance * n[k];
    }
}

/* Cheap rejection for a moving triangle, the one that needs no normals:
 * whether the particle stays farther than r from triangle t over the whole
 * step, so that neither the distance test nor the continuous one can
 * answer. Each point of the triangle is q(t) = sum w_k c_k(t), corners and
 * particle moving linearly, so p(t) - q(t) = (p(1) - q(1)) - (1 - t) sum
 * w_k d_k, d_k the particle's displacement less corner k's; the distance
 * at any time is then at least the end's less max_k |d_k|. A triangle that
 * is not apart still has the end's squared distance in *d2 and its
 * closest point's weights in w, which the full test goes on from. Returns
 * 1 if apart, 0 if not, -1 for a triangle degenerate at the end (which the
 * full test ignores, measuring nothing). The slack of 1e-9 r covers the
 * rounding of the continuous test's own distances. */
static int moving_triangle_apart(const wc_collider *c, int32_t t, const double start[3],
                                 const double end[3], double r, double *d2, double w[3])
{
    double t1[3][3], u[3], v[3], m[3], most2 = 0.0;
    for (int k = 0; k < 3; ++k) {
        int32_t corner = c->triangles[3 * (size_t)t + k];
        double c0[3], d[3];
        vertex_of(c->current, corner, c0);
        vertex_of(c->next, corner, t1[k]);
        for (int j = 0; j < 3; ++j) d[j] = (end[j] - start[j]) - (t1[k][j] - c0[j]);
        if (dot3(d, d) > most2) most2 = dot3(d, d);
    }
    sub3(t1[1], t1[0], u);
    sub3(t1[2], t1[0], v);
    cross3(u, v, m);
    if (!(dot3(m, m) > 0.0)) return -1;
    *d2 = wci_point_triangle_closest(end, t1[0], t1[1], t1[2], w);
    double clear = r * (1.0 + 1e-9) + sqrt(most2);
    return *d2 > clear * clear;
}

/* For a static triangle the particle stays on one side of all the step
 * (no crossing, so only the distance at the end can answer): whether that
 * distance is no touch. Its square goes to *d2 and its closest point's
 * weights to w either way, as the full test computes them, so that a
 * triangle that does touch goes on from them. Spares the test's contact
 * geometry for the many triangles that lie within reach of a resting
 * particle but do not touch it (the slivers at a UV sphere's pole). */
static int static_apart(const wc_collider *c, int32_t t, const double end[3], double r, double *d2,
                        double w[3])
{
    double e[3][3];
    for (int k = 0; k < 3; ++k) vertex_of(c->next, c->triangles[3 * (size_t)t + k], e[k]);
    *d2 = wci_point_triangle_closest(end, e[0], e[1], e[2], w);
    return !(*d2 < r * r * (1.0 - WC_FACE_SLACK));
}

int wci_narrow_particle_triangle(const wc_collider *c, int32_t t, int32_t particle,
                                const double start[3], const double end[3], double r,
                                double *end_d2, wc_contact *out)
{
    double t0[3][3], t1[3][3], n0[3], n1[3];
    double w[3], cp[3], offset[3], tc, d2 = 0.0;
    int measured = 0; /* d2 and w hold the end's distance already */
    *end_d2 = 0.0;
    if (!c->moving) {
        /* Cheap rejection for a static triangle: the particle stays on one
         * side of its plane, farther than r at the end of the step. */
        const double *n = c->normals + 3 * (size_t)t;
        if (n[0] == 0.0 && n[1] == 0.0 && n[2] == 0.0) return 0; /* degenerate: ignored */
        const double *a = c->current + 3 * (size_t)c->triangles[3 * (size_t)t];
        double ds = (start[0] - a[0]) * n[0] + (start[1] - a[1]) * n[1] + (start[2] - a[2]) * n[2];
        double de = (end[0] - a[0]) * n[0] + (end[1] - a[1]) * n[1] + (end[2] - a[2]) * n[2];
        if (ds * de > 0.0 && fabs(de) >= r) {
            *end_d2 = de * de;
            return 0;
        }
        if (ds * de > 0.0) {
            measured = 1;
            if (static_apart(c, t, end, r, &d2, w)) {
                *end_d2 = d2;
                return 0;
            }
        }
    }
    if (c->moving) {
        int apart = moving_triangle_apart(c, t, start, end, r, &d2, w);
        if (apart < 0) return 0;
        *end_d2 = d2;
        if (apart) return 0;
    }
    triangle_motion(c, t, t0, t1, n0, n1);
    if (n1[0] == 0.0 && n1[1] == 0.0 && n1[2] == 0.0) return 0;
    if (!c->moving && !measured) d2 = wci_point_triangle_closest(end, t1[0], t1[1], t1[2], w);
    *end_d2 = d2;
    bary_point(t1[0], t1[1], t1[2], w, cp);
    for (int k = 0; k < 3; ++k) offset[k] = end[k] - cp[k];
    double side = side_of(start, t0[0], n0, offset, n1);
    int hit = d2 < r * r * (1.0 - WC_FACE_SLACK);
    /* Crossed the surface during the step (possibly far through it): the
     * contact is placed where the particle met the triangle, on the
     * end-of-step triangle. */
    if (!hit) {
        hit = c->moving ? wci_ccd_point_triangle(start, end, t0[0], t1[0], t0[1], t1[1], t0[2],
                                                t1[2], r, &tc, w)
                        : crosses_static(start, end, t0, n0, r, w);
        if (hit) {
            bary_point(t1[0], t1[1], t1[2], w, cp);
            for (int k = 0; k < 3; ++k) offset[k] = 0.0;
        }
    }
    if (!hit) return 0;
    double n[3], len = sqrt(dot3(offset, offset));
    /* Off an edge or corner, on the particle's own side: push along the
     * offset (smooth round edges). In the face region, or on the wrong
     * side, push along the face normal to the particle's side. */
    if (len > 1e-12 * r && dot3(offset, n1) * side > 0.0)
        for (int k = 0; k < 3; ++k) n[k] = offset[k] / len;
    else
        for (int k = 0; k < 3; ++k) n[k] = side * n1[k];
    double p0[3], motion[3];
    bary_point(t0[0], t0[1], t0[2], w, p0);
    for (int k = 0; k < 3; ++k) motion[k] = cp[k] - p0[k];
    surface_contact(particle, end, cp, n, motion, r, out);
    return 1;
}

int wci_narrow_particle_convex(const wc_collider *c, int32_t particle, const double start[3],
                              const double end[3], double r, wc_contact *out)
{
    for (int k = 0; k < 3; ++k) {
        double lo = start[k] < end[k] ? start[k] : end[k], hi = start[k] < end[k] ? end[k] : start[k];
        if (hi + r < c->bounds[k] || lo - r > c->bounds[k + 3]) return 0;
    }
    /* Convex shapes move rigidly: the motion is taken into the shape's
     * frame (start in the pose at the start of the step, end in the pose at
     * its end), where the shape stands still. */
    double a[3], b[3], local[3], n_local[3], surface[3], n[3], before[3], motion[3];
    wci_pose_to_local(&c->pose_current, start, a);
    wci_pose_to_local(&c->pose_next, end, b);
    if (!wci_convex_resolve(&c->convex, a, b, r, local, n_local)) return 0;
    wci_pose_rotate(&c->pose_next, n_local, n);
    /* the surface point under the particle, at the end and the start */
    for (int k = 0; k < 3; ++k) local[k] -= n_local[k] * r;
    wci_pose_to_world(&c->pose_next, local, surface);
    wci_pose_to_world(&c->pose_current, local, before);
    for (int k = 0; k < 3; ++k) motion[k] = surface[k] - before[k];
    surface_contact(particle, end, surface, n, motion, r, out);
    return 1;
}

/* ------------------------------------------------------------------------ */
/* Collider vertices and edges against cloth triangles and edges            */
/* ------------------------------------------------------------------------ */

int wci_narrow_needs_ccd(double motion, double r) { return 2.0 * motion > r; }

/* Points along the step at which turning_cross follows a normal. */
#define NORMAL_SAMPLES 8

/* Whether m(t) = u(t) x v(t) stays within 44 degrees of m0 = u0 x v0 (not
 * yet normalised) over the step, so that following it (turning_cross)
 * never turns a sample's sign and ends at u1 x v1 as it is. With du = u1 -
 * u0 and dv = v1 - v0, m(t) - m0 = t (u0 x dv + du x v0) + t^2 du x dv,
 * at most the sum of the two lengths for t in [0, 1]; when that is below
 * 0.7 |m0| every m(t) lies within asin(0.7) of m0, any two samples within
 * 89 degrees of each other. The last term covers the rounding of the
 * sampled products, relative to |u| |v|. Most pushes of a resting cloth
 * turn it little in a step; the sampling is for those that turn it far. */
static int turns_little(const double u0[3], const double u1[3], const double v0[3],
                        const double v1[3], const double m0[3])
{
    double du[3], dv[3], a[3], b[3], ab[3];
    sub3(u1, u0, du);
    sub3(v1, v0, dv);
    cross3(u0, dv, a);
    cross3(du, v0, b);
    for (int k = 0; k < 3; ++k) ab[k] = a[k] + b[k];
    cross3(du, dv, b);
    double size = (sqrt(dot3(u0, u0)) + sqrt(dot3(du, du))) * (sqrt(dot3(v0, v0)) + sqrt(dot3(dv, dv)));
    double turn = sqrt(dot3(ab, ab)) + sqrt(dot3(b, b)) + 1e-12 * size;
    return turn < 0.7 * sqrt(dot3(m0, m0));
}

/* The unit normal m(t) = u(t) x v(t) of two vectors moving linearly over
 * the step (u0 to u1, v0 to v1) at its start and end, with the end's sign
 * chosen by following the normal along the step as an axis: at each of
 * NORMAL_SAMPLES points the sign nearest the last point's. A side judged
 * along m0 at the start then reads the same along m1 at the end unless the
 * elements crossed. Without this, two edges that pass through parallel
 * (or a triangle that turns over) within the step, where m(t) vanishes and
 * comes back reversed, would read as crossed, and the push would take the
 * cloth through the collider: cloth edges sliding over a sphere's edges,
 * both tangent to the sphere, do that at 8 implicit steps per frame. A
 * normal that keeps its length and turns past 90 degrees over the step is
 * followed too. Returns 0 if m0 or m1 has no direction. */
static int turning_cross(const double u0[3], const double u1[3], const double v0[3],
                         const double v1[3], double m0[3], double m1[3])
{
    double last[3], u[3], v[3], m[3];
    cross3(u0, v0, m0);
    int straight = turns_little(u0, u1, v0, v1, m0);
    if (!normalize3(m0)) return 0;
    if (straight) {
        /* what following it would give: no sample turns its sign */
        cross3(u1, v1, m1);
        return normalize3(m1);
    }
    memcpy(last, m0, sizeof last);
    for (int k = 1; k <= NORMAL_SAMPLES; ++k) {
        double t = (double)k / NORMAL_SAMPLES;
        if (k == NORMAL_SAMPLES) memcpy(u, u1, sizeof u), memcpy(v, v1, sizeof v);
        else lerp3(u0, u1, t, u), lerp3(v0, v1, t, v);
        cross3(u, v, m);
        if (!normalize3(m)) {
            if (k == NORMAL_SAMPLES) return 0;
            continue;
        }
        if (dot3(m, last) < 0.0)
            for (int d = 0; d < 3; ++d) m[d] = -m[d];
        memcpy(last, m, sizeof last);
    }
    memcpy(m1, last, sizeof last);
    return 1;
}

/* A cloth element of `count` particles with weights w touching a collider
 * feature at signed distance gap along n (from the feature toward the
 * cloth), the feature's point having moved by `motion`: a record if deeper
 * than the slack. */
static int element_contact(const int32_t *idx, const double *w, int count, const double n[3],
                           double gap, const double motion[3], double r, wc_contact *out)
{
    if (!(r - gap > WC_FEATURE_SLACK * r)) return 0;
    clear_contact(out);
    out->count = (uint8_t)count;
    for (int k = 0; k < count; ++k) out->particle[k] = idx[k], out->weight[k] = w[k];
    for (int k = 0; k < 3; ++k) out->normal[k] = n[k], out->surface_motion[k] = motion[k];
    out->distance = gap;
    out->target = r;
    return 1;
}

int wci_narrow_vertex_triangle(const wc_particle_arrays *p, const int32_t idx[3], const wc_collider *col,
                              int32_t vertex, int ccd, double r, double *d2, wc_contact *out)
{
    double v0[3], v1[3], a0[3], b0[3], c0[3], a1[3], b1[3], c1[3], w[3], p1[3], p0[3], n1[3], n0[3], tc;
    vertex_of(col->current, vertex, v0);
    vertex_of(col->next, vertex, v1);
    start_of(p, idx[0], a0), start_of(p, idx[1], b0), start_of(p, idx[2], c0);
    end_of(p, idx[0], a1), end_of(p, idx[1], b1), end_of(p, idx[2], c1);
    *d2 = wci_point_triangle_closest(v1, a1, b1, c1, w);
    int hit = *d2 < r * r * (1.0 - WC_FEATURE_SLACK);
    if (!hit && ccd) hit = wci_ccd_point_triangle(v0, v1, a0, a1, b0, b1, c0, c1, 1e-9 * r, &tc, w);
    if (!hit) return 0;
    double ab0[3], ac0[3], ab1[3], ac1[3];
    for (int d = 0; d < 3; ++d) {
        ab0[d] = b0[d] - a0[d], ac0[d] = c0[d] - a0[d];
        ab1[d] = b1[d] - a1[d], ac1[d] = c1[d] - a1[d];
    }
    /* crushed flat at either end: the edges decide */
    if (!turning_cross(ab0, ab1, ac0, ac1, n0, n1)) return 0;
    bary_point(a1, b1, c1, w, p1);
    bary_point(a0, b0, c0, w, p0);
    /* The cloth belongs on the side of the vertex it was on at the start. */
    double start_gap[3], end_gap[3], n[3], motion[3];
    for (int d = 0; d < 3; ++d) start_gap[d] = p0[d] - v0[d], end_gap[d] = p1[d] - v1[d];
    double side = dot3(start_gap, n0);
    if (side == 0.0) side = dot3(end_gap, n1);
    side = side < 0.0 ? -1.0 : 1.0;
    for (int d = 0; d < 3; ++d) n[d] = side * n1[d];
    /* Off the face region, on the right side: push along the offset. */
    double along = dot3(end_gap, n), len = sqrt(dot3(end_gap, end_gap));
    if (along > 0.0 && len > 0.0 && (w[0] == 0.0 || w[1] == 0.0 || w[2] == 0.0))
        for (int d = 0; d < 3; ++d) n[d] = end_gap[d] / len;
    for (int d = 0; d < 3; ++d) motion[d] = v1[d] - v0[d];
    return element_contact(idx, w, 3, n, dot3(end_gap, n), motion, r, out);
}

/* The way an edge-edge contact pushes the cloth's edge, from the collider's
 * closest point toward the cloth's (unit, into n): `start_gap` and
 * `end_gap` join the closest points' places at the start and end of the
 * step, the edges run p-q (collider) and a-b (cloth). `crossed` says the
 * continuous test saw the edges meet; `ccd` that they moved far enough to
 * need it. Returns 0 for edges parallel at the start or end: the vertices
 * decide those. */
static int edge_push_normal(const double p0[3], const double p1[3], const double q0[3],
                            const double q1[3], const double a0[3], const double a1[3],
                            const double b0[3], const double b1[3], const double start_gap[3],
                            const double end_gap[3], int ccd, int crossed, double r, double n[3])
{
    /* Near at the end after a large motion without meeting on the way: the
     * cloth's edge is on its side still, and the line between the closest
     * points is the way out. The side judged at the start along the edges'
     * common normal is not reliable there: the closest points at the start
     * can lie elsewhere, and the normal of two nearly parallel edges swings
     * (both happen to cloth edges sliding over a sphere's edges at 8
     * implicit steps per frame; judged so, the push took the cloth into the
     * sphere). */
    double gap = sqrt(dot3(end_gap, end_gap)), t, sp, u;
    if (ccd && !crossed && gap > 1e-3 * r &&
        !wci_ccd_edge_edge(p0, p1, q0, q1, a0, a1, b0, b1, 1e-9 * r, &t, &sp, &u)) {
        for (int d = 0; d < 3; ++d) n[d] = end_gap[d] / gap;
        return 1;
    }
    /* They met, or moved too little to have come round, or touch at the
     * end: the side they were on at the start decides. */
    double dp0[3], de0[3], dp1[3], de1[3], m0[3], m1[3];
    for (int d = 0; d < 3; ++d) {
        dp0[d] = q0[d] - p0[d], de0[d] = b0[d] - a0[d];
        dp1[d] = q1[d] - p1[d], de1[d] = b1[d] - a1[d];
    }
    if (!turning_cross(dp0, dp1, de0, de1, m0, m1)) return 0;
    double side = dot3(start_gap, m0);
    if (side == 0.0) side = dot3(end_gap, m1);
    for (int d = 0; d < 3; ++d) n[d] = (side < 0.0 ? -1.0 : 1.0) * m1[d];
    return 1;
}

int wci_narrow_edge_edge(const wc_particle_arrays *p, const int32_t idx[2], const wc_collider *col,
                        int32_t f, int ccd, double r, double *d2, wc_contact *out)
{
    double p0[3], p1[3], q0[3], q1[3], a0[3], b0[3], a1[3], b1[3], sp, u, tc;
    vertex_of(col->current, col->edges[2 * (size_t)f], p0);
    vertex_of(col->next, col->edges[2 * (size_t)f], p1);
    vertex_of(col->current, col->edges[2 * (size_t)f + 1], q0);
    vertex_of(col->next, col->edges[2 * (size_t)f + 1], q1);
    start_of(p, idx[0], a0), start_of(p, idx[1], b0);
    end_of(p, idx[0], a1), end_of(p, idx[1], b1);
    *d2 = wci_segment_segment_closest(p1, q1, a1, b1, &sp, &u);
    int hit = *d2 < r * r * (1.0 - WC_FEATURE_SLACK), crossed = 0;
    if (!hit && ccd)
        hit = crossed = wci_ccd_edge_edge(p0, p1, q0, q1, a0, a1, b0, b1, 1e-9 * r, &tc, &sp, &u);
    if (!hit) return 0;
    /* A contact at an end of either edge is a vertex's business (a cloth
     * particle against a face, or a collider vertex against a triangle). */
    if (sp <= 0.0 || sp >= 1.0 || u <= 0.0 || u >= 1.0) return 0;
    double c0[3], c1[3], e0[3], e1[3], start_gap[3], end_gap[3], n[3], motion[3];
    lerp3(p0, q0, sp, c0), lerp3(p1, q1, sp, c1);
    lerp3(a0, b0, u, e0), lerp3(a1, b1, u, e1);
    for (int d = 0; d < 3; ++d) start_gap[d] = e0[d] - c0[d], end_gap[d] = e1[d] - c1[d];
    if (!edge_push_normal(p0, p1, q0, q1, a0, a1, b0, b1, start_gap, end_gap, ccd, crossed, r, n))
        return 0;
    double w[2] = {1.0 - u, u};
    for (int d = 0; d < 3; ++d) motion[d] = (1.0 - sp) * (p1[d] - p0[d]) + sp * (q1[d] - q0[d]);
    return element_contact(idx, w, 2, n, dot3(end_gap, n), motion, r, out);
}
