/* Support planes: where a static mesh collider lies wholly behind one of its
 * triangles' planes.
 *
 * A particle that a collider triangle t holds (after the test of t, its
 * path over the step lies in front of t's plane and its end at least the
 * contact distance r in front of it) cannot touch any triangle whose corners
 * all lie on or behind that plane: such a triangle is no nearer to the end
 * than the plane, and the path, in front of the plane all along, never meets
 * it. On a convex collider that is every triangle, so one test answers for
 * the whole collider where the particle pass would otherwise test every
 * triangle the filter keeps: on the 30,624-triangle sphere at Blender's
 * collider thickness (r = 0.02 m against 1 cm triangles) a resting
 * particle has 5-7 triangles within a tenth of a millimetre of r, which
 * the filter cannot leave out.
 *
 * For each triangle and each side of its plane, the reach is the least
 * distance from the triangle of a collider vertex beyond the plane on that
 * side (by more than a rounding tolerance): every vertex nearer lies on the
 * plane or behind it. A triangle with a corner at least the reach from t
 * lies wholly at least reach - longest_edge from t, so a particle whose
 * path stays within reach - longest_edge - r of t has nothing to touch
 * there either (wci_support_holds). The reaches are measured up to a cap,
 * from the contact distance: a convex collider's front reaches are the cap.
 * The contact stage measures a triangle's reach when the triangle first
 * pushes a particle, at the start of the next step (so that a step taken
 * again sees what the first try saw); a triangle that held a particle is
 * the first it tests for that particle at the next step.
 *
 * A moving collider has none (its shape changes within the step); one at
 * rest again has them measured again for its new shape (wc_collider.shape). */
#ifndef WC_SUPPORT_H
#define WC_SUPPORT_H

#include <stdint.h>

#include "collider.h"
#include "wetcloth.h"

typedef struct wc_support {
    /// Per triangle, two reaches, m: beyond the front of its plane (the side
    /// its normal points to) and beyond the back; at most `cap`; negative
    /// until measured (wci_support_measure), 0 for a degenerate triangle.
    /// Measured one triangle and side at a time, as they come to hold
    /// particles: a whole dense collider would cost more than the contacts
    /// it saves over a shot.
    double *reach;
    int32_t triangle_count;
    /// The contact distance they are for, and the distance they are
    /// measured up to (support.c: CAP_R, CAP_EDGE), m.
    double r, cap;
    /// A vertex within this of a plane counts as on it, m: far above the
    /// rounding of the heights measured (1e-12 of the farthest a measured
    /// vertex can be from the plane's corner), far below anything physical.
    double tolerance;
    /// The collider's longest triangle edge, m.
    double longest_edge;
    /// The collider's shape (wc_collider.shape) they are for, and whether
    /// they are for any (0: none).
    int64_t shape;
    int made;
} wc_support;

/// Frees the reaches and zeroes the record.
void wci_support_destroy(wc_support *support);

/// Whether the reaches are for the collider as it stands and the contact
/// distance r (never for a moving collider).
int wci_support_ready(const wc_support *support, const wc_collider *collider, double r);

/// Makes the reaches ready for a static mesh collider and the contact
/// distance r, every one unmeasured, unless they are ready already.
/// WC_ERROR_OUT_OF_MEMORY leaves none.
wc_status wci_support_prepare(wc_support *support, const wc_collider *collider, double r);

/// The side of triangle t's plane a point is on: 0 in front (the side its
/// normal points to), 1 on it or behind.
int wci_support_side(const wc_collider *collider, int32_t t, const double point[3]);

/// Whether triangle t's reach on a side is measured.
int wci_support_measured(const wc_support *support, int32_t t, int side);

/// Measures triangle t's reach on a side. Needs wci_support_ready and the
/// collider's static normals (a step has begun).
void wci_support_measure(wc_support *support, const wc_collider *collider, int32_t t, int side);

/// Whether triangle t holds a particle whose step goes from `start` to
/// `end` at the reaches' contact distance: both on one side of t's plane
/// (the start's: wci_support_side),
/// the end at least r from it (by the face test's slack, WC_FACE_SLACK),
/// and every collider triangle that the path could come within r of lying
/// behind it (see above). Then no triangle of the collider can touch the
/// particle in this step. Needs t's reach on the start's side measured.
int wci_support_holds(const wc_support *support, const wc_collider *collider, int32_t t,
                      const double start[3], const double end[3]);

#endif
