#include "buckling.h"

#include <math.h>

#define WC_PI 3.14159265358979323846

/* Below this theta, 1 - sinc and sinc - cos are summed from their Taylor
 * series: the direct formulas lose about -2*log10(theta) digits to
 * cancellation. At theta = 1 the series' 10th term is below 1e-19 of the sum. */
#define SERIES_LIMIT 1.0

/* Taylor coefficients in t2 = theta^2, k = 1..10:
 *   1 - sinc(theta)         = t2 * sum_k (-1)^(k+1) t2^(k-1) / (2k+1)!
 *   (sinc - cos) / theta^2  =      sum_k (-1)^(k+1) 2k t2^(k-1) / (2k+1)!
 * For theta < 1 the first omitted term is below 2e-18 of either sum. */
static const double GAP_SERIES[10] = {
    1.0 / 6.0, -1.0 / 120.0, 1.0 / 5040.0, -1.0 / 362880.0, 1.0 / 39916800.0,
    -1.0 / 6227020800.0, 1.0 / 1307674368000.0, -1.0 / 355687428096000.0,
    1.0 / 121645100408832000.0, -1.0 / 51090942171709440000.0};
static const double Q_SERIES[10] = {
    2.0 / 6.0, -4.0 / 120.0, 6.0 / 5040.0, -8.0 / 362880.0, 10.0 / 39916800.0,
    -12.0 / 6227020800.0, 14.0 / 1307674368000.0, -16.0 / 355687428096000.0,
    18.0 / 121645100408832000.0, -20.0 / 51090942171709440000.0};

/* Both quantities Halley's method and the force need, from one sin/cos:
 *   gap_of = 1 - sinc(theta)
 *   q      = (sinc - cos) / theta^2, finite and positive on [0, pi]:
 *            1/3 at 0, 1/pi^2 at pi. */
static void sinc_terms(double theta, double *gap_of, double *q)
{
    if (theta >= SERIES_LIMIT) {
        double sinc = sin(theta) / theta;
        *gap_of = 1.0 - sinc;
        *q = (sinc - cos(theta)) / (theta * theta);
        return;
    }
    double t2 = theta * theta, g = GAP_SERIES[9], s = Q_SERIES[9];
    for (int k = 8; k >= 0; --k) {
        g = g * t2 + GAP_SERIES[k];
        s = s * t2 + Q_SERIES[k];
    }
    *gap_of = g * t2;
    *q = s;
}

/* theta(gap) / sqrt(gap) is analytic on [0, 1]; this degree-5 least-squares
 * fit (Chebyshev nodes, computed with mpmath) is within 3.3e-4 relative of
 * it everywhere, so two Halley steps reach rounding. */
static double initial_guess(double gap)
{
    static const double c[6] = {2.448993035045876, 0.38702525104788593,
                                -0.03587925013993268, 0.6736673741267878,
                                -0.8479676856255313, 0.5147357496899982};
    double p = c[5];
    for (int i = 4; i >= 0; --i) p = p * gap + c[i];
    return p * sqrt(gap);
}

double wci_inverse_sinc_gap(double gap)
{
    if (!(gap > 0.0)) return 0.0; /* also maps NaN to 0: never propagate it */
    if (gap >= 1.0) return WC_PI;
    double theta = initial_guess(gap);
    /* Halley's method on h(theta) = (1 - sinc theta) - gap:
     *   h'  = theta * q,    q = (sinc - cos) / theta^2
     *   h'' = sinc - 2 q
     *   step = (h / h') / (1 - (h / h') h'' / (2 h'))
     * written with the ratio h / h' first, since h and h' can both be tiny
     * (gap = 1e-300 gives theta ~ 1e-150, and h * h' would underflow).
     * Convergence is cubic, the error after a step about (step)^3: once a
     * step is below 1e-7 of theta, what is left is far below rounding, so
     * the loop stops there. From the initial guess that takes two passes. */
    for (int iter = 0; iter < 8; ++iter) {
        double gap_of, q;
        sinc_terms(theta, &gap_of, &q);
        double h1 = theta * q;
        double h2 = (1.0 - gap_of) - 2.0 * q;
        double ratio = (gap_of - gap) / h1;
        double step = ratio / (1.0 - 0.5 * ratio * h2 / h1);
        double next = theta - step;
        if (next < 0.0) next = 0.5 * theta;
        if (next > WC_PI) next = 0.5 * (theta + WC_PI);
        int done = fabs(next - theta) <= 1e-7 * next;
        theta = next;
        if (done) break;
    }
    return theta;
}

double wci_inverse_sinc(double r)
{
    return wci_inverse_sinc_gap(1.0 - r);
}

double wci_buckling_phi(double theta)
{
    double gap_of, q;
    sinc_terms(theta, &gap_of, &q);
    return 4.0 / q;
}

double wci_buckling_energy(double d, double l, double R)
{
    if (!(d < l)) return 0.0;
    double theta = wci_inverse_sinc_gap((l - d) / l);
    return 2.0 * R * theta * theta / l;
}

double wci_buckling_energy_ramped(double d, double l, double R)
{
    if (!(d < l)) return 0.0;
    double gap = (l - d) / l, ramp = WC_BUCKLING_ONSET_RAMP;
    /* the ramp's energy up to the given gap: F_end / 2 * gap^2 / ramp * l */
    double f_end = R / (l * l) * wc_buckling_phi_of_gap(ramp);
    if (gap < ramp) return 0.5 * f_end * gap * gap / ramp * l;
    double ramp_energy = 0.5 * f_end * ramp * l;
    return ramp_energy + wci_buckling_energy(d, l, R) - wci_buckling_energy((1.0 - ramp) * l, l, R);
}
