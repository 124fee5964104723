/* Applied forces against closed forms, for the three integrators:
 *   1. a cloth in uniform wind relaxes toward the wind's velocity (and,
 *      with gravity, toward the terminal velocity u + g density / air_drag)
 *      with the time constant density / air_drag;
 *   2. a uniform external force density p accelerates a free cloth by
 *      p / density;
 *   3. a cloth soft-pinned all over swings rigidly about its targets with
 *      sag g / s and period 2 pi / sqrt(s) (Verlet), settles at the sag
 *      (implicit, damped by backward Euler), stays stable at any stiffness
 *      (implicit), follows targets moved across substeps, and the stable
 *      step estimate counts the springs;
 *   4. a soft-pinned particle is free otherwise: it collides (cannot be
 *      pulled through a plate) and sticks when wet;
 *   5. what has no effect has none: air velocity without drag gives the
 *      same bits as still air, and a cleared field leaves nothing behind.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "applied.h"
#include "cloth.h"
#include "scenes.h"
#include "test_util.h"
#include "wetcloth.h"
#include "world.h"

static const double PI = 3.14159265358979323846;
static const double E = 2.71828182845904523536;
static const wc_integrator ALL[3] = {WC_INTEGRATOR_VERLET, WC_INTEGRATOR_XPBD,
                                     WC_INTEGRATOR_IMPLICIT};
static const char *NAME[3] = {"verlet", "xpbd", "implicit"};

/* The implicit integrator solved to round-off (residual 1e-8 of h f), so
 * that what is measured is its step error. */
static wc_world *make_world(wc_integrator integrator, const double g[3])
{
    wc_world_def def = wc_world_def_default();
    for (int k = 0; k < 3; ++k) def.gravity[k] = g[k];
    def.thread_count = 1;
    def.integrator = integrator;
    def.implicit_tolerance = 0.0;
    return scene_world_from(&def);
}

/* A small grid, 0.5 m across, with nothing but stretch links' elasticity
 * (100 N/m, soft enough for Verlet at the tests' steps): no damping, no
 * bending (a rigid motion leaves the links at their rest length to
 * rounding; see test_integration.c for why bending stays out of exact
 * closed forms), the given drag. */
static int32_t add_plain_grid(wc_world *w, int32_t side, double air_drag, double z)
{
    wc_grid_cloth_def def = wc_grid_cloth_def_default();
    def.count_u = def.count_v = side;
    def.size_u = def.size_v = 0.5;
    def.center[2] = z;
    def.material.stretch_stiffness = 100.0;
    def.material.stretch_damping = 0.0;
    def.material.bend_stiffness = 0.0;
    def.material.air_drag = air_drag;
    return scene_add_grid(w, &def);
}

static double *uniform_field(int32_t n, const double v[3])
{
    double *f = malloc(3 * (size_t)n * sizeof *f);
    for (int32_t i = 0; i < 3 * n; ++i) f[i] = v[i % 3];
    return f;
}

/* Largest |d - l| over the stretch links, m. */
static double worst_link_strain(const wc_world *w, int32_t id)
{
    int32_t n = wc_cloth_particle_count(w, id), links = wc_cloth_link_count(w, id, WC_LINK_STRETCH);
    int32_t *pairs = malloc(2 * (size_t)links * sizeof *pairs);
    double *rest = malloc((size_t)links * sizeof *rest), *x = malloc(3 * (size_t)n * sizeof *x);
    wc_cloth_get_links(w, id, WC_LINK_STRETCH, pairs, rest, links);
    wc_cloth_get_positions(w, id, x, n);
    double worst = 0.0;
    for (int32_t e = 0; e < links; ++e) {
        const double *a = x + 3 * (size_t)pairs[2 * e], *b = x + 3 * (size_t)pairs[2 * e + 1];
        double d = sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                        (a[2] - b[2]) * (a[2] - b[2]));
        if (fabs(d - rest[e]) > worst) worst = fabs(d - rest[e]);
    }
    free(pairs), free(rest), free(x);
    return worst;
}

/* ------------------------------------------------------------------------ */
/* 1. Uniform wind                                                           */
/* ------------------------------------------------------------------------ */

/* A 6 x 6 cloth at rest in uniform wind u = (2, -1, 0.5) m/s, air_drag
 * 1.5 N s/m^3 on 0.15 kg/m^2: a = g - (v - u) / tau with tau = density /
 * air_drag = 0.1 s for every particle (m_i = density A_i, drag force
 * air_drag A_i (u - v)), so the cloth moves rigidly and its links stay at
 * their rest length. The error e = v - v_T against the terminal velocity
 * v_T = u + g tau decays as exp(-t / tau). 0.5 s (5 tau) in steps of
 * h = 0.5 ms (x = h / tau = 0.005; half Verlet's stable step or less).
 *
 * What each integrator does with it, for the chord velocity v_n = (x_n -
 * x_{n-1}) / h that wc_cloth_get_velocities reports (the velocity at
 * t_n - h / 2):
 *   Verlet: x_{n+1} = 2 x_n - x_{n-1} + h^2 a(v_n), so e_{n+1} = (1 - x) e_n;
 *     its first step, x_0 + v_0 h + a h^2 / 2, gives e_1 = (1 - x / 2) e_0:
 *     e_n = e_0 (1 - x / 2) (1 - x)^(n-1).
 *   XPBD: Verlet's prediction; the stretch constraints see rounding-level
 *     stretch only: the same.
 *   Implicit: backward Euler on the drag, (1 + x) dv = -x e_n, e_{n+1} = e_n
 *     / (1 + x); its first step takes half of dv (share 1/2, implicit.c):
 *     e_n = e_0 (1 - x / (2 (1 + x))) (1 + x)^-(n-1).
 * Against the exact e_0 exp(-(t_n - h/2) / tau), both laws are off by a
 * relative (n - 3/4) x^2 / 2 (Verlet) and (n - 1/4) x^2 / 2 (implicit) to
 * second order: ~ t h / (2 tau^2), whose largest absolute effect,
 * |e_0| exp(-t / tau) t h / (2 tau^2), is |e_0| x / (2 e) at t = tau. The
 * bound adds x^2 |e_0| for the higher orders: 0.94e-3 |e_0|. At 5 tau,
 * the same relative error, 5 x / 2, separates the cloth from exp(-5) of
 * the start's difference: checked within (1 + 5 x) exp(-5) |e_0|.
 *
 * Each is also checked against its own discrete law: Verlet and XPBD to
 * rounding (a position rounds at ~1e-16 m per step, 1e-13 m/s in the chord
 * velocity, contracted by 1 - x per step: at most ~1e-11 m/s; checked to
 * 1e-9); the implicit integrator's solve stops at a residual of 1e-8 of h
 * f, an error of at most ~1e-8 |dv| per step (a few times that per
 * particle, the 2-norm being over all of them), contracted likewise: at
 * most a few 1e-8 |e_0|; checked to 1e-6 |e_0|.
 * The links stay at their rest length to rounding (1e-12 m), and for the
 * implicit integrator within what that residual leaves unequal between
 * the particles' velocity changes, 1e-8 of |dv| <= x |e_0| per step,
 * over 1000 steps of h: at most ~1e-10 m (checked to 1e-9 m). */
static void wind(int which, int with_gravity)
{
    const double g[3] = {0.0, 0.0, with_gravity ? -9.81 : 0.0}, u[3] = {2.0, -1.0, 0.5};
    const double tau = 0.15 / 1.5, h = 5e-4;
    const int steps = 1000;
    wc_world *w = make_world(ALL[which], g);
    int32_t id = add_plain_grid(w, 6, 1.5, 1.0);
    int32_t n = wc_cloth_particle_count(w, id);
    CHECK(h <= 0.5 * wc_cloth_stable_dt(w, id), "the test's step %g is above half the stable %g",
          h, wc_cloth_stable_dt(w, id));
    double *air = uniform_field(n, u), *v = malloc(3 * (size_t)n * sizeof *v);
    CHECK(wc_cloth_set_air_velocity(w, id, air, n) == WC_OK, "set_air_velocity: %s",
          wc_world_last_error(w));
    double terminal[3], e0[3], e0_norm = 0.0;
    for (int k = 0; k < 3; ++k) {
        terminal[k] = u[k] + g[k] * tau;
        e0[k] = 0.0 - terminal[k];
        e0_norm += e0[k] * e0[k];
    }
    e0_norm = sqrt(e0_norm);
    const double x = h / tau;
    const double bound = e0_norm * (x / (2.0 * E) + x * x);
    const double discrete_tolerance = which == 2 ? 1e-6 * e0_norm : 1e-9;
    double worst = 0.0, worst_discrete = 0.0, worst_strain = 0.0;
    for (int s = 1; s <= steps; ++s) {
        if (wc_world_step(w, h) != WC_OK) {
            CHECK(0, "%s step %d: %s", NAME[which], s, wc_world_last_error(w));
            break;
        }
        double law = which == 2 ? (1.0 - x / (2.0 * (1.0 + x))) * pow(1.0 + x, -(s - 1))
                                : (1.0 - x / 2.0) * pow(1.0 - x, s - 1);
        double exact = exp(-(s - 0.5) * x);
        wc_cloth_get_velocities(w, id, v, n);
        for (int32_t i = 0; i < n; ++i) {
            double d2 = 0.0, c2 = 0.0;
            for (int k = 0; k < 3; ++k) {
                double dk = v[3 * i + k] - (terminal[k] + e0[k] * law);
                double ck = v[3 * i + k] - (terminal[k] + e0[k] * exact);
                d2 += dk * dk, c2 += ck * ck;
            }
            if (sqrt(d2) > worst_discrete) worst_discrete = sqrt(d2);
            if (sqrt(c2) > worst) worst = sqrt(c2);
        }
        if (s % 100 == 0) {
            double strain = worst_link_strain(w, id);
            if (strain > worst_strain) worst_strain = strain;
        }
    }
    printf("wind, %s%s: %d steps of %g s (tau %g s): worst error %.3e m/s against exp(-t/tau) "
           "(bound %.3e), %.3e against its discrete law (bound %.1e), links within %.1e m\n",
           NAME[which], with_gravity ? ", with gravity" : "", steps, h, tau, worst, bound,
           worst_discrete, discrete_tolerance, worst_strain);
    CHECK(worst <= bound, "%s wind: %.3e m/s off exp(-t/tau), bound %.3e", NAME[which], worst,
          bound);
    CHECK(worst_discrete <= discrete_tolerance, "%s wind: %.3e m/s off its discrete law",
          NAME[which], worst_discrete);
    CHECK(worst_strain <= (which == 2 ? 1e-9 : 1e-12),
          "%s wind: a link strayed %.3e m from its rest length", NAME[which], worst_strain);
    /* after 5 tau the cloth moves with the wind (or falls through it at
     * the terminal velocity): within exp(-5) of the start's difference */
    wc_cloth_get_velocities(w, id, v, n);
    double left = 0.0;
    for (int k = 0; k < 3; ++k) left += (v[k] - terminal[k]) * (v[k] - terminal[k]);
    CHECK(sqrt(left) <= (1.0 + 5.0 * x) * exp(-5.0) * e0_norm,
          "%s wind: %.3e m/s from the terminal velocity", NAME[which], sqrt(left));
    free(air), free(v);
    wc_world_destroy(w);
}

/* ------------------------------------------------------------------------ */
/* 2. External force density                                                 */
/* ------------------------------------------------------------------------ */

/* p = (3, -2, 5) N/m^2 on a free cloth of 0.15 kg/m^2, no gravity, no drag:
 * every particle feels A_i p and has mass density A_i, so a = p / density,
 * whatever the particle's area (edge particles have half, corners a
 * quarter). 1 s in 2000 steps (half Verlet's stable step on the finer
 * cloth). Verlet and XPBD are exact for constant
 * acceleration: rounding only, 1e-10 relative (test_integration.c derives
 * it for free fall). The implicit integrator is exact too (test_integrators
 * free fall) up to its solve's residual, 1e-8 of h f per step: below
 * 1e-8 |a| t^2. Also two cloths of 6 x 6 and 11 x 11 particles get the same
 * motion: the force density does not depend on the resolution. */
static void external_force(int which)
{
    const double g[3] = {0.0, 0.0, 0.0}, p[3] = {3.0, -2.0, 5.0}, density = 0.15, h = 5e-4;
    const int steps = 2000;
    wc_world *w = make_world(ALL[which], g);
    int32_t ids[2] = {add_plain_grid(w, 6, 0.0, 0.0), add_plain_grid(w, 11, 0.0, 2.0)};
    CHECK(h <= 0.5 * wc_world_stable_dt(w), "the test's step %g is above half the stable %g", h,
          wc_world_stable_dt(w));
    double a[3], a_norm = 0.0;
    for (int k = 0; k < 3; ++k) a[k] = p[k] / density, a_norm += a[k] * a[k];
    a_norm = sqrt(a_norm);
    for (int c = 0; c < 2; ++c) {
        int32_t n = wc_cloth_particle_count(w, ids[c]);
        double *field = uniform_field(n, p);
        CHECK(wc_cloth_set_external_forces(w, ids[c], field, n) == WC_OK,
              "set_external_forces: %s", wc_world_last_error(w));
        free(field);
    }
    double *x0[2], *x[2];
    for (int c = 0; c < 2; ++c) {
        int32_t n = wc_cloth_particle_count(w, ids[c]);
        x0[c] = malloc(3 * (size_t)n * sizeof(double)), x[c] = malloc(3 * (size_t)n * sizeof(double));
        wc_cloth_get_positions(w, ids[c], x0[c], n);
    }
    for (int s = 0; s < steps; ++s)
        if (wc_world_step(w, h) != WC_OK) {
            CHECK(0, "%s step %d: %s", NAME[which], s, wc_world_last_error(w));
            break;
        }
    double t = steps * h, worst = 0.0;
    for (int c = 0; c < 2; ++c) {
        int32_t n = wc_cloth_particle_count(w, ids[c]);
        wc_cloth_get_positions(w, ids[c], x[c], n);
        for (int32_t i = 0; i < n; ++i) {
            double e2 = 0.0;
            for (int k = 0; k < 3; ++k) {
                double expect = x0[c][3 * i + k] + 0.5 * a[k] * t * t;
                e2 += (x[c][3 * i + k] - expect) * (x[c][3 * i + k] - expect);
            }
            if (sqrt(e2) > worst) worst = sqrt(e2);
        }
    }
    double scale = 2.5 + 0.5 * a_norm * t * t;
    double bound = which == 2 ? 1e-8 * a_norm * t * t : 1e-10 * scale;
    printf("external force, %s: a = p / density = (%g, %g, %g) m/s^2, %d steps: worst error "
           "%.2e m against a t^2 / 2 (bound %.2e), 6 x 6 and 11 x 11 cloths\n",
           NAME[which], a[0], a[1], a[2], steps, worst, bound);
    CHECK(worst <= bound, "%s external force: %.3e m off a t^2 / 2", NAME[which], worst);
    for (int c = 0; c < 2; ++c) free(x0[c]), free(x[c]);
    wc_world_destroy(w);
}

/* ------------------------------------------------------------------------ */
/* 3. Soft pins                                                              */
/* ------------------------------------------------------------------------ */

/* Soft-pins every particle of a cloth with one stiffness. */
static void pin_all_soft(wc_world *w, int32_t id, double stiffness)
{
    int32_t n = wc_cloth_particle_count(w, id);
    int32_t *idx = malloc((size_t)n * sizeof *idx);
    double *s = malloc((size_t)n * sizeof *s);
    for (int32_t i = 0; i < n; ++i) idx[i] = i, s[i] = stiffness;
    CHECK(wc_cloth_pin_soft(w, id, idx, s, n) == WC_OK, "pin_soft: %s", wc_world_last_error(w));
    free(idx), free(s);
}

/* Mean displacement of the cloth from where it started along z, m, and
 * the largest spread of the particles' displacements (x, y and z) about
 * it: zero for a rigid translation. */
static double mean_drop(const wc_world *w, int32_t id, const double *x0, double *spread)
{
    int32_t n = wc_cloth_particle_count(w, id);
    double *x = malloc(3 * (size_t)n * sizeof *x);
    wc_cloth_get_positions(w, id, x, n);
    double d0[3] = {x[0] - x0[0], x[1] - x0[1], x[2] - x0[2]};
    *spread = 0.0;
    for (int32_t i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k) {
            double off = fabs(x[3 * i + k] - x0[3 * i + k] - d0[k]);
            if (off > *spread) *spread = off;
        }
    free(x);
    return -d0[2];
}

/* Every particle of a 6 x 6 cloth soft-pinned with s = 100 /s^2 where it
 * starts, under g = 9.81 m/s^2, no damping, no drag: each particle obeys
 * z'' = -g - s (z - z_0), the same for all, so the cloth translates
 * rigidly and drops by d(t) = (g / s) (1 - cos(omega t)), omega = sqrt(s):
 * about a sag of g / s, period 2 pi / omega.
 * Verlet (h = 0.5 ms, two periods) solves d_{n+1} - 2 d_n + d_{n-1} = h^2 (g
 * - s d_n) with the exact start d_1 = g h^2 / 2, whose solution is exactly
 * (g / s) (1 - cos(Omega t_n)) with 2 (1 - cos(Omega h)) = s h^2: Omega =
 * (2 / h) asin(omega h / 2) = omega (1 + (omega h)^2 / 24 + ...). Checked
 * against that law to rounding (1e-12 m: ~1e-16 m per step for 2514
 * steps, not contracted), against the closed form within the phase error
 * (g / s) (Omega - omega) t plus that, and the period measured from the
 * up-crossings of the sag against 2 pi / omega within (omega h)^2 / 24
 * plus the linear interpolation's error (the sag is nearly linear at a
 * crossing: O((omega h)^2) of h, 1e-4 of the period here; 2e-4 allowed).
 * XPBD, which treats the spring explicitly as Verlet does and whose
 * constraints see rounding-level stretch only, must do the same. */
static void soft_pin_swing(int which)
{
    const double g[3] = {0.0, 0.0, -9.81}, s = 100.0, h = 5e-4, omega = sqrt(s);
    const double sag = 9.81 / s, period = 2.0 * PI / omega;
    const int steps = (int)ceil(2.0 * period / h);
    wc_world *w = make_world(ALL[which], g);
    int32_t id = add_plain_grid(w, 6, 0.0, 1.0);
    int32_t n = wc_cloth_particle_count(w, id);
    double *x0 = malloc(3 * (size_t)n * sizeof *x0);
    wc_cloth_get_positions(w, id, x0, n);
    pin_all_soft(w, id, s);
    CHECK(wc_cloth_pin_count(w, id) == n, "pin count %d, expected %d", wc_cloth_pin_count(w, id),
          (int)n);
    CHECK(h <= 0.5 * wc_cloth_stable_dt(w, id), "the test's step %g is above half the stable %g",
          h, wc_cloth_stable_dt(w, id));
    const double Omega = 2.0 / h * asin(omega * h / 2.0);
    double worst_law = 0.0, worst_closed = 0.0, worst_spread = 0.0, worst_strain = 0.0;
    double prev = 0.0, crossings[8];
    int crossing_count = 0;
    for (int k = 1; k <= steps; ++k) {
        if (wc_world_step(w, h) != WC_OK) {
            CHECK(0, "step %d: %s", k, wc_world_last_error(w));
            break;
        }
        double spread, d = mean_drop(w, id, x0, &spread), t = k * h;
        double law = sag * (1.0 - cos(Omega * t)), closed = sag * (1.0 - cos(omega * t));
        if (fabs(d - law) > worst_law) worst_law = fabs(d - law);
        if (fabs(d - closed) > worst_closed) worst_closed = fabs(d - closed);
        if (spread > worst_spread) worst_spread = spread;
        if (k % 200 == 0) {
            double strain = worst_link_strain(w, id);
            if (strain > worst_strain) worst_strain = strain;
        }
        /* up-crossings of d = sag, linearly interpolated */
        if (prev < sag && d >= sag && crossing_count < 8)
            crossings[crossing_count++] = (k - 1 + (sag - prev) / (d - prev)) * h;
        prev = d;
    }
    double t_end = steps * h;
    double closed_bound = sag * (Omega - omega) * t_end * 1.01 + 1e-12;
    double measured = crossing_count >= 2 ? crossings[1] - crossings[0] : 0.0;
    double period_error = fabs(measured - period) / period;
    printf("soft pins, %s: sag %.4g m, period %.6f s (2 pi / sqrt(s) = %.6f, off %.1e); "
           "%.2e m off the discrete law, %.2e m off the closed form (bound %.2e); rigid within "
           "%.1e m, links within %.1e m\n",
           NAME[which], sag, measured, period, period_error, worst_law, worst_closed, closed_bound,
           worst_spread, worst_strain);
    CHECK(crossing_count >= 2, "the sag crossed its mean %d times in two periods", crossing_count);
    CHECK(period_error <= 2e-4, "period %.6f s, expected %.6f", measured, period);
    CHECK(worst_law <= 1e-12, "%.3e m off Verlet's law", worst_law);
    CHECK(worst_closed <= closed_bound, "%.3e m off the closed form, bound %.3e", worst_closed,
          closed_bound);
    CHECK(worst_spread <= 1e-12 && worst_strain <= 1e-12,
          "not rigid: particles spread %.3e m, a link strayed %.3e m", worst_spread, worst_strain);
    free(x0);
    wc_world_destroy(w);
}

/* The same cloth with the implicit integrator at h = 20 ms (omega h =
 * 0.2): backward Euler damps the swing by 1 / sqrt(1 + (omega h)^2) =
 * 0.9806 per step, to 3e-9 of it after 20 s, and its fixed point is the
 * static sag exactly (f = 0 there): |d - g / s| <= 1e-6 g / s at the end.
 * On the way, y_n = d_n - g / s obeys backward Euler's recurrence
 * y_{n+1} = a y_n - b y_{n-1}, a = 2 b, b = 1 / (1 + (omega h)^2), for which
 * Q_n = y_{n+1}^2 - a y_{n+1} y_n + b y_n^2 shrinks by exactly b per step
 * (substitute the recurrence): Q_600 / Q_100 = b^500, checked within 1 %
 * (the solve's residual, 1e-8 of h f, is all that separates them). At
 * s = 1e6 (s h^2 = 400, where an explicit step would be 10x past its
 * limit) it is still stable and settles at g / s = 9.8 um. */
static void soft_pin_settle(double s, int steps, double h)
{
    const int which = 2;
    const double g[3] = {0.0, 0.0, -9.81}, sag = 9.81 / s;
    wc_world *w = make_world(ALL[which], g);
    int32_t id = add_plain_grid(w, 6, 0.0, 1.0);
    int32_t n = wc_cloth_particle_count(w, id);
    double *x0 = malloc(3 * (size_t)n * sizeof *x0);
    wc_cloth_get_positions(w, id, x0, n);
    pin_all_soft(w, id, s);
    const double b = 1.0 / (1.0 + s * h * h), a = 2.0 * b;
    double q[2] = {0.0, 0.0}, y_prev = 0.0, worst_spread = 0.0, d = 0.0;
    for (int k = 1; k <= steps; ++k) {
        if (wc_world_step(w, h) != WC_OK) {
            CHECK(0, "%s, s = %g: step %d: %s", NAME[which], s, k, wc_world_last_error(w));
            break;
        }
        double spread;
        d = mean_drop(w, id, x0, &spread);
        if (spread > worst_spread) worst_spread = spread;
        double y = d - sag;
        /* Q_100 from y_101 and y_100, Q_600 from y_601 and y_600 */
        if (k == 101) q[0] = y * y - a * y * y_prev + b * y_prev * y_prev;
        if (k == 601) q[1] = y * y - a * y * y_prev + b * y_prev * y_prev;
        y_prev = y;
    }
    printf("soft pins, %s, s = %g, h = %g: sag %.6e m after %d steps (g / s = %.6e, off %.1e "
           "relative); rigid within %.1e m", NAME[which], s, h, d, steps, sag,
           fabs(d - sag) / sag, worst_spread);
    CHECK(fabs(d - sag) <= 1e-6 * sag, "%s, s = %g: sag %.6e m, expected %.6e", NAME[which], s, d,
          sag);
    if (steps > 601) {
        double expect = pow(b, 500.0), got = q[1] / q[0];
        printf("; Q shrank %.6e-fold over 500 steps (backward Euler: %.6e)", got, expect);
        CHECK(fabs(got / expect - 1.0) <= 0.01, "Q shrank %.6e-fold, backward Euler %.6e", got,
              expect);
    }
    printf("\n");
    CHECK(worst_spread <= 1e-9 * (1.0 + sag), "%s, s = %g: not rigid, spread %.3e m", NAME[which],
          s, worst_spread);
    free(x0);
    wc_world_destroy(w);
}

/* The stable step estimate counts the springs where they are explicit:
 * Verlet's and XPBD's estimate drops to at most 2 / sqrt(s) (the spring
 * alone; Gershgorin's bound adds the links), and comes back bitwise after
 * wc_cloth_unpin_all; the implicit integrator's does not change. With
 * automatic substeps Verlet then stays stable at s = 1e6. */
static void soft_pin_stable_step(void)
{
    const double g[3] = {0.0, 0.0, -9.81}, s = 1e6;
    for (int which = 0; which < 3; ++which) {
        wc_world *w = make_world(ALL[which], g);
        int32_t id = add_plain_grid(w, 6, 0.0, 1.0);
        double before = wc_cloth_stable_dt(w, id);
        pin_all_soft(w, id, s);
        double with = wc_cloth_stable_dt(w, id);
        CHECK(wc_cloth_unpin_all(w, id) == WC_OK, "unpin_all");
        double after = wc_cloth_stable_dt(w, id);
        printf("stable step, %s: %.4e s, with soft pins of %g /s^2 %.4e s (2 / sqrt(s) = %.4e), "
               "unpinned %.4e s\n", NAME[which], before, s, with, 2.0 / sqrt(s), after);
        if (which == 2)
            CHECK(with == before, "implicit: soft pins changed the stable step %g -> %g", before,
                  with);
        else
            CHECK(with <= 2.0 / sqrt(s) && with < before, "%s: stable step %g with springs of "
                  "%g /s^2 (at most 2 / sqrt(s) = %g)", NAME[which], with, s, 2.0 / sqrt(s));
        CHECK(after == before, "%s: after unpin_all the stable step is %g, was %g", NAME[which],
              after, before);
        CHECK(wc_cloth_pin_count(w, id) == 0, "pins left after unpin_all");
        wc_world_destroy(w);
    }
    /* automatic substeps keep Verlet stable at the stiff springs */
    wc_world *w = make_world(WC_INTEGRATOR_VERLET, g);
    int32_t id = add_plain_grid(w, 6, 0.0, 1.0);
    int32_t n = wc_cloth_particle_count(w, id);
    double *x0 = malloc(3 * (size_t)n * sizeof *x0);
    wc_cloth_get_positions(w, id, x0, n);
    pin_all_soft(w, id, s);
    double worst = 0.0, spread;
    for (int f = 0; f < 6; ++f) {
        CHECK(wc_world_advance(w, 1.0 / 24, 0) == WC_OK, "frame %d: %s", f, wc_world_last_error(w));
        double d = mean_drop(w, id, x0, &spread);
        if (fabs(d) > worst) worst = fabs(d);
    }
    printf("stiff soft pins, verlet, automatic substeps (%d per frame): drop at most %.3e m "
           "(2 g / s = %.3e)\n", (int)wc_world_last_substeps(w), worst, 2.0 * 9.81 / s);
    CHECK(worst <= 2.0 * 9.81 / s * (1.0 + 1e-6), "stiff soft pins swung %.3e m, at most %.3e",
          worst, 2.0 * 9.81 / s);
    free(x0);
    wc_world_destroy(w);
}

/* Targets moved across the substeps of an advance. No gravity; every
 * particle soft-pinned with s = 400 /s^2; the targets are moved by
 * D = (0.1, 0, 0.05) m in one frame of 1/24 s (40 substeps), then by D
 * again in the next. Within an advance pin targets move linearly: a
 * substep from t_k to t_{k+1} sees T(t_k) (Verlet, whose force is at the
 * step's start) or T(t_{k+1}) (implicit, backward Euler's force at its
 * end). The test runs each integrator's 1D recurrence itself for the
 * displacement, which every particle shares, and compares: Verlet to
 * rounding (1e-13 m over 80 steps), the implicit within its solve's
 * residual (1e-8 of h f per step: below 1e-9 m here). Also checks that the
 * targets are not the particles' positions: after the advance the next
 * starts from the target where it was, not from where the particle got. */
static void soft_pin_moving_targets(int which)
{
    const double g[3] = {0.0, 0.0, 0.0}, s = 400.0, D[3] = {0.1, 0.0, 0.05};
    const int substeps = 40, frames = 2;
    const double h = 1.0 / 24 / substeps;
    wc_world *w = make_world(ALL[which], g);
    int32_t id = add_plain_grid(w, 6, 0.0, 1.0);
    int32_t n = wc_cloth_particle_count(w, id);
    double *x0 = malloc(3 * (size_t)n * sizeof *x0), *x = malloc(3 * (size_t)n * sizeof *x);
    double *targets = malloc(3 * (size_t)n * sizeof *targets);
    wc_cloth_get_positions(w, id, x0, n);
    pin_all_soft(w, id, s);
    /* the recurrence for each axis: displacement d, last chord velocity v */
    double d[3] = {0, 0, 0}, v[3] = {0, 0, 0};
    int first = 1;
    double worst = 0.0;
    for (int f = 1; f <= frames; ++f) {
        for (int32_t i = 0; i < 3 * n; ++i) targets[i] = x0[i] + f * D[i % 3];
        CHECK(wc_cloth_set_pin_targets(w, id, targets, n) == WC_OK, "targets: %s",
              wc_world_last_error(w));
        CHECK(wc_world_advance(w, 1.0 / 24, substeps) == WC_OK, "frame %d: %s", f,
              wc_world_last_error(w));
        for (int k = 0; k < substeps; ++k)
            for (int a = 0; a < 3; ++a) {
                double from = (f - 1) * D[a], to = f * D[a];
                double start = from + (to - from) * k / substeps;
                double end = from + (to - from) * (k + 1) / substeps;
                if (which == 2) {
                    double share = first ? 0.5 : 1.0;
                    double dv = h * (-s * (d[a] - end) - h * s * v[a]) / (1.0 + share * h * h * s);
                    double next = d[a] + h * (v[a] + share * dv);
                    v[a] = (next - d[a]) / h, d[a] = next;
                } else {
                    double acc = -s * (d[a] - start);
                    double next = first ? d[a] + v[a] * h + 0.5 * acc * h * h
                                        : d[a] + v[a] * h + acc * h * h;
                    v[a] = (next - d[a]) / h, d[a] = next;
                }
                if (a == 2) first = 0;
            }
        wc_cloth_get_positions(w, id, x, n);
        for (int32_t i = 0; i < n; ++i)
            for (int a = 0; a < 3; ++a) {
                double off = fabs(x[3 * i + a] - x0[3 * i + a] - d[a]);
                if (off > worst) worst = off;
            }
    }
    double bound = which == 2 ? 1e-9 : 1e-13;
    printf("soft pins, %s, targets moving across substeps: displacement (%.6f, %.6f, %.6f) m "
           "after %d frames, %.2e m off the recurrence (bound %.0e)\n",
           NAME[which], d[0], d[1], d[2], frames, worst, bound);
    CHECK(worst <= bound, "%s: moving soft pins %.3e m off the recurrence", NAME[which], worst);
    free(x0), free(x), free(targets);
    wc_world_destroy(w);
}

/* ------------------------------------------------------------------------ */
/* 4. A soft-pinned particle is free otherwise                               */
/* ------------------------------------------------------------------------ */

/* A 10 x 10 cloth 5 cm over a plate, every particle soft-pinned with
 * s = 400 /s^2 (a pull of 120 m/s^2 per 0.3 m), its targets moved 0.3 m
 * below the plate: the cloth is pulled onto the plate and stays on it,
 * each particle at least its thickness (5 mm) above it, to 1 % of the
 * thickness, with no intersection, in contact. Wet, the same cloth sticks
 * there. (A hard pin would go through: hard pins do not collide.) */
static void soft_pin_collides(int which, double wetness)
{
    const double g[3] = {0.0, 0.0, -9.81}, ex[3] = {1, 0, 0}, ey[3] = {0, 1, 0};
    const double zero[3] = {0.0, 0.0, 0.0};
    wc_world *w = make_world(ALL[which], g);
    wc_grid_cloth_def def = wc_grid_cloth_def_default();
    def.count_u = def.count_v = 10;
    def.size_u = def.size_v = 0.5;
    def.center[2] = 0.05;
    def.wetness = wetness;
    int32_t id = scene_add_grid(w, &def);
    scene_add_plate(w, zero, ex, ey, 2.0, 0.0);
    int32_t n = wc_cloth_particle_count(w, id);
    double *x = malloc(3 * (size_t)n * sizeof *x);
    wc_cloth_get_positions(w, id, x, n);
    pin_all_soft(w, id, 400.0);
    for (int32_t i = 0; i < n; ++i) x[3 * i + 2] -= 0.35;
    CHECK(wc_cloth_set_pin_targets(w, id, x, n) == WC_OK, "targets: %s", wc_world_last_error(w));
    int intersections = 0;
    for (int f = 0; f < 24; ++f) {
        if (wc_world_advance(w, 1.0 / 24, 0) != WC_OK) {
            CHECK(0, "%s frame %d: %s", NAME[which], f, wc_world_last_error(w));
            break;
        }
        intersections += scene_intersections(w);
    }
    wc_cloth_get_positions(w, id, x, n);
    double lowest = INFINITY;
    for (int32_t i = 0; i < n; ++i)
        if (x[3 * i + 2] < lowest) lowest = x[3 * i + 2];
    uint8_t *kind = malloc((size_t)n), *stuck = malloc((size_t)n);
    wc_cloth_get_contacts(w, id, kind, NULL, n);
    wc_cloth_get_stuck(w, id, stuck, n);
    int touching = 0, stuck_count = 0;
    for (int32_t i = 0; i < n; ++i) touching += kind[i] == WC_CONTACT_COLLIDER, stuck_count += stuck[i];
    printf("soft pins, %s%s, pulled 0.3 m under a plate: lowest particle %.5f m (thickness "
           "%.3f), %d of %d in contact, %d stuck, %d intersecting pair-frames\n", NAME[which],
           wetness > 0.0 ? ", wet" : "", lowest, def.material.thickness, touching, (int)n,
           stuck_count, intersections);
    CHECK(lowest >= 0.99 * def.material.thickness, "%s: a soft-pinned particle at z = %.5f went "
          "into the plate", NAME[which], lowest);
    CHECK(intersections == 0, "%s: %d intersecting pair-frames", NAME[which], intersections);
    CHECK(touching == n, "%s: only %d of %d particles touch the plate", NAME[which], touching,
          (int)n);
    if (wetness > 0.0)
        CHECK(stuck_count == n, "%s: only %d of %d wet soft-pinned particles stuck", NAME[which],
              stuck_count, (int)n);
    free(x), free(kind), free(stuck);
    wc_world_destroy(w);
}

/* ------------------------------------------------------------------------ */
/* 5. No effect where there is none                                         */
/* ------------------------------------------------------------------------ */

/* With air_drag 0 the air velocity has nothing to act through: bitwise the
 * same run as still air, and no pass runs (wci_applied_active). Cleared
 * fields (NULL, 0) free their memory, and unpinned soft pins stop the
 * pass too. A field set to zero everywhere adds +0 to every force: the
 * same bits as none. */
static void no_effect(void)
{
    const double g[3] = {0.0, 0.0, -9.81}, u[3] = {5.0, 0.0, 1.0}, none[3] = {0.0, 0.0, 0.0};
    for (int which = 0; which < 3; ++which) {
        wc_world *a = make_world(ALL[which], g), *b = make_world(ALL[which], g);
        int32_t ia = add_plain_grid(a, 6, 0.0, 1.0), ib = add_plain_grid(b, 6, 0.0, 1.0);
        int32_t n = wc_cloth_particle_count(a, ia), corner = 0;
        wc_cloth_pin(a, ia, &corner, 1), wc_cloth_pin(b, ib, &corner, 1);
        double *air = uniform_field(n, u), *zero = uniform_field(n, none);
        CHECK(wc_cloth_set_air_velocity(a, ia, air, n) == WC_OK, "air");
        wc_cloth *c = a->cloths[ia];
        CHECK(!wci_applied_active(c), "%s: air velocity without drag runs the pass", NAME[which]);
        CHECK(wc_cloth_set_external_forces(a, ia, zero, n) == WC_OK, "zero field");
        for (int s = 0; s < 50; ++s) wc_world_step(a, 1e-3), wc_world_step(b, 1e-3);
        CHECK(scene_hash_positions(a, ia) == scene_hash_positions(b, ib),
              "%s: air velocity without drag, or a zero force field, changed the motion",
              NAME[which]);
        CHECK(wc_cloth_set_air_velocity(a, ia, NULL, 0) == WC_OK &&
                  wc_cloth_set_external_forces(a, ia, NULL, 0) == WC_OK,
              "clearing: %s", wc_world_last_error(a));
        CHECK(!c->air_velocity && !c->external_force && !wci_applied_active(c),
              "%s: a cleared field stayed", NAME[which]);
        int32_t middle = 14;
        double stiff = 50.0;
        CHECK(wc_cloth_pin_soft(a, ia, &middle, &stiff, 1) == WC_OK, "pin_soft");
        CHECK(wci_applied_active(c), "%s: a soft pin runs no pass", NAME[which]);
        CHECK(wc_cloth_unpin_all(a, ia) == WC_OK && !wci_applied_active(c),
              "%s: the pass runs after unpin_all", NAME[which]);
        free(air), free(zero);
        wc_world_destroy(a), wc_world_destroy(b);
    }
}

int main(void)
{
    for (int which = 0; which < 3; ++which) wind(which, 0), wind(which, 1);
    for (int which = 0; which < 3; ++which) external_force(which);
    soft_pin_swing(0);
    soft_pin_swing(1);
    soft_pin_settle(100.0, 1000, 0.02);
    soft_pin_settle(1e6, 200, 0.02);
    soft_pin_stable_step();
    for (int which = 0; which < 3; ++which) soft_pin_moving_targets(which);
    for (int which = 0; which < 3; ++which) soft_pin_collides(which, 0.0);
    soft_pin_collides(2, 1.0);
    no_effect();
    return test_report("test_applied");
}
