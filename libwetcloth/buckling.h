/* Choi & Ko's buckling (compression) force, thesis eq. 2.2-2.3.
 *
 * A compressed bend link of rest length l and current length d < l is taken as
 * a circular arc of length l with chord d. Its half angle theta solves
 * sinc(theta) = d / l, and it stores the bending energy
 *     U = 0.5 * R * c^2 * l = 2 R theta^2 / l        (c = 2 theta / l).
 * The force is -dU/dd, which pushes the ends apart with magnitude
 *     |f| = (R / l^2) * Phi(theta),  Phi = 4 theta^2 / (sinc theta - cos theta),
 * the same as the thesis' R c^2 / (cos theta - sinc theta) up to its sign.
 * Phi runs from 12 at onset (d -> l) to 4 pi^2 at full fold (d = 0).
 */
#ifndef WC_BUCKLING_H
#define WC_BUCKLING_H

/// theta in [0, pi] with 1 - sin(theta)/theta = gap, for gap in [0, 1].
/// Taking the gap 1 - r rather than r keeps full precision near onset, where
/// theta ~ sqrt(6 gap) and 1 - r would lose digits.
double wc_inverse_sinc_gap(double gap);

/// theta in [0, pi] with sin(theta)/theta = r, for r in [0, 1].
double wc_inverse_sinc(double r);

/// Normalised force Phi(theta) = 4 theta^2 / (sinc theta - cos theta).
double wc_buckling_phi(double theta);

/// Force magnitude pushing the ends apart, N, for chord d and rest length l
/// (m) and link constant R (N m^2). Zero for d >= l.
double wc_buckling_force(double d, double l, double R);

/// Stored energy, J: 2 R theta^2 / l for d < l, zero otherwise.
double wc_buckling_energy(double d, double l, double R);

/// Upper bound of |d Phi / d r| over 0 <= r < 1 (r = d / l): 12 pi^2, reached
/// at full fold. So |df/dd| <= WC_BUCKLING_STIFFNESS_BOUND * R / l^3, which the
/// stable step estimate uses.
#define WC_BUCKLING_STIFFNESS_BOUND 118.43525281307230

#endif
