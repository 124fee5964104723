#include "predicates.h"

#include <math.h>

/* Unit roundoff of double, 2^-53. */
#define EPSILON 1.1102230246251565e-16
/* Bounds on the rounding error of the floating-point determinants, as
 * multiples of their permanents (Shewchuk's o3derrboundA = (7 + 56 eps) eps
 * and ccwerrboundA = (3 + 16 eps) eps, each rounded up). */
#define ORIENT3D_BOUND (8.0 * EPSILON)
#define ORIENT2D_BOUND (4.0 * EPSILON)
/* Longest expansion the exact determinants can make (192 for orient3d). */
#define MAX_TERMS 256

/* ------------------------------------------------------------------------ */
/* Expansion arithmetic                                                     */
/* ------------------------------------------------------------------------ */

/* An expansion: terms ascending in magnitude, none overlapping, whose exact
 * sum is the value; `count` terms. */
typedef struct expansion {
    int count;
    double term[MAX_TERMS];
} expansion;

/* x + y = a + b exactly, x = fl(a + b) (Knuth). */
static void two_sum(double a, double b, double *x, double *y)
{
    double s = a + b, bv = s - a, av = s - bv;
    *x = s;
    *y = (a - av) + (b - bv);
}

/* x + y = a - b exactly, x = fl(a - b). */
static void two_diff(double a, double b, double *x, double *y)
{
    double s = a - b, bv = a - s, av = s + bv;
    *x = s;
    *y = (a - av) + (bv - b);
}

/* a = hi + lo exactly, each with at most 26 significant bits (Veltkamp's
 * split, Shewchuk's Split), so that products of the halves are exact. */
static void split(double a, double *hi, double *lo)
{
    double c = 134217729.0 * a; /* 2^27 + 1 */
    double big = c - a;
    *hi = c - big;
    *lo = a - *hi;
}

/* x + y = a b exactly, x = fl(a b) (Dekker's product, Shewchuk's
 * Two_Product). Not fma: the C library's fma is not exact everywhere (the
 * Windows build under wine gets 5.5 % of random products' low parts wrong),
 * and these predicates are only as good as this product. Exact while
 * |a b| stays far from overflow, which the inputs' range (predicates.h)
 * keeps. */
static void two_product(double a, double b, double *x, double *y)
{
    double ahi, alo, bhi, blo;
    *x = a * b;
    split(a, &ahi, &alo);
    split(b, &bhi, &blo);
    double err1 = *x - ahi * bhi;
    double err2 = err1 - alo * bhi;
    double err3 = err2 - ahi * blo;
    *y = alo * blo - err3;
}

/* x + y = a + b exactly, for |a| >= |b|. */
static void fast_two_sum(double a, double b, double *x, double *y)
{
    double s = a + b, bv = s - a;
    *x = s;
    *y = b - bv;
}

/* The exact difference a - b of two doubles as an expansion. */
static void difference(double a, double b, expansion *out)
{
    double x, y;
    two_diff(a, b, &x, &y);
    out->count = 0;
    if (y != 0.0) out->term[out->count++] = y;
    if (x != 0.0 || out->count == 0) out->term[out->count++] = x;
}

/* h = e + b (Shewchuk's Grow-Expansion, zero terms dropped). h may be e. */
static void grow(const expansion *e, double b, expansion *h)
{
    double q = b;
    int n = 0;
    for (int i = 0; i < e->count; ++i) {
        double sum, err;
        two_sum(q, e->term[i], &sum, &err);
        q = sum;
        if (err != 0.0) h->term[n++] = err;
    }
    if (q != 0.0 || n == 0) h->term[n++] = q;
    h->count = n;
}

/* h = e + f, one term of f at a time (rare: only the filter's failures
 * come here, so the simple quadratic sum will do). h must not be e or f. */
static void sum(const expansion *e, const expansion *f, expansion *h)
{
    *h = *e;
    for (int i = 0; i < f->count; ++i) grow(h, f->term[i], h);
}

/* h = e b (Shewchuk's Scale-Expansion, zero terms dropped). */
static void scale(const expansion *e, double b, expansion *h)
{
    double q, err, p1, p0, s;
    int n = 0;
    two_product(e->term[0], b, &q, &err);
    if (err != 0.0) h->term[n++] = err;
    for (int i = 1; i < e->count; ++i) {
        two_product(e->term[i], b, &p1, &p0);
        two_sum(q, p0, &s, &err);
        if (err != 0.0) h->term[n++] = err;
        fast_two_sum(p1, s, &q, &err);
        if (err != 0.0) h->term[n++] = err;
    }
    if (q != 0.0 || n == 0) h->term[n++] = q;
    h->count = n;
}

/* h = e f. */
static void product(const expansion *e, const expansion *f, expansion *h)
{
    expansion part, total;
    h->count = 1, h->term[0] = 0.0;
    for (int i = 0; i < f->count; ++i) {
        scale(e, f->term[i], &part);
        sum(h, &part, &total);
        *h = total;
    }
}

static void negate(expansion *e)
{
    for (int i = 0; i < e->count; ++i) e->term[i] = -e->term[i];
}

/* The sign of an expansion: that of its largest term. */
static int sign_of(const expansion *e)
{
    double top = e->term[e->count - 1];
    return top > 0.0 ? 1 : top < 0.0 ? -1 : 0;
}

/* e = a b - c d, exactly. */
static void cross_term(const expansion *a, const expansion *b, const expansion *c, const expansion *d,
                       expansion *e)
{
    expansion ab, cd;
    product(a, b, &ab);
    product(c, d, &cd);
    negate(&cd);
    sum(&ab, &cd, e);
}

/* ------------------------------------------------------------------------ */
/* Predicates                                                               */
/* ------------------------------------------------------------------------ */

static int orient3d_exact(const double a[3], const double b[3], const double c[3], const double d[3])
{
    expansion u[3], v[3], w[3], m, t0, t1, t2, s01, det;
    for (int k = 0; k < 3; ++k) {
        difference(b[k], a[k], &u[k]);
        difference(c[k], a[k], &v[k]);
        difference(d[k], a[k], &w[k]);
    }
    /* u . (v x w) */
    cross_term(&v[1], &w[2], &v[2], &w[1], &m);
    product(&u[0], &m, &t0);
    cross_term(&v[2], &w[0], &v[0], &w[2], &m);
    product(&u[1], &m, &t1);
    cross_term(&v[0], &w[1], &v[1], &w[0], &m);
    product(&u[2], &m, &t2);
    sum(&t0, &t1, &s01);
    sum(&s01, &t2, &det);
    return sign_of(&det);
}

int wci_orient3d(const double a[3], const double b[3], const double c[3], const double d[3])
{
    double u[3], v[3], w[3];
    for (int k = 0; k < 3; ++k) u[k] = b[k] - a[k], v[k] = c[k] - a[k], w[k] = d[k] - a[k];
    double x0 = v[1] * w[2], x1 = v[2] * w[1], y0 = v[2] * w[0], y1 = v[0] * w[2];
    double z0 = v[0] * w[1], z1 = v[1] * w[0];
    double det = u[0] * (x0 - x1) + u[1] * (y0 - y1) + u[2] * (z0 - z1);
    double permanent = fabs(u[0]) * (fabs(x0) + fabs(x1)) + fabs(u[1]) * (fabs(y0) + fabs(y1)) +
                       fabs(u[2]) * (fabs(z0) + fabs(z1));
    double bound = ORIENT3D_BOUND * permanent;
    if (det > bound) return 1;
    if (det < -bound) return -1;
    /* every product rounded to zero: with no underflow, each had a zero
     * factor, and a difference of doubles rounds to zero only when it is
     * zero (a flat sheet lying in a coordinate plane comes here) */
    if (permanent == 0.0) return 0;
    return orient3d_exact(a, b, c, d);
}

static int orient2d_exact(const double a[2], const double b[2], const double c[2])
{
    expansion u[2], v[2], det;
    for (int k = 0; k < 2; ++k) {
        difference(b[k], a[k], &u[k]);
        difference(c[k], a[k], &v[k]);
    }
    cross_term(&u[0], &v[1], &u[1], &v[0], &det);
    return sign_of(&det);
}

int wci_orient2d(const double a[2], const double b[2], const double c[2])
{
    double l = (b[0] - a[0]) * (c[1] - a[1]), r = (b[1] - a[1]) * (c[0] - a[0]);
    double det = l - r, bound = ORIENT2D_BOUND * (fabs(l) + fabs(r));
    if (det > bound) return 1;
    if (det < -bound) return -1;
    if (l == 0.0 && r == 0.0) return 0; /* as in wci_orient3d */
    return orient2d_exact(a, b, c);
}
