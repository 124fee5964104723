/* Position Verlet (thesis eq. 2.4) and pinned particles. The large-step
 * integrators are in xpbd.c and implicit.c. */
#ifndef WC_INTEGRATE_H
#define WC_INTEGRATE_H

#include "cloth.h"

/// Writes the positions after a step of dt into cloth->nx/ny/nz from the
/// forces in cloth->fx/fy/fz. Pinned particles go to from + (to - from) *
/// pin_fraction. Returns the index of the first particle whose new position
/// is not finite, or -1 when all are.
int32_t wci_integrate_verlet(wc_cloth *cloth, double dt, double pin_fraction, int threads);

/// Where pin `slot` is at `fraction` of the way from its start to its
/// target (exactly the target at fraction 1).
void wci_pinned_position(const wc_cloth *cloth, int32_t slot, double fraction, double out[3]);

/// Index of the first particle with a non-finite coordinate, or -1.
int32_t wci_first_non_finite_xyz(const double *x, const double *y, const double *z, int32_t n);

#endif
