/* Narrowphase of cloth against colliders: the exact tests of the pairs the
 * candidates' filter kept (candidates.h), each turning a touch into a
 * contact record (response.h) that the response then answers.
 *
 *  * A particle against a collider triangle: proximity within the contact
 *    distance r at the end of the step, and for a crossing during the step
 *    the thesis' plane test (eq. 2.5-2.6: the signed distances at the two
 *    ends of the motion differ in sign, the crossing point lies in the
 *    triangle) against a static triangle, which is linear, or the
 *    coplanarity cubic on the relative motion against a moving one.
 *  * A particle against a convex shape: libccd's support functions
 *    (convex.c), the motion taken into the shape's frame.
 *  * A collider vertex against a cloth triangle, a collider edge against a
 *    cloth edge (the faceted solid's proud vertices and edges, a thin
 *    plate's rim): proximity, and the continuous test when the pair moves
 *    relative to each other by more than r.
 *
 * The side a cloth element belongs on is the side it was on at the start
 * of the step, read along a direction that cannot turn over without a
 * crossing (turning_cross). All tests only read. */
#ifndef WC_NARROWPHASE_H
#define WC_NARROWPHASE_H

#include "collider.h"
#include "response.h"

/// A particle counts as touching a collider face only nearer than
/// r sqrt(1 - WC_FACE_SLACK): a particle the last pass put at distance r may
/// sit a rounding error inside it, and must not count as a new contact.
#define WC_FACE_SLACK 1e-9

/// A contact counts for the feature tests only if it is deeper than this
/// fraction of the contact distance: where a collider corner and its edges
/// push the same cloth element in turn, what is left shrinks geometrically
/// rather than vanishing, and 1 % of r left over is harmless (an
/// intersection needs a violation of the whole contact distance).
#define WC_FEATURE_SLACK 1e-2

/// The contact distance of a collider feature (a vertex against a cloth
/// triangle, an edge against a cloth edge), as a fraction of the particle
/// contact distance r. Features hold the cloth a little nearer than faces
/// do, so that a cloth resting at r on the faces of a smooth dense collider
/// is not also resting on its vertices and edges: the chord of a cloth
/// edge of length L over a collider of radius R dips L^2 / (8 R) below its
/// ends (0.15 mm for a 2 cm edge over a 0.3 m sphere), which at a feature
/// distance of r put every collider edge a cloth edge lies over inside
/// reach, and each got its exact test at every step (the 50 x 50 cloth on
/// the 30,624-triangle sphere: 38 M edge-edge tests in 12 frames for 1,003
/// pushes). At 0.9 r those pairs sit 0.1 r clear and the candidates' filter
/// skips them; only features that really stand proud of the faces (a
/// faceted solid's corners, a thin plate's rim) are tested. The guarantee
/// does not depend on it: any positive distance keeps the cloth out.
#define WC_FEATURE_DISTANCE 0.9

/// The contact distance of a smooth collider feature (collider.h: the
/// surface turns there by at most WC_SMOOTH_FEATURE_ANGLE), as a fraction
/// of r, where the candidates choose it (candidates.h). The faces around
/// such a feature hold a cloth resting on them at r off it already; at
/// 0.9 r every smooth vertex and edge under a resting cloth was within its
/// lists' reach (0.9 r plus a margin of up to 0.5 r), and making those
/// lists was half of a frame on a dense collider (the bending tube: 1.04 M
/// vertex and 11.2 M edge pairs listed over 24 frames, 221 ms of
/// collisions per frame; at half r 0.66 M and 1.25 M, 115 ms). At half r,
/// no more than r with the largest margin, it is listed only when the
/// cloth comes nearer to it than to the faces. Any positive distance keeps
/// the guarantee: the cloth does not cross it.
#define WC_SMOOTH_FEATURE_DISTANCE 0.5

/// Particle moving from start to end against collider triangle t of a mesh
/// collider at contact distance r. Returns 1 and fills the record (source,
/// count 1 with the particle index `particle`, normal, distance, target r,
/// surface motion, place; friction left to the caller) on a touch.
/// *end_d2 gets a lower bound on the square of the particle's distance
/// from the triangle at the end of the step (the exact one, or the distance
/// from its plane where that already rules a touch out; 0 for a degenerate
/// triangle): what a renewed snapshot may credit the pair with.
int wci_narrow_particle_triangle(const wc_collider *col, int32_t t, int32_t particle,
                                const double start[3], const double end[3], double r,
                                double *end_d2, wc_contact *out);

/// The same against a convex collider.
int wci_narrow_particle_convex(const wc_collider *col, int32_t particle, const double start[3],
                              const double end[3], double r, wc_contact *out);

/// Whether a pair that moves relative to each other by up to `motion` (the
/// largest displacement of any of its points over the step, twice of which
/// bounds the relative motion) needs the continuous test at contact
/// distance r: the pair was at least r apart at the start (the previous step
/// saw to it) and distance changes no faster than the points move, so with
/// less relative motion than r a crossing still ends within r, where the
/// proximity test sees it and takes the side from the start.
int wci_narrow_needs_ccd(double motion, double r);

/// Collider vertex v against cloth triangle `tri` (3 particle indices) of
/// the particle arrays. *d2 gets the squared distance at the end of the step
/// before any response. Returns 1 and fills the record on a touch deeper
/// than the slack.
int wci_narrow_vertex_triangle(const wc_particle_arrays *p, const int32_t tri[3],
                              const wc_collider *col, int32_t v, int ccd, double r, double *d2,
                              wc_contact *out);

/// Collider edge f against cloth edge `edge` (2 particle indices); as
/// wci_narrow_vertex_triangle.
int wci_narrow_edge_edge(const wc_particle_arrays *p, const int32_t edge[2], const wc_collider *col,
                        int32_t f, int ccd, double r, double *d2, wc_contact *out);

#endif
