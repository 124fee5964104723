#include "primitives.h"

#include <math.h>

static double dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static void sub(const double a[3], const double b[3], double out[3])
{
    out[0] = a[0] - b[0], out[1] = a[1] - b[1], out[2] = a[2] - b[2];
}

static void cross(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

static void lerp(const double a[3], const double b[3], double t, double out[3])
{
    for (int k = 0; k < 3; ++k) out[k] = a[k] + (b[k] - a[k]) * t;
}

void wci_triangle_normal(const double a[3], const double b[3], const double c[3], double n[3])
{
    double u[3], v[3];
    sub(b, a, u);
    sub(c, a, v);
    cross(u, v, n);
    double len = sqrt(dot(n, n));
    for (int k = 0; k < 3; ++k) n[k] = len > 0.0 ? n[k] / len : 0.0;
}

/* Ericson, Real-Time Collision Detection, 5.1.5: Voronoi regions of the
 * triangle's vertices, edges and face, in that order. */
double wci_point_triangle_closest(const double p[3], const double a[3], const double b[3],
                                 const double c[3], double bary[3])
{
    double ab[3], ac[3], ap[3], bp[3], cp[3], q[3];
    sub(b, a, ab);
    sub(c, a, ac);
    sub(p, a, ap);
    double d1 = dot(ab, ap), d2 = dot(ac, ap);
    if (d1 <= 0.0 && d2 <= 0.0) {
        bary[0] = 1.0, bary[1] = 0.0, bary[2] = 0.0;
    } else {
        sub(p, b, bp);
        double d3 = dot(ab, bp), d4 = dot(ac, bp);
        sub(p, c, cp);
        double d5 = dot(ab, cp), d6 = dot(ac, cp);
        double vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
        if (d3 >= 0.0 && d4 <= d3) {
            bary[0] = 0.0, bary[1] = 1.0, bary[2] = 0.0;
        } else if (d6 >= 0.0 && d5 <= d6) {
            bary[0] = 0.0, bary[1] = 0.0, bary[2] = 1.0;
        } else if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
            double v = d1 / (d1 - d3);
            bary[0] = 1.0 - v, bary[1] = v, bary[2] = 0.0;
        } else if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
            double w = d2 / (d2 - d6);
            bary[0] = 1.0 - w, bary[1] = 0.0, bary[2] = w;
        } else if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
            double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
            bary[0] = 0.0, bary[1] = 1.0 - w, bary[2] = w;
        } else {
            double denom = va + vb + vc;
            double v = vb / denom, w = vc / denom;
            if (!(denom > 0.0)) v = w = 1.0 / 3.0; /* degenerate triangle */
            bary[0] = 1.0 - v - w, bary[1] = v, bary[2] = w;
        }
    }
    for (int k = 0; k < 3; ++k) q[k] = bary[0] * a[k] + bary[1] * b[k] + bary[2] * c[k];
    sub(p, q, q);
    return dot(q, q);
}

static double clamp01(double x) { return x < 0.0 ? 0.0 : (x > 1.0 ? 1.0 : x); }

/* Ericson 5.1.9, with the parallel and degenerate cases handled. */
double wci_segment_segment_closest(const double p0[3], const double p1[3], const double q0[3],
                                  const double q1[3], double *s_out, double *t_out)
{
    double d1[3], d2[3], r[3];
    sub(p1, p0, d1);
    sub(q1, q0, d2);
    sub(p0, q0, r);
    double a = dot(d1, d1), e = dot(d2, d2), f = dot(d2, r);
    double s, t;
    if (a <= 0.0 && e <= 0.0) {
        s = t = 0.0;
    } else if (a <= 0.0) {
        s = 0.0;
        t = clamp01(f / e);
    } else {
        double c = dot(d1, r);
        if (e <= 0.0) {
            t = 0.0;
            s = clamp01(-c / a);
        } else {
            double b = dot(d1, d2), denom = a * e - b * b;
            s = denom > 0.0 ? clamp01((b * f - c * e) / denom) : 0.0;
            t = (b * s + f) / e;
            if (t < 0.0) {
                t = 0.0;
                s = clamp01(-c / a);
            } else if (t > 1.0) {
                t = 1.0;
                s = clamp01((b - c) / a);
            }
        }
    }
    double x[3], y[3];
    lerp(p0, p1, s, x);
    lerp(q0, q1, t, y);
    sub(x, y, x);
    *s_out = s;
    *t_out = t;
    return dot(x, x);
}

/* Coefficients of f(t) = A(t) . (B(t) x C(t)), with A, B, C linear in t:
 * A = A0 + t A1 and so on. f[k] multiplies t^k. */
static void triple_product_cubic(const double A0[3], const double A1[3], const double B0[3],
                                 const double B1[3], const double C0[3], const double C1[3],
                                 double f[4])
{
    double bc0[3], bc1a[3], bc1b[3], bc1[3], bc2[3];
    cross(B0, C0, bc0);
    cross(B0, C1, bc1a);
    cross(B1, C0, bc1b);
    for (int k = 0; k < 3; ++k) bc1[k] = bc1a[k] + bc1b[k];
    cross(B1, C1, bc2);
    f[0] = dot(A0, bc0);
    f[1] = dot(A1, bc0) + dot(A0, bc1);
    f[2] = dot(A1, bc1) + dot(A0, bc2);
    f[3] = dot(A1, bc2);
}

static double cubic_at(const double f[4], double t) { return ((f[3] * t + f[2]) * t + f[1]) * t + f[0]; }

/* Roots of the cubic in [0, 1], ascending. The interval is cut at the
 * critical points (roots of the derivative), so f is monotone on each piece
 * and bisection finds the piece's root to full precision. Returns the count. */
static int cubic_roots01(const double f[4], double roots[3])
{
    double cuts[4] = {0.0, 1.0, 1.0, 1.0};
    int ncuts = 1;
    /* f' = 3 f3 t^2 + 2 f2 t + f1 */
    double a = 3.0 * f[3], b = 2.0 * f[2], c = f[1];
    double crit[2];
    int ncrit = 0;
    if (a != 0.0) {
        double disc = b * b - 4.0 * a * c;
        if (disc >= 0.0) {
            double sq = sqrt(disc);
            double qq = -0.5 * (b + (b >= 0.0 ? sq : -sq));
            crit[ncrit++] = qq / a;
            if (qq != 0.0) crit[ncrit++] = c / qq;
        }
    } else if (b != 0.0) {
        crit[ncrit++] = -c / b;
    }
    if (ncrit == 2 && crit[0] > crit[1]) {
        double tmp = crit[0];
        crit[0] = crit[1], crit[1] = tmp;
    }
    for (int i = 0; i < ncrit; ++i)
        if (crit[i] > 0.0 && crit[i] < 1.0) cuts[ncuts++] = crit[i];
    cuts[ncuts++] = 1.0;
    int count = 0;
    for (int i = 0; i + 1 < ncuts; ++i) {
        double lo = cuts[i], hi = cuts[i + 1];
        double flo = cubic_at(f, lo), fhi = cubic_at(f, hi);
        if (flo == 0.0) {
            if (count == 0 || roots[count - 1] != lo) roots[count++] = lo;
            continue;
        }
        if ((flo < 0.0) == (fhi < 0.0)) {
            if (fhi == 0.0 && i + 2 == ncuts) roots[count++] = hi;
            continue;
        }
        for (int it = 0; it < 60 && hi - lo > 1e-15; ++it) {
            double mid = 0.5 * (lo + hi), fm = cubic_at(f, mid);
            if ((fm < 0.0) == (flo < 0.0)) lo = mid, flo = fm;
            else hi = mid;
        }
        roots[count++] = hi; /* the end just past the sign change: never early */
    }
    return count;
}

int wci_ccd_point_triangle(const double p0[3], const double p1[3], const double a0[3],
                          const double a1[3], const double b0[3], const double b1[3],
                          const double c0[3], const double c1[3], double tolerance, double *t_out,
                          double bary[3])
{
    /* Everything relative to a: A = p - a, B = b - a, C = c - a. */
    double A0[3], A1[3], B0[3], B1[3], C0[3], C1[3], tmp[3];
    sub(p0, a0, A0);
    sub(b0, a0, B0);
    sub(c0, a0, C0);
    sub(p1, a1, tmp), sub(tmp, A0, A1);
    sub(b1, a1, tmp), sub(tmp, B0, B1);
    sub(c1, a1, tmp), sub(tmp, C0, C1);
    double f[4], roots[3];
    triple_product_cubic(A0, A1, B0, B1, C0, C1, f);
    int n = cubic_roots01(f, roots);
    for (int i = 0; i < n; ++i) {
        double t = roots[i], p[3], a[3], b[3], c[3];
        lerp(p0, p1, t, p), lerp(a0, a1, t, a), lerp(b0, b1, t, b), lerp(c0, c1, t, c);
        if (wci_point_triangle_closest(p, a, b, c, bary) <= tolerance * tolerance) {
            *t_out = t;
            return 1;
        }
    }
    return 0;
}

int wci_ccd_edge_edge(const double p0[3], const double p1[3], const double q0[3],
                     const double q1[3], const double r0[3], const double r1[3],
                     const double s0[3], const double s1[3], double tolerance, double *t_out,
                     double *u, double *v)
{
    /* Coplanar when (r - p) . ((q - p) x (s - r)) = 0. */
    double A0[3], A1[3], B0[3], B1[3], C0[3], C1[3], tmp[3];
    sub(r0, p0, A0);
    sub(q0, p0, B0);
    sub(s0, r0, C0);
    sub(r1, p1, tmp), sub(tmp, A0, A1);
    sub(q1, p1, tmp), sub(tmp, B0, B1);
    sub(s1, r1, tmp), sub(tmp, C0, C1);
    double f[4], roots[3];
    triple_product_cubic(A0, A1, B0, B1, C0, C1, f);
    int n = cubic_roots01(f, roots);
    for (int i = 0; i < n; ++i) {
        double t = roots[i], p[3], q[3], r[3], s[3];
        lerp(p0, p1, t, p), lerp(q0, q1, t, q), lerp(r0, r1, t, r), lerp(s0, s1, t, s);
        if (wci_segment_segment_closest(p, q, r, s, u, v) <= tolerance * tolerance) {
            *t_out = t;
            return 1;
        }
    }
    return 0;
}

void wci_sym3_inverse(const double m[6], double out[6])
{
    double c0 = m[3] * m[5] - m[4] * m[4], c1 = m[2] * m[4] - m[1] * m[5],
           c2 = m[1] * m[4] - m[2] * m[3];
    double det = m[0] * c0 + m[1] * c1 + m[2] * c2;
    if (!(det > 0.0) || !(m[0] > 0.0)) {
        for (int k = 0; k < 6; ++k) out[k] = 0.0;
        return;
    }
    double inv_det = 1.0 / det;
    out[0] = c0 * inv_det;
    out[1] = c1 * inv_det;
    out[2] = c2 * inv_det;
    out[3] = (m[0] * m[5] - m[2] * m[2]) * inv_det;
    out[4] = (m[1] * m[2] - m[0] * m[4]) * inv_det;
    out[5] = (m[0] * m[3] - m[1] * m[1]) * inv_det;
}
