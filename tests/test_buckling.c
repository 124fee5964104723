/* Choi & Ko buckling model (libwetcloth/buckling.h; docs/model.md, Forces):
 *  - inverse sinc against 50+-digit mpmath references, to a few ulps of theta;
 *  - a dense residual sweep against an independent long double evaluation;
 *  - the force: onset and full-fold limits, references at interior points,
 *    continuity within the derivative bound, monotonicity, finiteness, zero
 *    in tension, and force = -dU/dd by central differences;
 *  - WC_BUCKLING_STIFFNESS_BOUND = 12 pi^2 bounds the sampled |dPhi/dr| and
 *    is reached (so the stable step estimate is neither unsafe nor loose).
 *
 * The references below were computed with this mpmath (1.3) script, at 700
 * significant digits so that 1 - sinc(theta) keeps full precision even for
 * gap = 1e-15, and printed with repr(float(...)) (correctly rounded):
 *
 *     import mpmath as mp
 *     mp.mp.dps = 700
 *     def theta_gap(gap):                        # 1 - sin(t)/t = gap
 *         gap = mp.mpf(gap)                      # the double's exact value
 *         f = lambda t: 1 - mp.sin(t) / t - gap
 *         lo, hi = mp.sqrt(gap), mp.pi           # bracket, then bisect
 *         for _ in range(200):
 *             mid = (lo + hi) / 2
 *             lo, hi = (mid, hi) if f(mid) < 0 else (lo, mid)
 *         return mp.findroot(f, (lo + hi) / 2)
 *     phi = lambda t: 4 * t**2 / (mp.sin(t) / t - mp.cos(t))
 *     # r given as a double: gap = 1 - mp.mpf(r), exact
 */
#include <float.h>
#include <math.h>

#include "buckling.h"
#include "test_util.h"

static const double PI = 3.14159265358979323846;

/* Distance in units in the last place of the reference. */
static double ulps(double value, double reference)
{
    if (value == reference) return 0.0;
    double ulp = nextafter(fabs(reference), INFINITY) - fabs(reference);
    if (reference == 0.0) ulp = DBL_MIN;
    return fabs(value - reference) / ulp;
}

/* ------------------------------------------------------------------------ */
/* Inverse sinc against mpmath                                               */
/* ------------------------------------------------------------------------ */

/* Tolerance for theta. theta is found from 1 - sinc(theta) = gap evaluated in
 * double: a relative rounding of a few eps in that evaluation moves theta by
 * about half as much near onset (gap ~ theta^2 / 6) and by at most a few ulps
 * elsewhere (|d theta / d gap| <= pi, d theta / d gap ~ 3/theta near 0 with
 * gap ~ theta^2/6). So 4 ulps is "rounding-limited"; any approximation
 * (e.g. a fitted curve, or stopping Halley early) misses it by many orders. */
#define THETA_ULPS 4.0

static void test_inverse_sinc_references(void)
{
    /* The five points the model asks for (r = 1-1e-15, 1-1e-8, 0.5, 1e-9, 0), as doubles r. Near r = 1 the problem
     * is ill-conditioned in r (d theta / d r ~ -3 / theta), but 1 - r is
     * exact for these doubles (Sterbenz), so the reference is theta for the
     * exact value of the double r, and wci_inverse_sinc must hit it. */
    static const struct {
        double r, theta;
    } pts[] = {
        {1 - 1e-15, 7.742870483855356e-08},  /* exact gap 9.992007221626409e-16 */
        {1 - 1e-8, 0.0002449489752611461},   /* exact gap 1.0000000050247593e-08 */
        {0.5, 1.895494267033981},
        {1e-9, 3.141592650448201},           /* theta for r = 1e-9 exactly */
        {0.0, 3.141592653589793},            /* pi */
    };
    for (size_t i = 0; i < sizeof pts / sizeof pts[0]; ++i) {
        double t = wci_inverse_sinc(pts[i].r);
        double e = ulps(t, pts[i].theta);
        printf("inverse_sinc(r=%.17g) = %.17g, reference %.17g, error %.2f ulp\n", pts[i].r, t,
               pts[i].theta, e);
        CHECK(e <= THETA_ULPS, "inverse_sinc(%.17g) = %.17g, expected %.17g (%.1f ulp)", pts[i].r,
              t, pts[i].theta, e);
    }

    /* Gap form, including gaps that are not 1 - (a double). */
    static const struct {
        double gap, theta;
    } gaps[] = {
        {1e-15, 7.745966692414835e-08},
        {1e-8, 0.00024494897464574127},
        {0.25, 1.2756981092811261},
        {0.5, 1.895494267033981},
        {0.9, 2.852341894450092},
        {0.999, 3.1384541942432866},
        {0.999999999, 3.141592650448201},
        {1.0, 3.141592653589793},
        /* where a single Halley step from the initial fit lands: */
        {0.853, 2.728833274409208},
        {0.973, 3.0589079551055107},
    };
    for (size_t i = 0; i < sizeof gaps / sizeof gaps[0]; ++i) {
        double t = wci_inverse_sinc_gap(gaps[i].gap);
        double e = ulps(t, gaps[i].theta);
        printf("inverse_sinc_gap(%.17g) = %.17g, error %.2f ulp\n", gaps[i].gap, t, e);
        CHECK(e <= THETA_ULPS, "inverse_sinc_gap(%.17g) = %.17g, expected %.17g (%.1f ulp)",
              gaps[i].gap, t, gaps[i].theta, e);
    }

    /* Tiny gaps: theta = sqrt(6 gap) (1 + 3 gap / 20 + ...), so for
     * gap <= 1e-30 theta = sqrt(6 gap) to far below rounding. */
    double tiny[] = {1e-30, 1e-100, 1e-300};
    for (int i = 0; i < 3; ++i) {
        double expect = (double)sqrtl(6.0L * (long double)tiny[i]);
        double t = wci_inverse_sinc_gap(tiny[i]);
        double e = ulps(t, expect);
        printf("inverse_sinc_gap(%g) = %.17g, sqrt(6 gap) = %.17g, error %.2f ulp\n", tiny[i], t,
               expect, e);
        CHECK(e <= THETA_ULPS, "inverse_sinc_gap(%g) = %.17g, expected %.17g", tiny[i], t, expect);
    }
    CHECK(wci_inverse_sinc_gap(0.0) == 0.0, "theta(gap 0) = %g", wci_inverse_sinc_gap(0.0));
    CHECK(wci_inverse_sinc(1.0) == 0.0, "theta(r = 1) = %g", wci_inverse_sinc(1.0));
}

/* ------------------------------------------------------------------------ */
/* Dense residual sweep                                                      */
/* ------------------------------------------------------------------------ */

/* 1 - sinc(t) and its derivative d/dt, in long double (64-bit mantissa on
 * x86-64), independent of the library's code: a plain Taylor sum below 1,
 * the direct formula above (no cancellation there: 1 - sinc >= 0.15). */
static long double gap_of_theta(long double t, long double *slope)
{
    if (t < 1.0L) {
        long double t2 = t * t, term = t2 / 6.0L, sum = 0.0L, dsum = 0.0L;
        for (int k = 1; k < 30; ++k) {
            sum += term;
            dsum += term * (2.0L * k) / t;
            term *= -t2 / ((2.0L * k + 2.0L) * (2.0L * k + 3.0L));
        }
        *slope = dsum;
        return sum;
    }
    long double s = sinl(t), c = cosl(t);
    *slope = (s / t - c) / t;
    return 1.0L - s / t;
}

static void test_inverse_sinc_sweep(void)
{
    /* The residual of theta is consistent with theta being within a few ulps
     * of the true root when |gap_of(theta) - gap| <= slope * ulps(theta) plus
     * the rounding of gap itself. Sweep r uniformly (200001 points) and the
     * gap logarithmically from 1e-300 to 1 (3001 points). */
    int bad = 0, count = 0;
    double worst = 0.0;
    for (int pass = 0; pass < 2; ++pass) {
        int n = pass == 0 ? 200000 : 3000;
        for (int k = 0; k <= n; ++k) {
            double gap = pass == 0 ? (double)k / n : pow(10.0, -300.0 + 300.0 * k / n);
            double t = wci_inverse_sinc_gap(gap);
            ++count;
            if (!(t >= 0.0 && t <= PI)) {
                if (bad++ < 5) CHECK(0, "theta(%.17g) = %.17g outside [0, pi]", gap, t);
                continue;
            }
            if (gap == 0.0) {
                CHECK(t == 0.0, "theta(0) = %g", t);
                continue;
            }
            /* gap_of(theta) - gap ~ slope * (theta - root); the long double
             * evaluation itself is good to ~1e-19 relative. */
            long double slope;
            long double g = gap_of_theta((long double)t, &slope);
            double ulp = nextafter(t, INFINITY) - t;
            long double allowed = slope * THETA_ULPS * ulp + 64.0L * LDBL_EPSILON * gap;
            long double res = fabsl(g - gap);
            double ratio = allowed > 0 ? (double)(res / allowed) : (res > 0 ? INFINITY : 0.0);
            if (ratio > worst) worst = ratio;
            if (!(res <= allowed) && bad++ < 5)
                CHECK(0, "gap %.17g: theta %.17g has residual %Lg > %Lg", gap, t, res, allowed);
        }
    }
    printf("inverse sinc sweep: %d points, worst residual %.3f of the %g-ulp allowance\n", count,
           worst, THETA_ULPS);
    CHECK(bad == 0, "%d sweep points failed", bad);
}

/* ------------------------------------------------------------------------ */
/* Force                                                                     */
/* ------------------------------------------------------------------------ */

static void test_force_limits_and_references(void)
{
    /* Several link scales: the force must be (R / l^2) Phi(d / l). */
    static const double scales[][2] = {{1.0, 1.0}, {0.02, 3e-7}, {1e-3, 1e-12}, {50.0, 4.0}};
    for (int s = 0; s < 4; ++s) {
        double l = scales[s][0], R = scales[s][1], unit = R / (l * l);

        /* Full fold, d = 0: 4 pi^2 R / l^2. Only rounding of Phi and of the
         * few operations that scale it: 8 ulps. */
        double f0 = wc_buckling_force(0.0, l, R);
        double fold = 4.0 * PI * PI * unit;
        printf("l=%g R=%g: F(0) / (R/l^2) = %.17g (4 pi^2 = %.17g)\n", l, R, f0 / unit,
               4.0 * PI * PI);
        CHECK(isfinite(f0) && ulps(f0, fold) <= 8.0, "F(d=0) = %.17g, expected %.17g", f0, fold);
        /* d = a denormal-small fraction of l: still the full-fold value
         * (Phi(r) = 4 pi^2 - 12 pi^2 r + ..., so r = 1e-300 changes nothing). */
        double ftiny = wc_buckling_force(1e-300 * l, l, R);
        CHECK(isfinite(ftiny) && ulps(ftiny, fold) <= 8.0, "F(1e-300 l) = %.17g", ftiny);

        /* Onset: Phi = 12 + 7.2 gap + O(gap^2) (series of 4 t^2/(sinc - cos)
         * with gap = t^2/6 - ...), so at the largest double below l the
         * force is 12 R/l^2 within rounding. */
        double below = nextafter(l, 0.0);
        double fon = wc_buckling_force(below, l, R);
        double onset = 12.0 * unit;
        printf("l=%g R=%g: F(l^-) / (R/l^2) = %.17g (12)\n", l, R, fon / unit);
        CHECK(isfinite(fon) && fabs(fon - onset) <= 8.0 * DBL_EPSILON * onset,
              "F(l^-) = %.17g, expected %.17g", fon, onset);
        for (double gap = 1e-14; gap < 1e-3; gap *= 10.0) {
            double f = wc_buckling_force(l * (1.0 - gap), l, R);
            double expect = (12.0 + 7.2 * gap) * unit;
            /* remainder O(gap^2) below 10 gap^2 for gap < 1e-3, plus rounding
             * of d = l (1 - gap), which moves the gap by eps */
            CHECK(fabs(f - expect) <= (10.0 * gap * gap + 16.0 * DBL_EPSILON) * onset,
                  "F at gap %g = %.17g, expected %.17g", gap, f, expect);
        }

        /* In tension or at rest length: exactly zero. */
        CHECK(wc_buckling_force(l, l, R) == 0.0, "F(l) = %g", wc_buckling_force(l, l, R));
        CHECK(wc_buckling_force(1.5 * l, l, R) == 0.0, "F(1.5 l) = %g",
              wc_buckling_force(1.5 * l, l, R));
        CHECK(wc_buckling_force(nextafter(l, INFINITY), l, R) == 0.0, "F(l^+) nonzero");
        CHECK(wci_buckling_energy(l, l, R) == 0.0 && wci_buckling_energy(2.0 * l, l, R) == 0.0,
              "energy nonzero in tension");
        /* Energy at full fold: 2 R pi^2 / l. */
        double e0 = wci_buckling_energy(0.0, l, R);
        CHECK(ulps(e0, 2.0 * R * PI * PI / l) <= 8.0, "U(0) = %.17g, expected %.17g", e0,
              2.0 * R * PI * PI / l);

        /* Interior references, Phi from mpmath (see the top of the file).
         * Tolerance 1e-14 relative: theta is good to a few ulps and Phi's
         * relative condition number in theta is below 3 at these points, so
         * rounding alone gives ~1e-15; 1e-14 still leaves room for a
         * tabulated Phi (tools/gen_buckling_table.py fits to ~1e-16) and is
         * eleven orders tighter than Blender's quartic fit (error 0.15). */
        static const struct {
            double gap, phi;
        } ref[] = {
            {0.25, 14.177051787626816}, {0.5, 17.547251317025058},
            {0.9, 30.746067989336467},  {0.999, 39.36041235353601},
            {1e-8, 12.000000072},       {1e-15, 12.000000000000007},
        };
        for (size_t i = 0; i < sizeof ref / sizeof ref[0]; ++i) {
            /* d = l (1 - gap) moves the gap by about eps; |dPhi/dgap| < 12 pi^2
             * turns that into < 1e-14 * Phi. */
            double f = wc_buckling_force(l * (1.0 - ref[i].gap), l, R) / unit;
            double rel = fabs(f - ref[i].phi) / ref[i].phi;
            CHECK(rel <= 1e-14, "l=%g: Phi at gap %g = %.17g, expected %.17g (rel %.2e)", l,
                  ref[i].gap, f, ref[i].phi, rel);
            if (s == 0) printf("Phi(gap=%g) = %.17g, mpmath %.17g, rel error %.2e\n", ref[i].gap, f,
                               ref[i].phi, rel);
        }
        /* wci_buckling_phi itself, at theta from the same table. */
        CHECK(fabs(wci_buckling_phi(1.895494267033981) - 17.547251317025058) <= 1e-14 * 17.55,
              "Phi(theta(0.5)) = %.17g", wci_buckling_phi(1.895494267033981));
        CHECK(fabs(wci_buckling_phi(0.0) - 12.0) <= 1e-15 * 12.0, "Phi(0) = %.17g",
              wci_buckling_phi(0.0));
        CHECK(fabs(wci_buckling_phi(PI) - 4.0 * PI * PI) <= 1e-14 * 40.0, "Phi(pi) = %.17g",
              wci_buckling_phi(PI));
    }
}

/* Continuity, monotonicity, finiteness and the derivative bound over a fine
 * sweep of d in [0, l]. */
static void test_force_sweep(void)
{
    /* Independent value of the bound: 12 pi^2, dPhi/dr at r = 0. */
    long double pil = 3.141592653589793238462643383279502884L;
    double bound12 = (double)(12.0L * pil * pil);
    printf("WC_BUCKLING_STIFFNESS_BOUND = %.17g, 12 pi^2 = %.17g\n", WC_BUCKLING_STIFFNESS_BOUND,
           bound12);
    CHECK(ulps(WC_BUCKLING_STIFFNESS_BOUND, bound12) <= 1.0, "bound %.17g != 12 pi^2 %.17g",
          WC_BUCKLING_STIFFNESS_BOUND, bound12);

    const double l = 0.7, R = 2e-3, unit = R / (l * l);
    const int n = 200000;
    const double h = l / n;
    int bad_finite = 0, bad_mono = 0, bad_jump = 0;
    double max_slope = 0.0, prev = wc_buckling_force(0.0, l, R);
    for (int k = 1; k <= n; ++k) {
        double d = k == n ? l : l * ((double)k / n);
        double f = wc_buckling_force(d, l, R);
        if (!isfinite(f) || f < 0.0) {
            if (bad_finite++ < 5) CHECK(0, "F(%.17g) = %g", d, f);
            prev = f;
            continue;
        }
        if (k == n) {
            CHECK(f == 0.0, "F(l) = %g", f);
            break;
        }
        /* Monotonic: Phi' <= -7.2 in r everywhere (minimum slope at onset),
         * so neighbouring samples differ by at least 7.2 * R/l^3 * h, which
         * is ~1e-5 of F: far above rounding. Strict decrease required. */
        if (!(f < prev) && bad_mono++ < 5)
            CHECK(0, "not decreasing: F(%.17g) = %.17g >= F(previous) = %.17g", d, f, prev);
        /* Continuity: the jump between samples h apart is at most
         * BOUND * R/l^3 * h (mean value theorem), plus rounding of F
         * (8 eps F) and of d (eps l -> BOUND * eps * R / l^2). */
        double slope = (prev - f) / (h * unit / l);
        if (slope > max_slope) max_slope = slope;
        double allowed = WC_BUCKLING_STIFFNESS_BOUND * R / (l * l * l) * h +
                         (8.0 + WC_BUCKLING_STIFFNESS_BOUND) * DBL_EPSILON * 40.0 * unit;
        if (!(fabs(prev - f) <= allowed) && bad_jump++ < 5)
            CHECK(0, "jump at d=%.17g: |%.17g - %.17g| > %.3g", d, f, prev, allowed);
        prev = f;
    }
    printf("force sweep: %d samples, max sampled |dPhi/dr| = %.10f (bound %.10f)\n", n, max_slope,
           WC_BUCKLING_STIFFNESS_BOUND);
    CHECK(bad_finite == 0 && bad_mono == 0 && bad_jump == 0, "%d non-finite, %d non-monotonic, %d jumps",
          bad_finite, bad_mono, bad_jump);
    /* The bound is tight: the steepest sampled secant (at r in [0, 1/n]) is
     * 12 pi^2 - O(1/n); within 1e-3 means the estimate is not loose. */
    CHECK(max_slope <= WC_BUCKLING_STIFFNESS_BOUND * (1.0 + 1e-9) &&
              max_slope >= WC_BUCKLING_STIFFNESS_BOUND * (1.0 - 1e-3),
          "max slope %.10f vs bound %.10f", max_slope, WC_BUCKLING_STIFFNESS_BOUND);
}

/* The force is minus the derivative of the energy: F = -dU/dd. Central
 * differences with step h: truncation h^2 |F''| / 6, rounding ~ 4 eps U / h. */
static void test_force_is_energy_gradient(void)
{
    const double l = 0.3, R = 5e-4, unit = R / (l * l);
    const double h = 1e-5 * l;
    /* |F''| = |Phi''(r)| R / l^4. Estimate max |Phi''| from second
     * differences of the force on the same grid, then bound the truncation. */
    const int n = 2000;
    double max_phi2 = 0.0;
    for (int k = 2; k < n - 1; ++k) {
        double r = (double)k / n, dr = 1.0 / n;
        double p2 = (wc_buckling_force((r + dr) * l, l, R) - 2.0 * wc_buckling_force(r * l, l, R) +
                     wc_buckling_force((r - dr) * l, l, R)) /
                    (dr * dr * unit);
        if (fabs(p2) > max_phi2) max_phi2 = fabs(p2);
    }
    /* relative to the smallest force 12 R/l^2; factor 2 on Phi'' for the
     * sampling of its maximum */
    double trunc = (h / l) * (h / l) * 2.0 * max_phi2 / 6.0 / 12.0;
    double round = 4.0 * DBL_EPSILON * (2.0 * PI * PI) / (2.0 * (h / l)) / 12.0;
    double tol = trunc + round;
    double worst = 0.0;
    int bad = 0;
    for (int k = 1; k < n; ++k) {
        double d = l * ((double)k / n);
        if (d - h < 0.0 || d + h > l) continue;
        double fd = -(wci_buckling_energy(d + h, l, R) - wci_buckling_energy(d - h, l, R)) / (2.0 * h);
        double f = wc_buckling_force(d, l, R);
        double rel = fabs(fd - f) / (12.0 * unit);
        if (rel > worst) worst = rel;
        if (!(rel <= tol) && bad++ < 5)
            CHECK(0, "d/l=%g: F=%.17g, -dU/dd=%.17g (rel %.2e > %.2e)", d / l, f, fd, rel, tol);
    }
    printf("F vs -dU/dd: max |Phi''| ~ %.1f, worst rel diff %.2e (tolerance %.2e)\n", max_phi2,
           worst, tol);
    CHECK(bad == 0, "%d points where F != -dU/dd", bad);
}

/* The force comes from a piecewise polynomial table (buckling.h); it must
 * agree with the exact path Phi(inverse_sinc_gap(gap)) everywhere, across
 * piece boundaries included. Tolerance 1e-14 relative: the exact path is
 * good to a few ulps of theta (Phi's relative condition number in theta is
 * at most ~2 on [0, pi]), and the table is generated to ~1e-16, so a few
 * 1e-15 is the expected worst case; a piece with a wrong coefficient or an
 * off-by-one piece index is off by far more. */
static void test_force_matches_exact_path(void)
{
    const int n = 100000;
    double worst = 0.0, worst_gap = 0.0;
    int bad = 0;
    for (int k = 1; k <= n + 64; ++k) {
        /* uniform samples, then both sides of every boundary j / 32 */
        double gap = (double)k / n;
        if (k > n) {
            int j = (k - n + 1) / 2;
            gap = nextafter((double)j / 32.0, (k - n) % 2 ? 0.0 : 2.0);
        }
        if (gap > 1.0) gap = 1.0;
        double exact = wci_buckling_phi(wci_inverse_sinc_gap(gap));
        double f = wc_buckling_force(1.0 - gap, 1.0, 1.0);
        double rel = fabs(f - exact) / exact;
        if (rel > worst) worst = rel, worst_gap = gap;
        if (!(rel <= 1e-14) && bad++ < 5)
            CHECK(0, "gap %.17g: force %.17g, exact path %.17g (rel %.2e)", gap, f, exact, rel);
    }
    printf("table vs exact Phi: worst rel difference %.2e at gap %.6f\n", worst, worst_gap);
    CHECK(bad == 0, "%d points differ", bad);
}

/* The force as the simulation applies it (WC_BUCKLING_ONSET_RAMP): zero at
 * and beyond the rest length; linear in the compression up to a gap of
 * 1e-3, where it meets the exact force continuously; exactly the Choi-Ko
 * force beyond; minus the gradient of wci_buckling_energy_ramped; its slope
 * within WC_BUCKLING_STIFFNESS_BOUND_RAMPED R / l^3. */
static void test_ramped_force(void)
{
    const double l = 0.04, R = 3e-7, ramp = WC_BUCKLING_ONSET_RAMP;
    CHECK(wc_buckling_force_ramped(l, l, R) == 0.0 && wc_buckling_force_ramped(1.1 * l, l, R) == 0.0,
          "ramped force not zero at or past the rest length");
    double at = wc_buckling_force_ramped((1.0 - ramp) * l, l, R);
    double exact = wc_buckling_force((1.0 - ramp) * l, l, R);
    CHECK(fabs(at - exact) <= 1e-12 * exact, "ramp end %.17g, exact %.17g", at, exact);
    double half = wc_buckling_force_ramped((1.0 - 0.5 * ramp) * l, l, R);
    CHECK(fabs(half - 0.5 * at) <= 1e-9 * at, "ramp not linear: half-way %.17g, end %.17g", half, at);
    double worst_exact = 0.0, worst_gradient = 0.0, worst_slope = 0.0;
    for (int k = 1; k < 20000; ++k) {
        double d = l * (1.0 - k / 20000.0), h = 1e-7 * l;
        double f = wc_buckling_force_ramped(d, l, R);
        if ((l - d) / l >= ramp)
            worst_exact = fmax(worst_exact, fabs(f - wc_buckling_force(d, l, R)) / f);
        /* (the difference may not straddle the ramp's corner, where the
         * force's slope changes: there it is off by ~h times that change) */
        if (d - h > 0.0 && d + h < l && fabs((l - d) / l - ramp) > 2e-7) {
            double grad = (wci_buckling_energy_ramped(d - h, l, R) - wci_buckling_energy_ramped(d + h, l, R)) / (2 * h);
            worst_gradient = fmax(worst_gradient, fabs(grad - f) / f);
            double slope = fabs(wc_buckling_force_ramped(d - h, l, R) - wc_buckling_force_ramped(d + h, l, R)) / (2 * h);
            worst_slope = fmax(worst_slope, slope * l * l * l / R);
        }
    }
    printf("ramped force: past the ramp within %.2e of exact; -dU/dd within %.2e; largest slope "
           "%.1f R/l^3 (bound %.1f)\n", worst_exact, worst_gradient, worst_slope,
           WC_BUCKLING_STIFFNESS_BOUND_RAMPED);
    CHECK(worst_exact == 0.0, "ramped force differs from the exact one past the ramp by %g", worst_exact);
    /* Central differences of an energy ~1e-10 J with h = 1e-7 l: rounding
     * (~1e-16 J / 8e-9 m) and the h^2 term keep the match near 1e-6. */
    CHECK(worst_gradient < 1e-5, "ramped force is not minus the energy's gradient: %g", worst_gradient);
    CHECK(worst_slope <= WC_BUCKLING_STIFFNESS_BOUND_RAMPED, "slope %g above the bound", worst_slope);
}

int main(void)
{
    test_inverse_sinc_references();
    test_inverse_sinc_sweep();
    test_force_limits_and_references();
    test_force_matches_exact_path();
    test_force_sweep();
    test_force_is_energy_gradient();
    test_ramped_force();
    return test_report("test_buckling");
}
