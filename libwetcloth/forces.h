/* Forces on a cloth's particles (docs/model.md, Forces): tension-only stretch links with
 * damping, compression-only buckling links, gravity and air drag. */
#ifndef WC_FORCES_H
#define WC_FORCES_H

#include "cloth.h"

/// Fills cloth->fx/fy/fz with the total force on every particle, N.
/// Each link's force is computed once, then every particle sums its own
/// links in a fixed order: no two threads ever write the same value.
/// A cloth stepped by XPBD gets no stretch link forces (its stretch links
/// are constraints).
void wci_forces_compute(wc_cloth *cloth, const double gravity[3], int threads);

#endif
