/* The wet response (thesis 2.3-2.4, SPEC 3): adhesion of particles in
 * contact, spreading of the pull to their linked neighbours, which particles
 * are stuck, and the optional wetness dynamics (wicking, drying). Wet
 * friction lives in the collision response (collide.c), where the
 * tangential velocity is known. */
#ifndef WC_WETNESS_H
#define WC_WETNESS_H

#include "cloth.h"

/// Adds the adhesion and spreading forces to cloth->fx/fy/fz, from the
/// contacts of the last step (cloth->contact and its normals). Call only
/// when cloth->wet_forces is set. Each particle gathers its own force.
void wc_wet_forces(wc_cloth *cloth, int threads);

/// After the collisions of a step: marks the stuck particles (wet, in
/// contact in this step and the one before) and returns their count.
int32_t wc_wet_mark_stuck(wc_cloth *cloth);

/// Wicking and drying over a step of dt, then the material refreshed for
/// the new wetness. Call only when the material wicks or dries.
void wc_wet_update(wc_cloth *cloth, double dt);

#endif
