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

/// Moves each particle's end-of-step position (nx/ny/nz) out of every
/// collider, sets its new velocity through the history override and marks
/// contacts. Particles are independent, so the loop is parallel and its
/// result the same for any thread count. Adds fail-safe particles to stats.
void wc_collide_cloth(wc_cloth *cloth, wc_collider *const *colliders, int32_t collider_count,
                      double dt, int threads, wc_step_stats *stats);

#endif
