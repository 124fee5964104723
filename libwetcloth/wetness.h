/* The wet response (thesis 2.3-2.4, SPEC 3): adhesion of particles in
 * contact, spreading of the pull to their linked neighbours, which particles
 * are stuck, and the optional wetness dynamics (wicking, drying). Wet
 * friction lives in the collision response (collide.c), where the
 * tangential velocity is known. */
#ifndef WC_WETNESS_H
#define WC_WETNESS_H

#include "cloth.h"
#include "collider.h"

/// How far past its contact distance r a wet particle that touched a
/// collider in the last step may be and still count as touching it, as a
/// fraction of r (see wc_wet_hold_contacts).
#define WC_WET_HOLD_BAND 0.1

/// Adds the adhesion and spreading forces to cloth->fx/fy/fz, from the
/// contacts of the last step (cloth->contact and its normals). Call only
/// when cloth->wet_forces is set. Each particle gathers its own force.
void wc_wet_forces(wc_cloth *cloth, int threads);

/// After the collider passes of a step, before self-collision: a wet
/// particle that touched a collider in the last step, is not in contact now,
/// but lies within (1 + WC_WET_HOLD_BAND) r of a collider, keeps its contact
/// (kind and the normal from the nearest surface point), unmoved. Call only
/// when cloth->wet_forces is set. Each particle writes only its own entries.
void wc_wet_hold_contacts(wc_cloth *cloth, wc_collider *const *colliders, int32_t count,
                          int threads);

/// After the collisions of a step: marks the stuck particles (wet, in
/// contact in this step and the one before) and returns their count.
int32_t wc_wet_mark_stuck(wc_cloth *cloth);

/// Wicking and drying over a step of dt, then the material refreshed for
/// the new wetness. Call only when the material wicks or dries.
void wc_wet_update(wc_cloth *cloth, double dt);

#endif
