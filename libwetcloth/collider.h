/* Colliders: triangle meshes (static or animated) and solid convex shapes
 * (moved by a pose). Both store where they are now (`current`) and where
 * they must be at the end of the running advance (`target`); a step moves
 * them linearly from one toward the other. */
#ifndef WC_COLLIDER_H
#define WC_COLLIDER_H

#include <stdint.h>

#include "grid.h"
#include "wetcloth.h"

/// Position and orientation: x_world = position + rotate(rotation, x_local).
typedef struct wc_pose {
    double position[3];
    /// Unit quaternion (w, x, y, z).
    double rotation[4];
} wc_pose;

/// Geometry of a convex collider in its local frame.
typedef struct wc_convex_shape {
    wc_shape shape;
    double radius;
    double half_height;
    double half_extents[3];
    /// Hull points (WC_SHAPE_CONVEX_HULL), 3 * point_count, local coordinates.
    double *points;
    int32_t point_count;
    /// Radius of a ball around the local origin that holds the whole shape.
    double bound_radius;
} wc_convex_shape;

typedef struct wc_collider {
    /// 1 for a triangle mesh, 0 for a convex shape.
    int is_mesh;
    double thickness;
    double friction;

    /* Mesh colliders. */
    int32_t vertex_count;
    int32_t triangle_count;
    int32_t *triangles;
    /// Unique edges of the triangles, 2 vertex indices each, and the 3 edge
    /// ids of each triangle (-1 for a degenerate triangle's collapsed edge).
    int32_t edge_count;
    int32_t *edges;
    int32_t *triangle_edges;
    /// Boxes of the vertices and edges over the step (current and next
    /// positions) and their grids, for the feature pass (collide_features.c);
    /// rebuilt with the triangle grid, so never for a static collider.
    double *vertex_boxes;
    double *edge_boxes;
    wc_grid vertex_grid;
    wc_grid edge_grid;
    /// Vertex positions now, xyz per vertex.
    double *current;
    /// Vertex positions at the end of the running advance.
    double *target;
    /// Vertex positions at the end of the step being computed.
    double *next;
    /// Whether target differs from current (the collider is animated now).
    int moving;
    /// Box around the whole collider over the step (min xyz, max xyz).
    double bounds[6];
    /// Unit normal of each triangle at the start and at the end of the step
    /// (zero for a degenerate triangle, which is then ignored).
    double *normal_current;
    double *normal_next;
    /// Per triangle: its box over the step (current and next positions),
    /// grown by the largest contact distance; the grid indexes them.
    double *boxes;
    wc_grid grid;
    /// The grid holds boxes of the current positions and needs no rebuild
    /// while the collider does not move.
    int grid_static;
    /// Counts the builds of the grids, so what was made from them (the
    /// feature pass' near lists) can tell they changed.
    int64_t grid_version;

    /* Convex colliders. */
    wc_convex_shape convex;
    wc_pose pose_current;
    wc_pose pose_target;
    wc_pose pose_next;
} wc_collider;

void wc_collider_destroy(wc_collider *collider);

/// Readies a collider for a step that covers `share` of what is left of the
/// running advance (1 / substeps left): next = current + (target - current)
/// * share, its step boxes and, unless it is static and already indexed, its
/// grid.
wc_status wc_collider_begin_step(wc_collider *collider, double share);

/// After a step that was committed: the collider is now where it was headed.
void wc_collider_end_step(wc_collider *collider);

#endif
