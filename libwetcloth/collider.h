/* Colliders: triangle meshes (static or animated) and solid convex shapes
 * (moved by a pose). Both store where they are now (`current`) and where
 * they must be at the end of the running advance (`target`); a step moves
 * them linearly from one toward the other. */
#ifndef WC_COLLIDER_H
#define WC_COLLIDER_H

#include <stdint.h>

#include "broadphase.h"
#include "wetcloth.h"

/// The most a collider's surface may turn at a smooth feature, radians
/// (6 degrees): an edge whose two faces' normals differ by no more, a vertex
/// whose faces' normals all lie within half of it of their mean. A UV
/// sphere of 64 segments turns by 5.6 degrees at an edge, the thesis' 16
/// segments by 22.5.
#define WC_SMOOTH_FEATURE_ANGLE (6.0 * 3.14159265358979323846 / 180.0)

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
    /// Unique edges of the triangles, 2 vertex indices each (a degenerate
    /// triangle's collapsed edge left out), ascending.
    int32_t edge_count;
    int32_t *edges;
    /// Vertex positions now, xyz per vertex.
    double *current;
    /// Vertex positions at the end of the running advance.
    double *target;
    /// Vertex positions at the end of the step being computed.
    double *next;
    /// Whether target differs from current (the collider is animated now).
    int moving;
    /// Box around the whole collider over the running advance (min xyz,
    /// max xyz); for a convex collider, over the step.
    double bounds[6];
    /// Per triangle: its box over the running advance (current and target
    /// positions), and the tree over them (broadphase.h): built at the first
    /// step, refit (not rebuilt) when the collider is given new vertices.
    double *boxes;
    wc_bvh bvh;
    /// The same for the unique edges, and for the vertices that triangles
    /// use (`used_vertices`, ascending; the tree's items index it): the
    /// cloth's edges and triangles find the collider's edges and vertices
    /// near them directly, each once, in boxes as thin as the feature
    /// (through the triangles, each edge came twice and each vertex about
    /// six times, in boxes as large as a triangle).
    double *edge_boxes, *vertex_boxes;
    wc_bvh edge_bvh, vertex_bvh;
    int32_t *used_vertices;
    int32_t used_vertex_count;
    /// Per vertex and per edge: whether the feature is smooth (the surface
    /// turns there by no more than WC_SMOOTH_FEATURE_ANGLE; classify_features
    /// in collider.c), judged on the shape the collider was made with. A
    /// smooth feature of a dense mesh lies within a fraction of a millimetre
    /// of the faces around it, which hold the cloth off it already; its own
    /// test is kept at a smaller distance (narrowphase.h), so that the lists
    /// of a cloth resting on the faces need not hold it (candidates.c).
    uint8_t *vertex_smooth, *edge_smooth;
    /// The used vertices are in two runs, the sharp ones then the smooth
    /// ones (each ascending), split at smooth_vertices_from; the edges'
    /// vertex pairs and indices likewise in `class_edges` and `edge_order`.
    /// edge_boxes and vertex_boxes follow these orders; edge_bvh and
    /// vertex_bvh index the sharp runs, the smooth trees the smooth runs
    /// (their items counted from the run's start).
    int32_t *class_edges, *edge_order;
    int32_t smooth_edges_from, smooth_vertices_from;
    wc_bvh smooth_edge_bvh, smooth_vertex_bvh;
    /// Whether the boxes and the tree describe the running advance.
    int indexed;
    /// Mean length of the triangles' edges when the tree was built: the
    /// scale of the collider's features (candidates.c, margins).
    double feature_size;
    /// Unit normal of each triangle while the collider stands still (zero
    /// for a degenerate triangle, which is then ignored), valid while
    /// normals_current; a moving collider's are made where a test needs
    /// them (narrowphase.c).
    double *normals;
    int normals_current;
    /// Counts the shapes the collider has stood still in: it grows each
    /// time the collider comes to rest after moving, so that what was
    /// measured on a shape (support.h) knows when it no longer holds.
    int64_t shape;
    /// The collider's path: summed over the committed steps, the largest
    /// displacement of any of its vertices in each; and that displacement
    /// in the step being computed. No vertex has moved farther than the
    /// difference of two paths between them (candidates.h).
    double path, step_motion;
    /// While moving, the box (min xyz, max xyz) of this step's
    /// displacements of each triangle's corners, and the union of its
    /// triangles' per node of the tree (wci_bvh_fold_boxes): what the
    /// candidates read to bound the collider's motion near each cloth
    /// particle, relative to a translation that follows it (candidates.h).
    /// Made at the first step that moves it.
    double *triangle_shift, *node_shift;

    /* Convex colliders. */
    wc_convex_shape convex;
    wc_pose pose_current;
    wc_pose pose_target;
    wc_pose pose_next;
} wc_collider;

void wci_collider_destroy(wc_collider *collider);

/// Readies a collider for a step that covers `share` of what is left of the
/// running advance (1 / substeps left): next = current + (target - current)
/// * share and its step motion; at the first step of an advance that moves
/// it (or the first step at all), its boxes over the advance and its tree
/// (built once, refit after), and the normals of a static one.
wc_status wci_collider_begin_step(wc_collider *collider, double share);

/// After a step that was committed: the collider is now where it was headed.
void wci_collider_end_step(wc_collider *collider);

#endif
