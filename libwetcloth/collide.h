/* Cloth against colliders (SPEC 2): continuous detection of each particle's
 * motion over the step against collider triangles (the coplanarity cubic on
 * the relative motion, thesis eq. 2.5-2.6 generalised to moving triangles),
 * proximity within the contact distance, libccd for convex shapes, and the
 * response of thesis eq. 2.7 as corrected: the normal part of the velocity
 * relative to the collider is removed, the tangential part meets Coulomb
 * friction. */
#ifndef WC_COLLIDE_H
#define WC_COLLIDE_H

#include "cloth.h"
#include "collider.h"

/// What one round of the collision passes leaves for the next (world.c
/// runs this particle pass and the feature pass, collide_features.h, in
/// turn until the feature pass moves nothing). Whether a pass finds a
/// contact depends only on positions, so a particle or element that a pass
/// found free and that nothing has moved since is still free: the next
/// round tests only what was moved, with the same result as testing all.
typedef struct wc_collide_marks {
    /// Per particle: the particle pass must test it again (the feature pass
    /// moved it, or the particle pass left it to its fail-safe).
    uint8_t *recheck;
    /// Per particle: the feature pass must test its triangles and edges
    /// again (the particle pass moved it, or the feature pass left it to
    /// its fail-safe).
    uint8_t *shifted;
} wc_collide_marks;

/// Moves each particle's end-of-step position (nx/ny/nz) out of every
/// collider, sets its new velocity through the history override and marks
/// contacts. Tests every particle if `all`, else only those marked in
/// marks->recheck; leaves recheck marking its fail-safe particles and
/// marks in shifted each particle it moved. Particles are independent, so
/// the loop is parallel and its result the same for any thread count. Adds
/// fail-safe particles to stats.
void wc_collide_cloth(wc_cloth *cloth, wc_collider *const *colliders, int32_t collider_count,
                      double dt, int threads, int all, const wc_collide_marks *marks,
                      wc_step_stats *stats);

#endif
