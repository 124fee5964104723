/* Convex colliders (convex.c): ball penetration against closed forms for
 * every shape (chosen positions on faces, edges and corners, then random
 * positions), a random hull against brute-force facets, the swept resolve
 * of fast particles, triangle tests, poses, validation messages, and paths
 * with coordinates anywhere in the doubles (infinite and NaN included). */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "convex.h"
#include "test_util.h"
#include "wetcloth.h"

/* Penetration depths must match the closed forms this closely (the spec's
 * bar is 1e-6 m; the implementation is exact to rounding, so the test holds
 * it to 1e-12 m on shapes of size ~1 m). */
#define DEPTH_TOL 1e-12

/* PI is not C99. */
#define PI 3.14159265358979323846

/* Deterministic random numbers (64-bit LCG), uniform in [lo, hi). */
static uint64_t rng_state = 0x9E3779B97F4A7C15ull;
static double uniform(double lo, double hi)
{
    rng_state = rng_state * 6364136223846793005ull + 1442695040888963407ull;
    return lo + (hi - lo) * (double)(rng_state >> 11) * (1.0 / 9007199254740992.0);
}

static double dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static double len(const double a[3]) { return sqrt(dot(a, a)); }

static wc_convex_shape make(const wc_convex_collider_def *d)
{
    wc_convex_shape s;
    wc_pose p;
    wc_message m = {{0}};
    wc_status st = wci_convex_shape_create(&s, &p, d, &m);
    CHECK(st == WC_OK, "wci_convex_shape_create: %s", m.text);
    return s;
}

static wc_convex_collider_def sphere_def(double radius)
{
    wc_convex_collider_def d = wc_convex_collider_def_default();
    d.shape = WC_SHAPE_SPHERE;
    d.radius = radius;
    return d;
}

static wc_convex_collider_def capsule_def(double radius, double half_height)
{
    wc_convex_collider_def d = wc_convex_collider_def_default();
    d.shape = WC_SHAPE_CAPSULE;
    d.radius = radius;
    d.half_height = half_height;
    return d;
}

static wc_convex_collider_def box_def(double hx, double hy, double hz)
{
    wc_convex_collider_def d = wc_convex_collider_def_default();
    d.shape = WC_SHAPE_BOX;
    d.half_extents[0] = hx, d.half_extents[1] = hy, d.half_extents[2] = hz;
    return d;
}

static double cube_points[24];
static const double octa_points[18] = {1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1};

static wc_convex_collider_def hull_def(const double *points, int32_t count)
{
    wc_convex_collider_def d = wc_convex_collider_def_default();
    d.shape = WC_SHAPE_CONVEX_HULL;
    d.points = points;
    d.point_count = count;
    return d;
}

/* ---- closed-form signed distances (independent of the library) ---- */

static double sd_sphere(double radius, const double c[3]) { return len(c) - radius; }

static double sd_capsule(double radius, double hh, const double c[3])
{
    double z = c[2] > hh ? hh : c[2] < -hh ? -hh : c[2];
    double d[3] = {c[0], c[1], c[2] - z};
    return len(d) - radius;
}

static double sd_box(const double h[3], const double c[3])
{
    double out = 0.0, in = -INFINITY;
    for (int k = 0; k < 3; ++k) {
        double q = fabs(c[k]) - h[k];
        if (q > 0) out += q * q;
        if (q > in) in = q;
    }
    return out > 0 ? sqrt(out) : in;
}

/* Exact distance to the octahedron |x| + |y| + |z| <= 1 (after Inigo
 * Quilez's derivation). */
static double sd_octahedron(const double c[3])
{
    double p[3] = {fabs(c[0]), fabs(c[1]), fabs(c[2])}, q[3];
    double m = p[0] + p[1] + p[2] - 1.0;
    if (3.0 * p[0] < m) q[0] = p[0], q[1] = p[1], q[2] = p[2];
    else if (3.0 * p[1] < m) q[0] = p[1], q[1] = p[2], q[2] = p[0];
    else if (3.0 * p[2] < m) q[0] = p[2], q[1] = p[0], q[2] = p[1];
    else return m / sqrt(3.0);
    double k = 0.5 * (q[2] - q[1] + 1.0);
    k = k < 0 ? 0 : k > 1 ? 1 : k;
    double d[3] = {q[0], q[1] - 1.0 + k, q[2] - k};
    return len(d);
}

/* Checks one ball against an expected depth and outward normal (normal NULL:
 * only the depth and that moving out lands at distance r). */
static void check_ball(const wc_convex_shape *s, const char *what, double x, double y, double z,
                       double r, double expect_depth, const double *expect_normal)
{
    double c[3] = {x, y, z}, depth = -1, dir[3] = {0, 0, 0};
    int hit = wci_convex_penetration(s, c, r, &depth, dir);
    if (expect_depth <= 0) {
        CHECK(!hit, "%s at (%g, %g, %g) r %g: contact reported (depth %g), none expected", what, x,
              y, z, r, depth);
        return;
    }
    CHECK(hit, "%s at (%g, %g, %g) r %g: no contact, expected depth %.17g", what, x, y, z, r,
          expect_depth);
    if (!hit) return;
    CHECK(fabs(depth - expect_depth) <= DEPTH_TOL, "%s at (%g, %g, %g) r %g: depth %.17g, expected %.17g (error %.3g)",
          what, x, y, z, r, depth, expect_depth, depth - expect_depth);
    CHECK(fabs(len(dir) - 1.0) < 1e-12, "%s: direction not unit (%g)", what, len(dir));
    if (expect_normal) {
        /* dir points into the shape: the outward normal is -dir */
        double e = fabs(-dir[0] - expect_normal[0]) + fabs(-dir[1] - expect_normal[1]) +
                   fabs(-dir[2] - expect_normal[2]);
        CHECK(e < 1e-9, "%s at (%g, %g, %g): normal (%g, %g, %g), expected (%g, %g, %g)", what, x, y,
              z, -dir[0], -dir[1], -dir[2], expect_normal[0], expect_normal[1], expect_normal[2]);
    }
}

static void test_sphere_points(void)
{
    wc_convex_collider_def d = sphere_def(0.5);
    wc_convex_shape s = make(&d);
    CHECK(fabs(s.bound_radius - 0.5) < 1e-15, "sphere bound radius %g", s.bound_radius);
    double up[3] = {0, 0, 1};
    check_ball(&s, "sphere top", 0, 0, 0.52, 0.05, 0.03, up);
    check_ball(&s, "sphere inside", 0, 0, 0.3, 0.05, 0.25, up);
    double c[3] = {0.3, -0.2, 0.35};
    double n[3] = {c[0] / len(c), c[1] / len(c), c[2] / len(c)};
    check_ball(&s, "sphere oblique", c[0], c[1], c[2], 0.1, 0.6 - len(c), n);
    check_ball(&s, "sphere clear", 0.3, 0.3, 0.3, 0.01, 0, NULL);
    check_ball(&s, "sphere far", 10, 0, 0, 0.01, 0, NULL);
    /* at the very centre any direction is right; the depth is r + radius */
    check_ball(&s, "sphere centre", 0, 0, 0, 0.05, 0.55, NULL);
    wci_convex_shape_destroy(&s);
}

static void test_capsule_points(void)
{
    wc_convex_collider_def d = capsule_def(0.2, 0.4);
    wc_convex_shape s = make(&d);
    double x[3] = {1, 0, 0}, up[3] = {0, 0, 1};
    check_ball(&s, "capsule side", 0.22, 0, 0.1, 0.05, 0.03, x);
    check_ball(&s, "capsule cap", 0, 0, 0.62, 0.05, 0.03, up);
    double c[3] = {0.1, 0.1, 0.5}, cc[3] = {0.1, 0.1, 0.1};
    double n[3] = {cc[0] / len(cc), cc[1] / len(cc), cc[2] / len(cc)};
    check_ball(&s, "capsule cap edge", c[0], c[1], c[2], 0.05, 0.25 - len(cc), n);
    check_ball(&s, "capsule inside", 0.15, 0, -0.3, 0.05, 0.1, x);
    check_ball(&s, "capsule clear", 0.3, 0, 0, 0.05, 0, NULL);
    check_ball(&s, "capsule beyond the cap", 0, 0, 0.7, 0.05, 0, NULL);
    wci_convex_shape_destroy(&s);
}

/* Box and cube hull share the same cases (a cube of half size 0.5). */
static void check_cube(const wc_convex_shape *s, const char *what)
{
    double up[3] = {0, 0, 1}, x[3] = {1, 0, 0};
    double edge[3] = {sqrt(0.5), 0, sqrt(0.5)}, corner[3] = {1 / sqrt(3), 1 / sqrt(3), 1 / sqrt(3)};
    char name[96];
    snprintf(name, sizeof name, "%s face", what);
    check_ball(s, name, 0.1, 0.2, 0.53, 0.05, 0.02, up);
    snprintf(name, sizeof name, "%s face near its edge", what);
    check_ball(s, name, 0.49, 0.2, 0.53, 0.05, 0.02, up);
    snprintf(name, sizeof name, "%s face, centre inside", what);
    check_ball(s, name, 0.1, -0.3, 0.48, 0.05, 0.07, up);
    snprintf(name, sizeof name, "%s side face, centre inside", what);
    check_ball(s, name, 0.45, 0.1, 0.3, 0.05, 0.1, x);
    snprintf(name, sizeof name, "%s edge", what);
    check_ball(s, name, 0.52, 0.1, 0.52, 0.05, 0.05 - 0.02 * sqrt(2.0), edge);
    snprintf(name, sizeof name, "%s corner", what);
    check_ball(s, name, 0.52, 0.52, 0.52, 0.05, 0.05 - 0.02 * sqrt(3.0), corner);
    snprintf(name, sizeof name, "%s off-diagonal edge", what);
    {
        /* closest point on the edge x = z = 0.5: distance sqrt(0.03^2 + 0.01^2) */
        double n[3] = {0.03, 0, 0.01}, l = len(n);
        for (int k = 0; k < 3; ++k) n[k] /= l;
        check_ball(s, name, 0.53, -0.2, 0.51, 0.05, 0.05 - l, n);
    }
    snprintf(name, sizeof name, "%s clear of the corner", what);
    check_ball(s, name, 0.54, 0.54, 0.54, 0.05, 0, NULL);
    snprintf(name, sizeof name, "%s deep, nearest face below", what);
    check_ball(s, name, 0.2, 0.1, -0.4, 0.05, 0.15, (double[3]){0, 0, -1});
}

static void test_box_points(void)
{
    wc_convex_collider_def d = box_def(0.5, 0.5, 0.5);
    wc_convex_shape s = make(&d);
    CHECK(fabs(s.bound_radius - sqrt(0.75)) < 1e-15, "box bound radius %g", s.bound_radius);
    check_cube(&s, "box");
    wci_convex_shape_destroy(&s);
    d = hull_def(cube_points, 8);
    s = make(&d);
    check_cube(&s, "cube hull");
    wci_convex_shape_destroy(&s);

    /* A long thin plate: plain MPR measures along the ray from the centre,
     * which here leaves through the far end (0.9 m off); the exact answer is
     * the bottom face right under the ball. */
    d = box_def(1.0, 0.5, 0.05);
    s = make(&d);
    check_ball(&s, "plate under its end", 0.79, 0.17, -0.06, 0.03, 0.02, (double[3]){0, 0, -1});
    check_ball(&s, "plate inside near its end", 0.9, 0.0, 0.03, 0.01, 0.03, (double[3]){0, 0, 1});
    wci_convex_shape_destroy(&s);
}

static void test_octahedron_points(void)
{
    wc_convex_collider_def d = hull_def(octa_points, 6);
    wc_convex_shape s = make(&d);
    double n[3] = {1 / sqrt(3), 1 / sqrt(3), 1 / sqrt(3)};
    /* on the face's axis, 0.02 outside the face plane */
    double f = 1 / 3.0 + 0.02 / sqrt(3);
    check_ball(&s, "octahedron face", f, f, f, 0.05, 0.03, n);
    check_ball(&s, "octahedron inside", 0.2, 0.2, 0.2, 0.05, 0.05 + (1 - 0.6) / sqrt(3), n);
    /* beyond the apex (0, 0, 1) along z: the apex is nearest */
    check_ball(&s, "octahedron apex", 0, 0, 1.03, 0.05, 0.02, (double[3]){0, 0, 1});
    check_ball(&s, "octahedron clear", 0, 0, 1.06, 0.05, 0, NULL);
    wci_convex_shape_destroy(&s);
}

/* Random positions near each shape against the closed forms; the pushed-out
 * ball must sit at distance r. Also: no contact reported where the closed
 * form says clear. */
static void sweep_random(const char *what, const wc_convex_shape *s, double (*sd)(const wc_convex_shape *, const double *),
                         int count)
{
    double worst = 0, worst_push = 0;
    int contacts = 0, wrong = 0;
    for (int i = 0; i < count; ++i) {
        double c[3] = {uniform(-1.3, 1.3), uniform(-1.3, 1.3), uniform(-1.3, 1.3)};
        double r = uniform(0.005, 0.12);
        double expect = r - sd(s, c), depth = 0, dir[3];
        int hit = wci_convex_penetration(s, c, r, &depth, dir);
        if (fabs(expect) < 1e-9) continue; /* touching: either answer is right */
        if ((expect > 0) != (hit != 0)) {
            if (wrong++ < 3)
                CHECK(0, "%s at (%.17g, %.17g, %.17g) r %.17g: contact %d, expected depth %g", what, c[0],
                      c[1], c[2], r, hit, expect);
            continue;
        }
        if (!hit) continue;
        ++contacts;
        double e = fabs(depth - expect);
        if (e > worst) worst = e;
        double q[3] = {c[0] - depth * dir[0], c[1] - depth * dir[1], c[2] - depth * dir[2]};
        double p = fabs(sd(s, q) - r);
        if (p > worst_push) worst_push = p;
    }
    CHECK(wrong == 0, "%s: %d contact decisions wrong", what, wrong);
    CHECK(contacts > count / 100, "%s: only %d contacts in %d samples", what, contacts, count);
    CHECK(worst <= DEPTH_TOL, "%s: worst depth error %.3g over %d contacts", what, worst, contacts);
    CHECK(worst_push <= DEPTH_TOL, "%s: pushed-out balls off distance r by up to %.3g", what, worst_push);
}

static double sd_of_sphere(const wc_convex_shape *s, const double *c) { return sd_sphere(s->radius, c); }
static double sd_of_capsule(const wc_convex_shape *s, const double *c) { return sd_capsule(s->radius, s->half_height, c); }
static double sd_of_box(const wc_convex_shape *s, const double *c) { return sd_box(s->half_extents, c); }
static double sd_of_cube_hull(const wc_convex_shape *s, const double *c)
{
    (void)s;
    const double h[3] = {0.5, 0.5, 0.5};
    return sd_box(h, c);
}
static double sd_of_octahedron(const wc_convex_shape *s, const double *c)
{
    (void)s;
    return sd_octahedron(c);
}

static void test_random_positions(void)
{
    wc_convex_collider_def d = sphere_def(0.7);
    wc_convex_shape s = make(&d);
    sweep_random("sphere", &s, sd_of_sphere, 40000);
    wci_convex_shape_destroy(&s);
    d = capsule_def(0.3, 0.6);
    s = make(&d);
    sweep_random("capsule", &s, sd_of_capsule, 40000);
    wci_convex_shape_destroy(&s);
    d = box_def(1.0, 0.5, 0.05);
    s = make(&d);
    sweep_random("plate box", &s, sd_of_box, 40000);
    wci_convex_shape_destroy(&s);
    d = box_def(0.5, 0.5, 0.5);
    s = make(&d);
    sweep_random("cube box", &s, sd_of_box, 40000);
    wci_convex_shape_destroy(&s);
    d = hull_def(cube_points, 8);
    s = make(&d);
    sweep_random("cube hull", &s, sd_of_cube_hull, 40000);
    wci_convex_shape_destroy(&s);
    d = hull_def(octa_points, 6);
    s = make(&d);
    sweep_random("octahedron hull", &s, sd_of_octahedron, 40000);
    wci_convex_shape_destroy(&s);
}

/* ---- a random hull against brute-force facets ---- */

#define HULL_N 20
static double hull_pts[3 * (HULL_N + 10)];
static double facets[4 * 2000];
static int facet_tri[3 * 2000];
static int facet_count;

/* Closest-point distance from p to triangle (a, b, c), by Ericson's regions
 * (Real-Time Collision Detection, 5.1.5); the library's own code is a
 * different method. */
static double point_triangle_distance(const double p[3], const double a[3], const double b[3],
                                      const double c[3])
{
    double ab[3], ac[3], ap[3], bp[3], cp[3], q[3];
    for (int k = 0; k < 3; ++k) {
        ab[k] = b[k] - a[k], ac[k] = c[k] - a[k], ap[k] = p[k] - a[k];
        bp[k] = p[k] - b[k], cp[k] = p[k] - c[k];
    }
    double d1 = dot(ab, ap), d2 = dot(ac, ap), d3 = dot(ab, bp), d4 = dot(ac, bp);
    double d5 = dot(ab, cp), d6 = dot(ac, cp);
    double vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
    if (d1 <= 0 && d2 <= 0) memcpy(q, a, sizeof q);
    else if (d3 >= 0 && d4 <= d3) memcpy(q, b, sizeof q);
    else if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        double v = d1 / (d1 - d3);
        for (int k = 0; k < 3; ++k) q[k] = a[k] + v * ab[k];
    } else if (d6 >= 0 && d5 <= d6) memcpy(q, c, sizeof q);
    else if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        double w = d2 / (d2 - d6);
        for (int k = 0; k < 3; ++k) q[k] = a[k] + w * ac[k];
    } else if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
        double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        for (int k = 0; k < 3; ++k) q[k] = b[k] + w * (c[k] - b[k]);
    } else {
        double den = 1.0 / (va + vb + vc), v = vb * den, w = vc * den;
        for (int k = 0; k < 3; ++k) q[k] = a[k] + ab[k] * v + ac[k] * w;
    }
    double d[3] = {p[0] - q[0], p[1] - q[1], p[2] - q[2]};
    return len(d);
}

static void build_facets(const double *p, int n)
{
    facet_count = 0;
    for (int i = 0; i < n; ++i)
        for (int j = i + 1; j < n; ++j)
            for (int k = j + 1; k < n; ++k) {
                double e1[3], e2[3], nrm[3];
                for (int m = 0; m < 3; ++m) e1[m] = p[3 * j + m] - p[3 * i + m], e2[m] = p[3 * k + m] - p[3 * i + m];
                nrm[0] = e1[1] * e2[2] - e1[2] * e2[1];
                nrm[1] = e1[2] * e2[0] - e1[0] * e2[2];
                nrm[2] = e1[0] * e2[1] - e1[1] * e2[0];
                double l = len(nrm);
                for (int m = 0; m < 3; ++m) nrm[m] /= l;
                double off = dot(nrm, p + 3 * i);
                int above = 0, below = 0;
                for (int m = 0; m < n; ++m) {
                    double s = dot(nrm, p + 3 * m) - off;
                    if (s > 1e-12) ++above;
                    if (s < -1e-12) ++below;
                }
                if (above && below) continue;
                double sign = above ? -1.0 : 1.0;
                for (int m = 0; m < 3; ++m) facets[4 * facet_count + m] = sign * nrm[m];
                facets[4 * facet_count + 3] = sign * off;
                facet_tri[3 * facet_count] = i, facet_tri[3 * facet_count + 1] = j, facet_tri[3 * facet_count + 2] = k;
                ++facet_count;
            }
}

static double sd_random_hull(const wc_convex_shape *s, const double *c)
{
    (void)s;
    double inside = -INFINITY;
    for (int f = 0; f < facet_count; ++f) {
        double v = dot(facets + 4 * f, c) - facets[4 * f + 3];
        if (v > inside) inside = v;
    }
    if (inside <= 0) return inside;
    double best = INFINITY;
    for (int f = 0; f < facet_count; ++f) {
        const int *t = facet_tri + 3 * f;
        double d = point_triangle_distance(c, hull_pts + 3 * t[0], hull_pts + 3 * t[1], hull_pts + 3 * t[2]);
        if (d < best) best = d;
    }
    return best;
}

static void test_random_hull(void)
{
    /* Points on a sphere of radius 0.8-1.0, shifted off the origin, plus a
     * few interior points that must be ignored. */
    int n = HULL_N + 10;
    for (int i = 0; i < n; ++i) {
        double v[3];
        do {
            for (int k = 0; k < 3; ++k) v[k] = uniform(-1, 1);
        } while (len(v) < 0.3 || len(v) > 1.0);
        double r = i < HULL_N ? uniform(0.8, 1.0) : uniform(0.0, 0.3);
        double l = len(v);
        for (int k = 0; k < 3; ++k) hull_pts[3 * i + k] = v[k] / l * r + (k == 0 ? 0.15 : 0.0);
    }
    build_facets(hull_pts, n);
    CHECK(facet_count >= 2 * HULL_N - 4 - 2, "random hull: %d facets", facet_count);
    wc_convex_collider_def d = hull_def(hull_pts, n);
    wc_convex_shape s = make(&d);
    sweep_random("random hull", &s, sd_random_hull, 40000);
    wci_convex_shape_destroy(&s);
}

/* ---- moving particles ---- */

static void check_resolve(const wc_convex_shape *s, const char *what, const double a[3], const double b[3],
                          double r, const double expect[3], const double expect_normal[3], double tol)
{
    double out[3] = {7, 7, 7}, n[3] = {7, 7, 7};
    int hit = wci_convex_resolve(s, a, b, r, out, n);
    if (!expect) {
        CHECK(!hit, "%s: contact reported at (%g, %g, %g)", what, out[0], out[1], out[2]);
        CHECK(out[0] == 7 && n[0] == 7, "%s: outputs written without contact", what);
        return;
    }
    CHECK(hit, "%s: no contact", what);
    if (!hit) return;
    double e = fabs(out[0] - expect[0]) + fabs(out[1] - expect[1]) + fabs(out[2] - expect[2]);
    CHECK(e <= tol, "%s: ends at (%.12g, %.12g, %.12g), expected (%.12g, %.12g, %.12g)", what, out[0],
          out[1], out[2], expect[0], expect[1], expect[2]);
    double en = fabs(n[0] - expect_normal[0]) + fabs(n[1] - expect_normal[1]) + fabs(n[2] - expect_normal[2]);
    CHECK(en <= 1e-6, "%s: normal (%g, %g, %g), expected (%g, %g, %g)", what, n[0], n[1], n[2],
          expect_normal[0], expect_normal[1], expect_normal[2]);
    /* the result keeps exactly r from the surface */
    double depth, dir[3];
    CHECK(!wci_convex_penetration(s, out, r * (1 - 1e-9), &depth, dir), "%s: result still inside",
          what);
    CHECK(wci_convex_penetration(s, out, r * (1 + 1e-6), &depth, dir), "%s: result not on the surface",
          what);
}

static void test_resolve(void)
{
    const double r = 0.01, dt = 0.01, speed = 100.0;
    wc_convex_collider_def d = sphere_def(0.5);
    wc_convex_shape s = make(&d);
    {
        /* 100 m/s for 0.01 s: 1 m in one step, ending inside the sphere's
         * lower half, where pushing the end point out would pass it
         * through. It must stop on top instead, where it came in. */
        double a[3] = {0.05, 0.02, 0.7}, b[3] = {0.05, 0.02, 0.7 - speed * dt};
        double z = sqrt(0.51 * 0.51 - 0.05 * 0.05 - 0.02 * 0.02);
        double e[3] = {0.05, 0.02, z}, n[3] = {0.05 / 0.51, 0.02 / 0.51, z / 0.51};
        check_resolve(&s, "sphere, fast, ends inside", a, b, r, e, n, 1e-8);
        /* all the way through: the end is clear below the sphere */
        double a2[3] = {0.05, 0.02, 0.55}, b2[3] = {0.05, 0.02, 0.55 - 1.2};
        check_resolve(&s, "sphere, fast, passes through", a2, b2, r, e, n, 1e-8);
    }
    {
        /* slow: just the end point pushed out radially */
        double a[3] = {0.1, 0.0, 0.52}, b[3] = {0.1, 0.0, 0.5};
        double l = len(b), e[3] = {b[0] / l * 0.51, 0, b[2] / l * 0.51}, n[3] = {b[0] / l, 0, b[2] / l};
        check_resolve(&s, "sphere, slow", a, b, r, e, n, 1e-12);
        /* clear all the way */
        double a2[3] = {0.0, 0.6, 0.0}, b2[3] = {0.0, 0.6, 0.3};
        check_resolve(&s, "sphere, passing by", a2, b2, r, NULL, NULL, 0);
        double a3[3] = {5, 5, 5}, b3[3] = {5, 5, 6};
        check_resolve(&s, "sphere, far away", a3, b3, r, NULL, NULL, 0);
    }
    wci_convex_shape_destroy(&s);

    d = box_def(0.3, 0.3, 0.3);
    s = make(&d);
    {
        double up[3] = {0, 0, 1};
        /* ends 0.01 from the side face but 0.5 below the top: the nearest
         * face is the side, the right one the top */
        double a[3] = {0.29, 0.1, 0.8}, b[3] = {0.29, 0.1, 0.8 - speed * dt}, e[3] = {0.29, 0.1, 0.31};
        check_resolve(&s, "box, fast, ends near a side", a, b, r, e, up, 1e-8);
        double a2[3] = {0.0, -0.1, 0.6}, b2[3] = {0.0, -0.1, -0.4}, e2[3] = {0.0, -0.1, 0.31};
        check_resolve(&s, "box, fast, passes through", a2, b2, r, e2, up, 1e-8);
        /* fast but sliding along the top: the end point is pushed up and
         * keeps its sideways motion */
        double a3[3] = {-0.2, 0.0, 0.31}, b3[3] = {0.2, 0.0, 0.305}, e3[3] = {0.2, 0.0, 0.31};
        check_resolve(&s, "box, fast slide", a3, b3, r, e3, up, 1e-12);
        /* skimming over the edge, never within r/2: no contact */
        double a4[3] = {-0.5, 0.0, 0.32}, b4[3] = {0.5, 0.0, 0.32};
        check_resolve(&s, "box, skimming over", a4, b4, r, NULL, NULL, 0);
    }
    wci_convex_shape_destroy(&s);
}

/* Random motions around a box and a sphere: every contact ends exactly r
 * from the surface with the right normal; a path whose centre comes within
 * r/2 of the shape is always caught; one that never comes within r never
 * is. Minimum distances along a path are found by dense sampling. */
static void random_resolve(const char *what, const wc_convex_shape *s,
                           double (*sd)(const wc_convex_shape *, const double *), int count)
{
    int caught = 0, bad = 0;
    for (int i = 0; i < count; ++i) {
        double r = uniform(0.005, 0.05), a[3], b[3];
        do {
            for (int k = 0; k < 3; ++k) a[k] = uniform(-1.0, 1.0);
        } while (sd(s, a) <= r);
        double reach = uniform(0.001, 1.5), dir[3];
        for (int k = 0; k < 3; ++k) dir[k] = uniform(-1, 1);
        double l = len(dir);
        for (int k = 0; k < 3; ++k) b[k] = a[k] + dir[k] / l * reach;
        double closest = INFINITY;
        for (int j = 0; j <= 2000; ++j) {
            double p[3];
            for (int k = 0; k < 3; ++k) p[k] = a[k] + (b[k] - a[k]) * j / 2000.0;
            double d = sd(s, p);
            if (d < closest) closest = d;
        }
        double out[3], n[3];
        int hit = wci_convex_resolve(s, a, b, r, out, n);
        int must = closest < 0.5 * r || sd(s, b) < r * (1 - 1e-6);
        int must_not = closest > r * (1 + 1e-6);
        if ((must && !hit) || (must_not && hit)) {
            if (bad++ < 3)
                CHECK(0, "%s: a (%.17g, %.17g, %.17g) b (%.17g, %.17g, %.17g) r %.17g: contact %d, path's closest %g",
                      what, a[0], a[1], a[2], b[0], b[1], b[2], r, hit, closest);
            continue;
        }
        if (!hit) continue;
        ++caught;
        double e = fabs(sd(s, out) - r);
        double probe[3] = {out[0] + 1e-4 * n[0], out[1] + 1e-4 * n[1], out[2] + 1e-4 * n[2]};
        double slope = (sd(s, probe) - sd(s, out)) / 1e-4;
        if (e > 1e-12 || fabs(slope - 1) > 1e-6) {
            if (bad++ < 3)
                CHECK(0, "%s: a (%.17g, %.17g, %.17g) b (%.17g, %.17g, %.17g) r %.17g: ends %g off distance r, normal slope %g",
                      what, a[0], a[1], a[2], b[0], b[1], b[2], r, e, slope);
        }
    }
    CHECK(bad == 0, "%s: %d bad resolves", what, bad);
    CHECK(caught > count / 50, "%s: only %d of %d motions made contact", what, caught, count);
}

static void test_random_resolve(void)
{
    wc_convex_collider_def d = sphere_def(0.5);
    wc_convex_shape s = make(&d);
    random_resolve("sphere", &s, sd_of_sphere, 3000);
    wci_convex_shape_destroy(&s);
    d = box_def(0.4, 0.3, 0.2);
    s = make(&d);
    random_resolve("box", &s, sd_of_box, 3000);
    wci_convex_shape_destroy(&s);
    d = hull_def(octa_points, 6);
    s = make(&d);
    random_resolve("octahedron", &s, sd_of_octahedron, 3000);
    wci_convex_shape_destroy(&s);
}

/* ---- triangles ---- */

static void test_triangles(void)
{
    wc_convex_collider_def d = sphere_def(0.5);
    wc_convex_shape s = make(&d);
    wc_pose pose = {{1, 2, 3}, {1, 0, 0, 0}};
    /* a big triangle in a plane through the centre: the case MPR gets wrong */
    double a[3] = {-2, 0, 3}, b[3] = {4, -3, 3}, c[3] = {4, 6, 3};
    CHECK(wci_convex_triangle_intersects(&s, &pose, a, b, c), "triangle through the sphere's centre");
    double a2[3] = {-2, 0, 3.49}, b2[3] = {4, -3, 3.49}, c2[3] = {4, 6, 3.49};
    CHECK(wci_convex_triangle_intersects(&s, &pose, a2, b2, c2), "triangle cutting the sphere's cap");
    double a3[3] = {-2, 0, 3.51}, b3[3] = {4, -3, 3.51}, c3[3] = {4, 6, 3.51};
    CHECK(!wci_convex_triangle_intersects(&s, &pose, a3, b3, c3), "triangle above the sphere");
    /* small triangle wholly inside */
    double a4[3] = {1, 2, 3}, b4[3] = {1.1, 2, 3}, c4[3] = {1, 2.1, 3.05};
    CHECK(wci_convex_triangle_intersects(&s, &pose, a4, b4, c4), "triangle inside the sphere");
    wci_convex_shape_destroy(&s);

    /* a box turned 45 degrees about z: its corner reaches x = 0.3 sqrt 2 */
    d = box_def(0.3, 0.3, 0.3);
    s = make(&d);
    double h = sin(PI / 8), w = cos(PI / 8);
    wc_pose turned = {{0, 0, 0}, {w, 0, 0, h}};
    double x = 0.3 * sqrt(2.0);
    double t1[3] = {x - 0.001, -1, -1}, t2[3] = {x - 0.001, 1, -1}, t3[3] = {x - 0.001, 0, 1};
    CHECK(wci_convex_triangle_intersects(&s, &turned, t1, t2, t3), "triangle at the turned box's edge");
    t1[0] = t2[0] = t3[0] = x + 0.001;
    CHECK(!wci_convex_triangle_intersects(&s, &turned, t1, t2, t3), "triangle beyond the turned box");
    /* a vertex at infinity or NaN (an exploded cloth): not counted, and
     * libccd is not asked */
    double bad[3] = {0.0, 0.0, INFINITY}, o1[3] = {0, 0, 0}, o2[3] = {0.1, 0, 0};
    CHECK(!wci_convex_triangle_intersects(&s, &turned, o1, o2, bad), "triangle with an infinite vertex");
    bad[2] = NAN;
    CHECK(!wci_convex_triangle_intersects(&s, &turned, o1, o2, bad), "triangle with a NaN vertex");
    wci_convex_shape_destroy(&s);
}

/* ---- poses ---- */

static void test_poses(void)
{
    double q[4] = {0.3, -0.5, 0.7, 0.2}, l = 0;
    for (int k = 0; k < 4; ++k) l += q[k] * q[k];
    for (int k = 0; k < 4; ++k) q[k] /= sqrt(l);
    wc_pose p = {{0.5, -1.0, 2.0}, {q[0], q[1], q[2], q[3]}};
    double v[3] = {0.3, 0.4, -1.2}, w[3], back[3], rv[3];
    wci_pose_to_world(&p, v, w);
    wci_pose_to_local(&p, w, back);
    double e = fabs(back[0] - v[0]) + fabs(back[1] - v[1]) + fabs(back[2] - v[2]);
    CHECK(e < 1e-15, "to_world then to_local: off by %g", e);
    wci_pose_rotate(&p, v, rv);
    CHECK(fabs(len(rv) - len(v)) < 1e-15, "rotation changed a length: %g vs %g", len(rv), len(v));
    for (int k = 0; k < 3; ++k)
        CHECK(fabs(w[k] - (rv[k] + p.position[k])) < 1e-15, "to_world is not rotate + translate");
    /* against a rotation matrix built from the quaternion */
    double W = q[0], X = q[1], Y = q[2], Z = q[3];
    double m[3][3] = {{1 - 2 * (Y * Y + Z * Z), 2 * (X * Y - W * Z), 2 * (X * Z + W * Y)},
                      {2 * (X * Y + W * Z), 1 - 2 * (X * X + Z * Z), 2 * (Y * Z - W * X)},
                      {2 * (X * Z - W * Y), 2 * (Y * Z + W * X), 1 - 2 * (X * X + Y * Y)}};
    for (int i = 0; i < 3; ++i) {
        double mv = m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2];
        CHECK(fabs(mv - rv[i]) < 1e-15, "rotate[%d] %.17g, matrix gives %.17g", i, rv[i], mv);
    }
    /* 90 degrees about z takes x to y */
    wc_pose qz = {{0, 0, 0}, {sqrt(0.5), 0, 0, sqrt(0.5)}};
    double ex[3] = {1, 0, 0}, ey[3];
    wci_pose_rotate(&qz, ex, ey);
    CHECK(fabs(ey[0]) < 1e-15 && fabs(ey[1] - 1) < 1e-15 && fabs(ey[2]) < 1e-15,
          "90 degrees about z: (%g, %g, %g)", ey[0], ey[1], ey[2]);

    /* lerp: exact ends, midpoint, shorter arc */
    wc_pose a = {{0, 0, 0}, {1, 0, 0, 0}}, b = {{2, 4, -6}, {sqrt(0.5), 0, 0, sqrt(0.5)}}, o;
    wci_pose_lerp(&a, &b, 0.0, &o);
    CHECK(memcmp(&o, &a, sizeof o) == 0, "lerp at 0 is not a");
    wci_pose_lerp(&a, &b, 1.0, &o);
    CHECK(memcmp(&o, &b, sizeof o) == 0, "lerp at 1 is not b");
    wci_pose_lerp(&a, &b, 0.5, &o);
    CHECK(fabs(o.position[0] - 1) < 1e-15 && fabs(o.position[1] - 2) < 1e-15 && fabs(o.position[2] + 3) < 1e-15,
          "lerp midpoint position (%g, %g, %g)", o.position[0], o.position[1], o.position[2]);
    /* nlerp halfway between 0 and 90 degrees about z is 45 degrees */
    CHECK(fabs(o.rotation[0] - cos(PI / 8)) < 1e-15 && fabs(o.rotation[3] - sin(PI / 8)) < 1e-15,
          "lerp midpoint rotation (%g, %g, %g, %g)", o.rotation[0], o.rotation[1], o.rotation[2],
          o.rotation[3]);
    /* the same target written as -q: still the short way, same result */
    wc_pose nb = b;
    for (int k = 0; k < 4; ++k) nb.rotation[k] = -b.rotation[k];
    wc_pose o2;
    wci_pose_lerp(&a, &nb, 0.5, &o2);
    double r1[3], r2[3];
    wci_pose_rotate(&o, ex, r1);
    wci_pose_rotate(&o2, ex, r2);
    CHECK(fabs(r1[0] - r2[0]) < 1e-15 && fabs(r1[1] - r2[1]) < 1e-15,
          "lerp toward -q took the long way: (%g, %g) vs (%g, %g)", r2[0], r2[1], r1[0], r1[1]);
    double ql = 0;
    for (int k = 0; k < 4; ++k) ql += o2.rotation[k] * o2.rotation[k];
    CHECK(fabs(ql - 1) < 1e-15, "lerp rotation not unit: %g", ql);
}

/* ---- validation ---- */

static void expect_invalid(const wc_convex_collider_def *d, const char *needle, const char *what)
{
    wc_convex_shape s;
    wc_pose p;
    wc_message m = {{0}};
    wc_status st = wci_convex_shape_create(&s, &p, d, &m);
    CHECK(st == WC_ERROR_INVALID_ARGUMENT, "%s: status %s", what, wc_status_name(st));
    CHECK(strstr(m.text, needle) != NULL, "%s: message \"%s\" does not name \"%s\"", what, m.text, needle);
    CHECK(s.points == NULL, "%s: points allocated on failure", what);
    wci_convex_shape_destroy(&s);
}

static void test_validation(void)
{
    double nan = NAN;
    wc_convex_collider_def d = sphere_def(0.5);
    d.shape = (wc_shape)7;
    expect_invalid(&d, "shape", "bad shape");
    d = sphere_def(0.5);
    d.position[1] = INFINITY;
    expect_invalid(&d, "position[1]", "infinite position");
    d = sphere_def(0.5);
    d.rotation[0] = 0;
    expect_invalid(&d, "rotation", "zero quaternion");
    d = sphere_def(0.5);
    d.rotation[2] = nan;
    expect_invalid(&d, "rotation[2]", "nan quaternion");
    d = sphere_def(0.0);
    expect_invalid(&d, "radius", "zero radius");
    d = sphere_def(2e6);
    expect_invalid(&d, "radius", "huge radius");
    d = capsule_def(-0.1, 0.2);
    expect_invalid(&d, "radius", "negative capsule radius");
    d = capsule_def(0.1, -0.2);
    expect_invalid(&d, "half_height", "negative half height");
    d = capsule_def(0.1, nan);
    expect_invalid(&d, "half_height", "nan half height");
    d = box_def(0.1, 0.0, 0.1);
    expect_invalid(&d, "half_extents[1]", "flat box");
    d = box_def(0.1, 0.1, nan);
    expect_invalid(&d, "half_extents[2]", "nan box");
    d = hull_def(NULL, 8);
    expect_invalid(&d, "points", "NULL points");
    d = hull_def(cube_points, 3);
    expect_invalid(&d, "point_count", "too few points");
    d = hull_def(cube_points, 70000);
    expect_invalid(&d, "point_count", "too many points");
    double bad[24];
    memcpy(bad, cube_points, sizeof bad);
    bad[3 * 7 + 1] = nan;
    d = hull_def(bad, 8);
    expect_invalid(&d, "points[7] y is nan", "nan hull point");
    double flat[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 0.5, 0.3, 1e-14};
    d = hull_def(flat, 5);
    expect_invalid(&d, "span a volume", "flat hull");
    double line[12] = {0, 0, 0, 1, 1, 1, 2, 2, 2, 3, 3, 3};
    d = hull_def(line, 4);
    expect_invalid(&d, "span a volume", "hull on a line");
    double same[12] = {1, 2, 3, 1, 2, 3, 1, 2, 3, 1, 2, 3};
    d = hull_def(same, 4);
    expect_invalid(&d, "span a volume", "hull of one point");
    d = sphere_def(0.5);
    d.thickness = 1.5;
    expect_invalid(&d, "thickness", "thick");
    d = sphere_def(0.5);
    d.friction = -1;
    expect_invalid(&d, "friction", "negative friction");
    d = sphere_def(0.5);
    d.friction = nan;
    expect_invalid(&d, "friction", "nan friction");
    expect_invalid(NULL, "NULL", "NULL def");

    /* fields of other shapes are not looked at */
    d = sphere_def(0.5);
    d.half_extents[0] = nan;
    d.half_height = -1;
    d.points = NULL;
    d.point_count = 0;
    wc_convex_shape s;
    wc_pose p;
    wc_message m = {{0}};
    CHECK(wci_convex_shape_create(&s, &p, &d, &m) == WC_OK, "sphere with junk box fields: %s", m.text);
    wci_convex_shape_destroy(&s);

    /* a good hull: points copied, rotation normalised, bound radius */
    d = hull_def(octa_points, 6);
    d.rotation[0] = 2.0;
    d.position[2] = 3.0;
    CHECK(wci_convex_shape_create(&s, &p, &d, &m) == WC_OK, "octahedron: %s", m.text);
    CHECK(s.points != octa_points && s.points && memcmp(s.points, octa_points, sizeof octa_points) == 0,
          "hull points not copied");
    CHECK(p.rotation[0] == 1.0 && p.position[2] == 3.0, "pose not normalised/copied");
    CHECK(fabs(s.bound_radius - 1.0) < 1e-15, "octahedron bound radius %g", s.bound_radius);
    wci_convex_shape_destroy(&s);
    CHECK(s.points == NULL, "free left the points");
}

/* An exploded cloth's particle moving from ~1e72 m to ~2e81 m in one step
 * on a line that passes within reach of a capsule (the coordinates of a
 * fuzz input that timed out): libccd's MPR, asked whether that path meets
 * the capsule, turned forever on rounding. Checked: wci_convex_resolve
 * returns (without the fix this test hangs until ctest's timeout), and
 * what it gives is finite. */
static void test_exploded_path(void)
{
    wc_convex_collider_def d = wc_convex_collider_def_default();
    d.shape = WC_SHAPE_CAPSULE;
    d.radius = d.half_height = 0.5;
    wc_convex_shape s = make(&d);
    const double a[3] = {1.1527361862470264e+72, -8.5614729931985079e+71, -8.1971527105887753e+70};
    const double b[3] = {-2.3567254664727314e+81, 1.7503607221076334e+81, 1.6758768203942447e+80};
    double out[3] = {0, 0, 0}, n[3] = {0, 0, 0};
    if (wci_convex_resolve(&s, a, b, 0.005, out, n))
        for (int k = 0; k < 3; ++k)
            CHECK(isfinite(out[k]) && isfinite(n[k]), "exploded path: non-finite result");
    wci_convex_shape_destroy(&s);
}

/* A particle whose end position, taken into a hull's frame, overflowed to
 * infinity (the coordinates of a fuzz input that crashed: the first contact
 * bisected that path and handed libccd's EPA an infinite point, which read
 * through NULL). Checked: no contact is reported for the infinite end; an
 * end inside the hull after a path too long for a double is still pushed
 * out onto the surface; a finite end far away after such a path is left
 * alone. */
static void test_overflowing_path(void)
{
    static const double pts[18] = {-0.2, -0.2, -0.2, -0.2,    -0.2,     0, -0.2, 0.2, -0.2,
                                   0.2,  0.2,  0,    -0.00625, -0.40625, 0, -0.2, -0.2, 0};
    wc_convex_collider_def d = hull_def(pts, 6);
    wc_convex_shape s = make(&d);
    double r = 0x1.47ae147ae147bp-8, out[3] = {0, 0, 0}, n[3] = {0, 0, 0};
    const double a[3] = {-0x1p-2, -0x1p-2, 0.0};
    const double b[3] = {-0x1.1ccf385ebc89fp+1023, -0x1p+971, INFINITY};
    CHECK(!wci_convex_resolve(&s, a, b, r, out, n), "infinite end reported as a contact");
    /* from ~1.5e308 m away into the hull, 0.05 m under its top face z = 0 */
    const double far[3] = {-1.5e308, 0.0, -1.5e308}, inside[3] = {-0.1, -0.15, -0.05};
    CHECK(wci_convex_resolve(&s, far, inside, r, out, n), "end inside the hull not pushed out");
    double depth = 0.0, dir[3];
    CHECK(isfinite(out[0]) && isfinite(out[1]) && isfinite(out[2]), "pushed-out end not finite");
    CHECK(!wci_convex_penetration(&s, out, r * (1.0 - 1e-9), &depth, dir),
          "pushed-out end still inside by %g", depth);
    const double gone[3] = {1.5e308, 0.0, 1.5e308};
    CHECK(!wci_convex_resolve(&s, far, gone, r, out, n), "far path with a far end reported as a contact");
    wci_convex_shape_destroy(&s);
}

/* A coordinate anywhere in the doubles: near the shape, far, enormous,
 * infinite or NaN, with either sign. */
static double extreme_coordinate(void)
{
    double u = uniform(0.0, 1.0), sign = uniform(0.0, 1.0) < 0.5 ? -1.0 : 1.0;
    if (u < 0.4) return uniform(-2.0, 2.0);
    if (u < 0.8) return sign * pow(10.0, uniform(-300.0, 308.0));
    if (u < 0.9) return sign * 1.7976931348623157e308;
    return u < 0.95 ? sign * INFINITY : NAN;
}

/* wci_convex_resolve and wci_convex_penetration on paths and points from
 * extreme_coordinate, against every kind of shape: libccd is never handed
 * something it cannot take (the sanitizer build would see a bad read, as it
 * did for the overflowing path above), and whatever is returned is finite:
 * a position on the surface and a unit normal. */
static void test_extreme_inputs(void)
{
    wc_convex_collider_def defs[4] = {sphere_def(0.4), capsule_def(0.2, 0.3), box_def(0.3, 0.2, 0.1),
                                      hull_def(octa_points, 6)};
    int hits = 0, bad = 0;
    for (int d = 0; d < 4; ++d) {
        wc_convex_shape s = make(&defs[d]);
        for (int trial = 0; trial < 3000; ++trial) {
            double a[3], b[3], out[3], n[3], depth, dir[3];
            for (int k = 0; k < 3; ++k) a[k] = extreme_coordinate(), b[k] = extreme_coordinate();
            if (trial % 3 == 0) memcpy(a, b, sizeof a);
            if (wci_convex_resolve(&s, a, b, 0.005, out, n)) {
                ++hits;
                bad += !(isfinite(out[0]) && isfinite(out[1]) && isfinite(out[2]) && fabs(len(n) - 1.0) < 1e-9);
            }
            if (wci_convex_penetration(&s, b, 0.005, &depth, dir))
                bad += !(isfinite(depth) && depth > 0.0 && fabs(len(dir) - 1.0) < 1e-9);
        }
        wci_convex_shape_destroy(&s);
    }
    printf("extreme inputs: 12000 paths, %d contacts, %d with a non-finite or non-unit answer\n", hits,
           bad);
    CHECK(bad == 0, "%d answers not finite", bad);
    CHECK(hits > 100, "only %d of the paths touched a shape: the test is not testing", hits);
}

int main(void)
{
    test_exploded_path();
    test_extreme_inputs();
    test_overflowing_path();
    for (int i = 0; i < 8; ++i)
        for (int k = 0; k < 3; ++k) cube_points[3 * i + k] = (i >> k) & 1 ? 0.5 : -0.5;
    test_sphere_points();
    test_capsule_points();
    test_box_points();
    test_octahedron_points();
    test_random_positions();
    test_random_hull();
    test_resolve();
    test_random_resolve();
    test_triangles();
    test_poses();
    test_validation();
    return test_report("test_convex");
}
