/* Position Verlet (thesis eq. 2.4) and pinned particles. */
#ifndef WC_INTEGRATE_H
#define WC_INTEGRATE_H

#include "cloth.h"

/// Writes the positions after a step of dt into cloth->nx/ny/nz from the
/// forces in cloth->fx/fy/fz. Pinned particles go to from + (to - from) *
/// pin_fraction. Returns the index of the first particle whose new position
/// is not finite, or -1 when all are.
int32_t wc_integrate_verlet(wc_cloth *cloth, double dt, double pin_fraction, int threads);

#endif
