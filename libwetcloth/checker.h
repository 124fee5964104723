/* The intersection checker: counts intersecting triangle pairs in a world's
 * current state. Deliberately shares no code with the collision solver
 * (its own triangle-triangle test, its own sort-and-sweep broadphase), so a
 * solver bug cannot hide from it. */
#ifndef WC_CHECKER_H
#define WC_CHECKER_H

#include "wetcloth.h"

/// Whether triangles (p0, p1, p2) and (q0, q1, q2) intersect (touching counts).
int wci_triangles_intersect(const double p0[3], const double p1[3], const double p2[3],
                           const double q0[3], const double q1[3], const double q2[3]);

#endif
