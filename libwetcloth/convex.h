/* Solid convex colliders through libccd: sphere, capsule, box and convex
 * hull. A particle is a ball of the contact radius (cloth thickness plus
 * collider thickness); its exact penetration depth and direction come from
 * the shapes' support functions (GJK distance to the shape's core, libccd's
 * EPA inside it), libccd's MPR tells whether a fast particle's path meets
 * the shape. Everything here works in the shape's local frame; the pose
 * helpers convert. (NOTES: MPR is wrong for flat triangles, so mesh
 * triangles never come here; they use closed-form distances.) */
#ifndef WC_CONVEX_H
#define WC_CONVEX_H

#include "collider.h"

/// Validates a convex collider description (shape, radius, half_height,
/// half_extents, points/point_count spanning a volume, rotation non-zero and
/// finite, position finite, thickness, friction) naming the first bad field,
/// and fills the shape (hull points copied) and the normalised pose.
wc_status wci_convex_shape_create(wc_convex_shape *shape, wc_pose *pose,
                               const wc_convex_collider_def *def, wc_message *msg);
void wci_convex_shape_destroy(wc_convex_shape *shape);

/// Penetration of a ball (centre c, radius r, local coordinates) into the
/// shape: the smallest one, exact to rounding (convex.c says why this is not
/// libccd's MPR depth). Returns 1 on contact and writes depth (m, > 0) and
/// the unit direction `dir` from the ball into the shape: moving the ball by
/// -depth * dir separates them. Returns 0 when they do not touch; a
/// penetration below 1e-10 of (bounding radius + r) counts as touching, so a
/// ball just put at distance r is not found in contact again by rounding.
int wci_convex_penetration(const wc_convex_shape *shape, const double c[3], double r,
                          double *depth, double dir[3]);

/// A particle moving from a to b (local coordinates) as a ball of radius r.
/// Returns 1 when it touches the shape at b or on the way (a fast particle
/// that would pass through is caught at its first contact); then writes the
/// position it may have at the end of the step (on the surface, at distance r)
/// and the outward unit normal there. Returns 0 (outputs untouched) otherwise.
int wci_convex_resolve(const wc_convex_shape *shape, const double a[3], const double b[3],
                      double r, double out[3], double normal[3]);

/// Whether triangle (a, b, c), world coordinates, reaches inside the shape at
/// the pose (thickness ignored). For the intersection checker.
int wci_convex_triangle_intersects(const wc_convex_shape *shape, const wc_pose *pose,
                                  const double a[3], const double b[3], const double c[3]);

/// World to local coordinates of a point.
void wci_pose_to_local(const wc_pose *pose, const double world[3], double local[3]);
/// Local to world coordinates of a point.
void wci_pose_to_world(const wc_pose *pose, const double local[3], double world[3]);
/// Rotates a vector from local to world (no translation).
void wci_pose_rotate(const wc_pose *pose, const double v[3], double out[3]);
/// Pose a fraction t of the way from a to b: positions linearly, rotations
/// by normalised linear interpolation along the shorter arc.
void wci_pose_lerp(const wc_pose *a, const wc_pose *b, double t, wc_pose *out);

#endif
