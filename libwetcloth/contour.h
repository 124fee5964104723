/* The contour condition of self-collision's normal-cone cull (Volino &
 * Magnenat-Thalmann 1994): when a region of cloth cannot pass through itself.
 *
 * Let a region be a disk of triangles, oriented consistently, every normal of
 * which stays within 90 degrees of one direction d over the step. Projected
 * onto the plane across d every triangle keeps a positive area, so for a
 * point y of the plane off the projected boundary the number of triangles
 * over y equals the winding number of the projected boundary around y (the
 * degree of the projection). If that boundary is a simple closed curve, the
 * winding number is 0 or 1: the projection is one-to-one, the region is a
 * height field over the plane, and no two of its points can meet (Floater
 * 2003, "One-to-one piecewise linear mappings over triangulations"). A crushed
 * free edge that folds over itself in the plane, every triangle still facing
 * d, breaks exactly this: its boundary crosses itself.
 *
 * So the cull needs, besides the cone, two things checked here:
 *  - the region is an oriented disk (a fact of the rest mesh, checked once
 *    per patch and per pair of patches: wci_region_is_disk);
 *  - its projected boundary stays simple over the whole step (per step:
 *    wci_contour_simple). */
#ifndef WC_CONTOUR_H
#define WC_CONTOUR_H

#include <stdint.h>

/// One directed edge of a triangle: the edge's endpoints sorted, its
/// direction, and its triangle's position in the region's list.
typedef struct wc_half_edge {
    int32_t lo, hi, from, to, owner;
} wc_half_edge;

/// Whether the triangles list[0 .. count) (3 particles each in triangles)
/// form a disk: connected across shared edges, every edge in at most two of
/// them and then in opposite directions (oriented alike), one boundary loop
/// through each of its vertices once, and Euler characteristic 1. halves and
/// vertices are scratch of 3 * count entries each.
int wci_region_is_disk(const int32_t *triangles, const int32_t *list, int32_t count,
                       wc_half_edge *halves, int32_t *vertices);

/// A boundary segment of a region projected onto the plane across d: the
/// particles, both ends at the start of the step (a0, b0) and their
/// displacements over it (da, db), its swept box and the larger of its ends'
/// displacements. Filled by wci_contour_simple.
typedef struct wc_contour_segment {
    int32_t from, to;
    double a0[2], b0[2], da[2], db[2];
    double box[4];
    double reach;
} wc_contour_segment;

/// Whether the boundary segments segments[0 .. count) of a disk region (only
/// from and to set by the caller) stay a simple closed curve in projection
/// along the unit vector d while every particle moves linearly from
/// (x, y, z) to (nx, ny, nz): segments without a common end never meet, and
/// two with one never fold onto each other. Conservative: 0 also when a test
/// is too close to call. Looks at the motion relative to the boundary's mean
/// motion, and first at whether the loop stays star-shaped round its centre
/// (O(count)); only then pairs up segments whose swept boxes overlap. scale is a length of the region (its mean edge), for
/// rounding margins. Fills the rest of each segment and reorders them.
int wci_contour_simple(wc_contour_segment *segments, int32_t count, const double d[3],
                       const double *x, const double *y, const double *z, const double *nx,
                       const double *ny, const double *nz, double scale);

#endif
