/* Guard against steps above what the integrator keeps stable (
 * "with a forced step it must fail cleanly").
 *
 * An explicit step above 2 / omega of some mode makes that mode grow by a
 * factor |lambda| > 1 every step with alternating sign (both roots of
 * Verlet's characteristic equation are real and negative there: at
 * omega dt = 2.04, lambda = -1.49; at 2.2, -2.43). Left alone it runs for
 * tens of steps to ~1e150 m before a position overflows, and the "last
 * good state" a non-finite check keeps is an exploded cloth.
 *
 * The guard watches steps longer than the cloth's stable estimate (a bound:
 * shorter steps are stable), and looks for exactly that signature, cheaply:
 * after integration
 * (before collisions, which change velocities for other reasons) each
 * cloth's largest velocity change of the step, |v_new - v_old| over its
 * free particles, is compared with the last step's. It fires when that
 * change has grown by at least GROWTH per step, with the particle that had
 * the largest change last step now changing the other way, for long enough
 * in a row (step_guard.c: the faster, the fewer steps), and now moves a
 * particle by at least FLOOR mean link lengths per step. Real
 * motion at a stable step does not do that: forces that build up (a cloth
 * catching on its pins, a fast plate striking it) grow without
 * alternating, a stiff link ringing at a stable step alternates without
 * growing, and rounding noise stays under the floor. Then the step fails
 * with WC_ERROR_NON_FINITE, naming the particle and the stable estimate,
 * and the world keeps the state before it, while the oscillation is still
 * a fraction of a link long. */
#ifndef WC_STEP_GUARD_H
#define WC_STEP_GUARD_H

#include <stdint.h>

struct wc_cloth;

/// What the guard keeps per cloth between steps; all zero: no history.
typedef struct wc_step_guard {
    /// Largest velocity change of the last step as an acceleration, m/s^2
    /// (0: none), its particle and its change of velocity (xyz, m/s).
    double change;
    int32_t particle;
    double dv[3];
    /// Steps in a row that grew and alternated, and the growth over them.
    int32_t run;
    double growth;
    /// Mean rest length of the stretch links, m (0 until first needed).
    double scale;
} wc_step_guard;

/// Looks at the step from (x, y, z) to (nx, ny, nz) of length dt; writes
/// what the guard would keep if the step is committed to *next. Returns
/// the particle whose growing oscillation makes the step unstable, or -1.
int32_t wci_step_guard_check(const struct wc_cloth *cloth, const wc_step_guard *guard, double dt,
                            int threads, wc_step_guard *next);

/* Tearing. A large step can also go wrong without growing oscillations: a
 * contact answered from a configuration the step's length made ambiguous
 * (a cloth triangle crushed to a sliver between a bending dense tube's
 * facets, whose normal turns over within the step) pushes the cloth a
 * contact distance the wrong way, and the links it stretches feed the next
 * steps until the cloth tears (the bending 14,784-vertex tube at 12 implicit
 * steps per frame: a link from 1.015 to 1.86 times its rest length in one
 * step, 3.5 the next, 24 two steps later). The same scene at 24 steps per
 * frame holds within 1.03. So a step whose collisions stretch a stretch
 * link past WC_TEAR_RATIO times its rest length, by more than
 * WC_TEAR_GROWTH times it in that one step, is taken again as two half
 * steps (world.c), down to WC_TEAR_HALVINGS halvings; what still tears then
 * is kept. On the tube that takes 5 steps again in 24 frames (the first: a
 * link from 1.002 to 1.69) and the cloth holds within 1.08. Stretch that
 * builds over several steps is not this (the soaked 2 m cloth landing on
 * the dense sphere stretches links to about 1.6 over several steps). The
 * same jump happens, once, to the add-on's 17 x 17 drape resting on the
 * thesis sphere (frame 20: a link from 1.03 to 1.54 in one step); a
 * quarter instead of a half as the growth took two of its steps again. */
#define WC_TEAR_RATIO 1.5
#define WC_TEAR_GROWTH 0.5
#define WC_TEAR_HALVINGS 3

/// The first stretch link of the cloth that the step from (x, y, z) to
/// (nx, ny, nz) stretches past `ratio` times its rest length, by more than
/// `growth` times it (WC_TEAR_RATIO and WC_TEAR_GROWTH: it tears), or -1;
/// the links looked at on up to `threads` threads.
int32_t wci_step_tears(const struct wc_cloth *cloth, double ratio, double growth, int threads);

#endif
