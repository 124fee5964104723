/* Strain-limited stretch (WC_INTEGRATOR_XPBD): stretch links as tension-only
 * constraints solved by compliant projection (XPBD, Macklin et al. 2016),
 * one iteration per step, with the world's steps as the small substeps of
 * Macklin et al. 2019 ("Small Steps in Physics Simulation"). */
#ifndef WC_XPBD_H
#define WC_XPBD_H

#include "cloth.h"

/// Stretch links grouped by colour: no two links of one colour share a
/// particle, so a colour's projections can run in parallel and still give
/// the same result as a serial Gauss-Seidel sweep.
typedef struct wc_xpbd_state wc_xpbd_state;

/// Colours the cloth's stretch links. NULL when out of memory.
wc_xpbd_state *wci_xpbd_state_create(const wc_cloth *cloth);

void wci_xpbd_state_destroy(wc_xpbd_state *state);

/// Number of colours (the last one may be a serial remainder).
int32_t wci_xpbd_color_count(const wc_xpbd_state *state);

/// Writes the positions after a step of dt into cloth->nx/ny/nz: the
/// Verlet prediction from cloth->fx/fy/fz (which hold every force but the
/// stretch links'), then the backward-Euler dashpot of every stretch link
/// slack at the prediction, then a Gauss-Seidel sweep of compliant
/// projections over the taut ones. Pinned particles are placed as in Verlet
/// and never moved by a projection.
/// Returns the index of the first particle whose new position is not
/// finite, or -1 when all are. cloth->xpbd must exist (asserted).
int32_t wci_integrate_xpbd(wc_cloth *cloth, double dt, double pin_fraction, int threads);

#endif
