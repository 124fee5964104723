/* Geometric primitives for collision: closest points and continuous
 * (swept) tests of a point against a triangle and an edge against an edge,
 * both moving linearly over a step. Plain double[3] vectors. */
#ifndef WC_PRIMITIVES_H
#define WC_PRIMITIVES_H

#include <math.h>

/// a + (b - a) t, t in [0, 1]: where a motion is spread over substeps. Where
/// b - a overflows (a and b near the ends of the double range with opposite
/// signs) the weighted sum a (1 - t) + b t instead, which stays between
/// them: the usual form gave infinity and then NaN (a collider's vertices
/// went NaN mid-advance and stayed so; found by fuzzing). Otherwise the
/// usual form, bit for bit.
static inline double wc_lerp(double a, double b, double t)
{
    double d = b - a;
    return isfinite(d) ? a + d * t : a * (1.0 - t) + b * t;
}

/// out = B (x, y, z) for a symmetric 3 x 3 matrix B given as xx, xy, xz,
/// yy, yz, zz (the link and diagonal blocks of implicit.c and multigrid.c).
static inline void wc_sym3_times(const double b[6], double x, double y, double z, double out[3])
{
    out[0] = b[0] * x + b[1] * y + b[2] * z;
    out[1] = b[1] * x + b[3] * y + b[4] * z;
    out[2] = b[2] * x + b[4] * y + b[5] * z;
}

/// Inverse of a symmetric 3 x 3 matrix given as xx, xy, xz, yy, yz, zz,
/// into the same layout, by cofactors. A matrix that is not positive
/// definite (determinant or xx not > 0, NaN included) gets zeros: the
/// preconditioners that use it (implicit.c, multigrid.c) invert blocks that
/// are positive definite, or empty ones, whose rows must stay zero.
void wci_sym3_inverse(const double m[6], double out[6]);

/// Closest point of triangle (a, b, c) to p. Returns the squared distance and
/// writes the barycentric coordinates (weights of a, b, c) of the closest point.
double wci_point_triangle_closest(const double p[3], const double a[3], const double b[3],
                                 const double c[3], double bary[3]);

/// Closest points of segments p0-p1 and q0-q1. Returns the squared distance
/// and writes the parameters s (along p) and t (along q), both in [0, 1].
double wci_segment_segment_closest(const double p0[3], const double p1[3], const double q0[3],
                                  const double q1[3], double *s, double *t);

/// Earliest time t in [0, 1] at which point p and triangle (a, b, c), each
/// moving linearly from its "0" to its "1" position, are coplanar with the
/// point within `tolerance` (m) of the triangle. Solves the coplanarity cubic
/// (Provot 1997; Bridson et al. 2002). Returns 1 and writes t and the
/// barycentric coordinates of the contact at t, or 0 when they never meet.
int wci_ccd_point_triangle(const double p0[3], const double p1[3], const double a0[3],
                          const double a1[3], const double b0[3], const double b1[3],
                          const double c0[3], const double c1[3], double tolerance, double *t,
                          double bary[3]);

/// Earliest time t in [0, 1] at which edges p-q and r-s, moving linearly,
/// are coplanar and within `tolerance` of each other. Returns 1 and writes t
/// and the parameters along each edge at that time, or 0.
int wci_ccd_edge_edge(const double p0[3], const double p1[3], const double q0[3],
                     const double q1[3], const double r0[3], const double r1[3],
                     const double s0[3], const double s1[3], double tolerance, double *t,
                     double *u, double *v);

/// Unit normal of triangle (a, b, c) (right-handed); zero vector when degenerate.
void wci_triangle_normal(const double a[3], const double b[3], const double c[3], double n[3]);

#endif
