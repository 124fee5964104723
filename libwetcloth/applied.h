/* Forces applied to a cloth from outside it: the velocity of the air, which
 * makes the drag relative to the air instead of to the world, an external
 * force field, and the goal springs of soft pins (docs/model.md, "Applied
 * forces"). The application sets each of them, they are held until it sets
 * them again, and a cloth without any pays nothing: no memory, no pass. */
#ifndef WC_APPLIED_H
#define WC_APPLIED_H

#include "cloth.h"

/// Whether an applied force can act on the cloth: air velocity with a
/// material that has drag, an external force field, or a soft pin.
int wci_applied_active(const wc_cloth *cloth);

/// Adds the applied forces to cloth->fx/fy/fz (after wci_forces_compute),
/// per particle, so the result is the same for any thread count:
///  * air_drag A_i u_i, the constant part of the drag relative to the air,
///    -air_drag A_i (v_i - u_i) (forces.c adds its -air_drag A_i v_i);
///  * the external force, A_i p_i;
///  * a soft pin's goal spring, -m_i s (x_i - T), with s the pin's stiffness
///    (1/s^2) and T its target at `target_fraction` of the way through the
///    advance (wci_pinned_position): the step's start for the explicit
///    integrators, its end for the implicit one, which evaluates forces
///    there (backward Euler).
/// Hard-pinned particles get none: they feel no forces.
void wci_applied_forces_add(wc_cloth *cloth, double target_fraction, int threads);

#endif
