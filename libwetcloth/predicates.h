/* Exact orientation predicates for the intersection checker (checker.c).
 *
 * Each gives the sign of a determinant of point coordinates exactly: first
 * in floating point, which decides whenever the result is larger than a
 * bound on its rounding error (Shewchuk 1997, "Adaptive precision floating-
 * point arithmetic and fast robust geometric predicates": the bound on the
 * same formula with rounded differences), and otherwise again in exact
 * expansion arithmetic (sums of non-overlapping doubles; products split
 * with fma, which C99 guarantees correctly rounded). So a pair of triangles
 * that merely come close is never taken for one that intersects, and a
 * pair that touches is found touching.
 *
 * Coordinates must be finite and not so small that their products
 * underflow (below about 1e-150 m: nothing a cloth is made of). */
#ifndef WC_PREDICATES_H
#define WC_PREDICATES_H

/// Sign (-1, 0, +1) of det[b - a, c - a, d - a]: +1 when d lies on the side
/// of the plane through a, b, c that (b - a) x (c - a) points to.
int wci_orient3d(const double a[3], const double b[3], const double c[3], const double d[3]);

/// Sign of det[b - a, c - a] for 2D points: +1 when a, b, c turn
/// counter-clockwise.
int wci_orient2d(const double a[2], const double b[2], const double c[2]);

#endif
