/* Collider vertices and edges against cloth triangles and edges.
 *
 * Keeping every particle at the contact distance from every collider
 * triangle (collide.c) is not enough on its own: a collider's vertices and
 * edges can still poke through a cloth triangle whose corners all rest on
 * the collider's faces (a 5 cm cloth over the thesis' faceted sphere, whose
 * vertices stand ~6 mm proud of its face centres; a cloth wrapped round the
 * edge of a thin plate). This pass treats the collider's vertices against
 * the cloth's triangles and the collider's edges against the cloth's edges:
 * proximity within the contact distance at the end of the step, plus
 * continuous detection of the relative motion, the side taken from the start
 * of the step, and an inelastic response with friction shared among the
 * cloth element's particles by barycentric weight and inverse mass (the
 * collider has infinite mass). */
#ifndef WC_COLLIDE_FEATURES_H
#define WC_COLLIDE_FEATURES_H

#include "cloth.h"
#include "collide.h"
#include "collider.h"

/// Per-cloth buffers: the cloth's triangle edges, boxes, grid. Opaque.
typedef struct wc_feature_state wc_feature_state;

/// NULL on out-of-memory.
wc_feature_state *wc_feature_state_create(const wc_cloth *cloth);
void wc_feature_state_destroy(wc_feature_state *state);

/// Whether the pass keeps near lists (near_list.h) of static colliders
/// across steps (1, the default) or asks the grids every pass (0). The
/// results are the same either way; tests compare the two.
void wc_feature_state_keep_near_lists(wc_feature_state *state, int keep);

/// The near list kept for collider `collider` (by index), or NULL if there
/// is none; the particle pass (collide.c) uses its particle part.
struct wc_near_list *wc_feature_state_near_list(wc_feature_state *state, int32_t collider);

/// Path lengths of the particles' ends of step (near_list.h, clearances).
/// At the start of a step's collision passes: each particle's path goes on
/// to its start of step, which is noted, and then to its end.
void wc_feature_state_begin_step(wc_feature_state *state, const wc_cloth *cloth);
/// After particle i's end of step moved: its path goes on to it. Touches
/// only particle i's entries (safe in a parallel loop over particles).
void wc_feature_state_track(wc_feature_state *state, const wc_cloth *cloth, int32_t particle);
/// Particle i's path length now.
double wc_feature_state_path(const wc_feature_state *state, int32_t particle);
/// How far particle i's start and end of step can be from where its end
/// was when its path length was path_at (in this step or an earlier one).
double wc_feature_state_drift(const wc_feature_state *state, int32_t particle, double path_at);

/// The marks the particle pass and this pass leave each other between
/// rounds (collide.h), kept here for the cloth.
const wc_collide_marks *wc_feature_state_marks(const wc_feature_state *state);

/// Resolves collider vertices and edges of every mesh collider against the
/// cloth's motion from (x, y, z) to (nx, ny, nz). Serial and in a fixed
/// order (collider, vertex, edge, candidate), so deterministic. Its first
/// pass tests every triangle and edge if `all`, else only those with a
/// particle marked in marks->shifted; it marks in marks->recheck each
/// particle it moves and leaves its fail-safe particles in marks->shifted.
/// *moved_out says whether it moved anything.
wc_status wc_collide_features(wc_cloth *cloth, wc_feature_state *state,
                              wc_collider *const *colliders, int32_t collider_count, double dt,
                              int all, wc_step_stats *stats, int *moved_out);

#endif
