/* Semi-implicit backward Euler (WC_INTEGRATOR_IMPLICIT), after Baraff &
 * Witkin 1998 and Choi & Ko 2002: one linear solve per step,
 *   (M - h df/dv - s h^2 df/dx) dv = h (f + h df/dx v),  x+ = x + h (v + s dv),
 * s = (h + h_prev) / 2h (1 with equal steps),
 * with df/dx the stretch links' Jacobian (tension only), the bend links'
 * axial stiffness (their transverse term dropped, as Choi & Ko do, because
 * it would make the matrix indefinite) and the soft pins' goal springs,
 * df/dv the stretch dashpots and air drag (relative to the air: its
 * velocity's part of the drag is constant and enters f alone). Block-Jacobi preconditioned conjugate gradients (with coarse
 * levels on large cloths, multigrid.h), stopped at an estimated velocity
 * error of wc_world_def.implicit_tolerance times the step, matrix-free,
 * gathered per particle with fixed-order reductions: the same bits for any
 * thread count. */
#ifndef WC_IMPLICIT_H
#define WC_IMPLICIT_H

#include "cloth.h"

typedef struct wc_implicit_state wc_implicit_state;

/// Buffers for a cloth's solve. NULL when out of memory.
wc_implicit_state *wci_implicit_state_create(const wc_cloth *cloth);

void wci_implicit_state_destroy(wc_implicit_state *state);

/// Conjugate-gradient iterations of the last solve, and its residual
/// relative to the right-hand side.
int32_t wci_implicit_last_iterations(const wc_implicit_state *state);
double wci_implicit_last_residual(const wc_implicit_state *state);

/// Writes the positions after a step of dt into cloth->nx/ny/nz, x + dt (v
/// + share dv), with v the last step's chord velocity, dv from the solve
/// above (whose stiffness term takes the same share) and the forces in
/// cloth->fx/fy/fz; share = (dt + dt_prev) / (2 dt), 1/2 on a first step:
/// the velocity change acts over the same time as Verlet's acceleration,
/// which keeps free fall exact. Pinned
/// particles go where Verlet puts them. The solve stops when its estimated
/// velocity error is at most tolerance * dt (wc_world_def.implicit_tolerance,
/// m/s^2; 0: to round-off). Returns the index of the first particle whose
/// new position is not finite, or -1 when all are. cloth->implicit must exist
/// (asserted).
int32_t wci_integrate_implicit(wc_cloth *cloth, double dt, double pin_fraction, double tolerance,
                              int threads);

#endif
