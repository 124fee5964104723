/* Geometry the tests share: the thesis' collision solid and small meshes. */
#ifndef WC_TEST_SCENES_H
#define WC_TEST_SCENES_H

#include <stdint.h>

#include "wetcloth.h"

/// UV sphere of `segments` x `rings` around the origin (the thesis' 114-vertex
/// solid is 16 x 8): 2 + (rings - 1) * segments vertices,
/// 2 * segments * (rings - 1) triangles, outward-facing. Writes into caller
/// arrays of that size; returns the vertex count.
int32_t scene_uv_sphere(double radius, int32_t segments, int32_t rings, double *vertices,
                        int32_t *triangles, int32_t *triangle_count);

/// Creates a world from `def`; aborts the test on failure.
wc_world *scene_world_from(const wc_world_def *def);

/// Creates a world with default settings and the given thread count; aborts
/// the test on failure.
wc_world *scene_world(int32_t threads);

/// Adds a grid cloth; aborts the test on failure. Returns its index.
int32_t scene_add_grid(wc_world *world, const wc_grid_cloth_def *def);

/// Adds the thesis' 114-vertex UV sphere (radius r, centre at the origin) as
/// a mesh collider; returns its index.
int32_t scene_add_thesis_sphere(wc_world *world, double radius);

/// Adds a square collider plate of two triangles, side `size`, centred at
/// `center`, in the plane spanned by axes u and v (unit). Returns its index.
int32_t scene_add_plate(wc_world *world, const double center[3], const double u[3],
                        const double v[3], double size, double thickness);

/// Plate corner positions for wc_collider_set_vertices (12 doubles).
void scene_plate_vertices(const double center[3], const double u[3], const double v[3],
                          double size, double out[12]);

/// Particles of a cloth within `within` (m) of the surface of the thesis'
/// UV sphere (16 x 8, `radius`, at the origin), by brute force over its
/// triangles: independent of the solver's broadphase.
int scene_count_near_sphere(const wc_world *world, int32_t cloth, double radius, double within);

/// Distance of each of `count` points (xyz) to a triangle mesh, by brute
/// force over its triangles: independent of the solver's broadphase.
void scene_distances_to_mesh(const double *points, int32_t count, const double *vertices,
                             const int32_t *triangles, int32_t triangle_count, double *out);

/// Intersections in the world by the independent checker (cloth-cloth plus
/// cloth-collider); on an error prints it and returns 1000000, which fails
/// any check for none.
int scene_intersections(const wc_world *world);
/// FNV-1a hash of a cloth's positions (bitwise).
uint64_t scene_hash_positions(const wc_world *world, int32_t cloth);

#endif
