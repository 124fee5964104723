/* Small vector helpers on double[3], shared by the collision code.
 *
 * Each is written in one fixed order of operations, so every file that
 * includes this header computes the same bits for the same inputs (the
 * determinism tests compare runs bit for bit). The intersection checker
 * (checker.c) keeps its own on purpose: it shares no code with the solver
 * it checks. */
#ifndef WC_VEC3_H
#define WC_VEC3_H

#include <math.h>

static inline double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static inline void sub3(const double a[3], const double b[3], double out[3])
{
    out[0] = a[0] - b[0], out[1] = a[1] - b[1], out[2] = a[2] - b[2];
}

/* out may be a or b: the components are computed before any is stored. */
static inline void cross3(const double a[3], const double b[3], double out[3])
{
    double x = a[1] * b[2] - a[2] * b[1];
    double y = a[2] * b[0] - a[0] * b[2];
    double z = a[0] * b[1] - a[1] * b[0];
    out[0] = x, out[1] = y, out[2] = z;
}

static inline double norm3(const double a[3]) { return sqrt(dot3(a, a)); }

static inline double dist3(const double a[3], const double b[3])
{
    double d[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
    return sqrt(dot3(d, d));
}

/* a + (b - a) t, the point at parameter t of a linear motion from a to b. */
static inline void lerp3(const double a[3], const double b[3], double t, double out[3])
{
    for (int k = 0; k < 3; ++k) out[k] = a[k] + (b[k] - a[k]) * t;
}

/* Scales v to unit length; returns 0 (v untouched) when its length is zero
 * or not finite. */
static inline int normalize3(double v[3])
{
    double len = sqrt(dot3(v, v));
    if (!(len > 0.0) || !isfinite(len)) return 0;
    for (int k = 0; k < 3; ++k) v[k] /= len;
    return 1;
}

/* fmin/fmax without their NaN rules, which keep them from being inlined;
 * callers pass finite values. */
static inline double min2(double a, double b) { return a < b ? a : b; }
static inline double max2(double a, double b) { return a > b ? a : b; }

#endif
