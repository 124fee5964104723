/* Solid convex colliders through libccd (SPEC 2, "Convex colliders through
 * libccd").
 *
 * A particle is a ball. The spec asks for its penetration from libccd's
 * MPR, but MPR's depth is not the smallest penetration: MPR measures along
 * the ray from the interior point it is given (the shape's centre) through
 * the ball's centre. Measured on Debian's libccd 2.1 against closed forms,
 * ball radii 0.01-0.11 m, 2e5 random positions per shape: exact for a
 * sphere (3e-16 m), but off by up to 0.14 m for a capsule (radius 0.3,
 * half height 0.6), 0.9 m for a 2 x 1 x 0.1 m box and 0.09 m for an
 * octahedron hull, whatever mpr_tolerance (1e-6 to 1e-15): near edges,
 * corners and the ends of long shapes the ray leaves through another face.
 * The point it moves the ball to is on the surface, just not the nearest.
 * Re-aiming MPR along the direction it returned does not converge either
 * (its portal settles on a chamfer across the edge).
 *
 * So the penetration is computed exactly instead, still from the shapes'
 * support functions: every shape is a core inflated by a radius (sphere: a
 * point; capsule: a segment; box and hull: themselves, radius 0), and the
 * ball's penetration is r + radius - distance(centre, core). The distance
 * comes from a small GJK (libccd 2.1 exposes no distance query); a centre
 * inside a box or hull gets its nearest face from libccd's EPA, exact for
 * polyhedra. Measured: within 2e-16 m of the closed forms (1.7e-14 m for
 * the hull's pushed-out positions) on the same 2e5 positions. libccd's MPR
 * still answers the yes/no question of a swept particle (capsule) meeting
 * the shape, and GJK the triangle test of the intersection checker. Flat
 * triangles never go through MPR (NOTES: MPR is wrong for them). */
#include "convex.h"

#include <ccd/ccd.h>
#include <math.h>
#include <string.h>

#include "alloc.h"
#include "primitives.h"
#include "status.h"

/* Limits of the description (wetcloth.h). */
#define MAX_LENGTH 1e6
#define MIN_HULL_POINTS 4
#define MAX_HULL_POINTS 65536

/* libccd's tolerances as a fraction of the problem's size (the shape's
 * bounding radius plus the ball's): far below the contact threshold, above
 * the rounding of coordinates of that size. */
#define MPR_TOLERANCE 1e-13
/* Safety caps. libccd's portal refinement has no iteration limit of its own;
 * a support-call budget (see shape_support) ends any call that runs away
 * on rounding, and the call's result is then discarded. */
#define MPR_MAX_ITERATIONS 200
/* Largest distance from the shape, as a multiple of its size, at which MPR
 * is asked anything (see sweep_hits). A particle this far out has moved a
 * million shape sizes in one step. */
#define MPR_LARGEST_PROBLEM 1e6
#define SUPPORT_BUDGET 4000
/* Penetrations below this fraction of the problem's size count as touching,
 * not contact: a ball just put back at distance r must not be found in
 * contact again by rounding (that would make every resting particle a
 * contact each pass). */
#define CONTACT_EPS 1e-10
/* First-contact search: interval on the segment's parameter. */
#define FIRST_CONTACT_TOL 1e-9
/* A far point returned by an exhausted support function: large enough to
 * end every libccd loop, small enough that libccd's triple products of
 * such points stay finite. */
#define FAR_AWAY 1e60

/* ------------------------------------------------------------------------ */
/* Small vector helpers                                                      */
/* ------------------------------------------------------------------------ */

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross3(const double a[3], const double b[3], double out[3])
{
    double x = a[1] * b[2] - a[2] * b[1];
    double y = a[2] * b[0] - a[0] * b[2];
    double z = a[0] * b[1] - a[1] * b[0];
    out[0] = x, out[1] = y, out[2] = z;
}

static double norm3(const double a[3]) { return sqrt(dot3(a, a)); }

/* ------------------------------------------------------------------------ */
/* Poses                                                                     */
/* ------------------------------------------------------------------------ */

/* Rotation of v by the unit quaternion (w, x, y, z), or by its inverse when
 * `inverse` is set: v + 2w (q x v) + 2 q x (q x v), the form that needs no
 * matrix and keeps rotate-then-unrotate within a few ulps. */
static void quat_rotate(const double q[4], int inverse, const double v[3], double out[3])
{
    double u[3] = {q[1], q[2], q[3]};
    if (inverse) u[0] = -u[0], u[1] = -u[1], u[2] = -u[2];
    double t[3], ut[3];
    cross3(u, v, t);
    for (int k = 0; k < 3; ++k) t[k] *= 2.0;
    cross3(u, t, ut);
    for (int k = 0; k < 3; ++k) out[k] = v[k] + q[0] * t[k] + ut[k];
}

void wci_pose_rotate(const wc_pose *pose, const double v[3], double out[3])
{
    quat_rotate(pose->rotation, 0, v, out);
}

void wci_pose_to_world(const wc_pose *pose, const double local[3], double world[3])
{
    double r[3];
    quat_rotate(pose->rotation, 0, local, r);
    for (int k = 0; k < 3; ++k) world[k] = pose->position[k] + r[k];
}

void wci_pose_to_local(const wc_pose *pose, const double world[3], double local[3])
{
    double d[3];
    for (int k = 0; k < 3; ++k) d[k] = world[k] - pose->position[k];
    quat_rotate(pose->rotation, 1, d, local);
}

void wci_pose_lerp(const wc_pose *a, const wc_pose *b, double t, wc_pose *out)
{
    /* The ends are returned bit for bit, so a collider that stops moving
     * ends exactly at its target. */
    if (t <= 0.0) {
        *out = *a;
        return;
    }
    if (t >= 1.0) {
        *out = *b;
        return;
    }
    wc_pose r;
    for (int k = 0; k < 3; ++k) r.position[k] = wc_lerp(a->position[k], b->position[k], t);
    /* q and -q are the same rotation: blend toward whichever of them is
     * nearer, so the interpolation takes the shorter arc. */
    double d = 0.0;
    for (int k = 0; k < 4; ++k) d += a->rotation[k] * b->rotation[k];
    double sign = d < 0.0 ? -1.0 : 1.0, len = 0.0;
    for (int k = 0; k < 4; ++k) {
        r.rotation[k] = (1.0 - t) * a->rotation[k] + t * sign * b->rotation[k];
        len += r.rotation[k] * r.rotation[k];
    }
    /* both unit and at most 90 degrees apart in 4D: len >= 0.5 */
    len = sqrt(len);
    for (int k = 0; k < 4; ++k) r.rotation[k] /= len;
    *out = r;
}

/* ------------------------------------------------------------------------ */
/* Validation and set-up                                                     */
/* ------------------------------------------------------------------------ */

static wc_status check_length(wc_message *msg, const char *field, double value, int zero_ok)
{
    int ok = isfinite(value) && value <= MAX_LENGTH && (zero_ok ? value >= 0.0 : value > 0.0);
    if (ok) return WC_OK;
    return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT, "convex_collider_def.%s must be in %s0, 1e6] m but is %g",
                   field, zero_ok ? "[" : "(", value);
}

/* Whether the hull points span a volume: a large tetrahedron is built
 * greedily (farthest point from the first, farthest from that line,
 * farthest from that plane); its volume relative to the cube of the
 * extent must not vanish. Greedy is within a constant factor of the
 * largest tetrahedron, which is all a flatness test needs. */
static int hull_has_volume(const double *p, int32_t n)
{
    double ext = 0.0, area = 0.0, vol = 0.0, e1[3], e2[3], nrm[3];
    int32_t i1 = 0, i2 = 0;
    for (int32_t i = 1; i < n; ++i) {
        double d[3] = {p[3 * i] - p[0], p[3 * i + 1] - p[1], p[3 * i + 2] - p[2]};
        double l = norm3(d);
        if (l > ext) ext = l, i1 = i;
    }
    if (!(ext > 0.0)) return 0;
    for (int k = 0; k < 3; ++k) e1[k] = p[3 * i1 + k] - p[k];
    for (int32_t i = 1; i < n; ++i) {
        double d[3] = {p[3 * i] - p[0], p[3 * i + 1] - p[1], p[3 * i + 2] - p[2]}, c[3];
        cross3(e1, d, c);
        double a = norm3(c);
        if (a > area) area = a, i2 = i;
    }
    if (!(area > 1e-12 * ext * ext)) return 0;
    for (int k = 0; k < 3; ++k) e2[k] = p[3 * i2 + k] - p[k];
    cross3(e1, e2, nrm);
    for (int32_t i = 1; i < n; ++i) {
        double d[3] = {p[3 * i] - p[0], p[3 * i + 1] - p[1], p[3 * i + 2] - p[2]};
        double v = fabs(dot3(nrm, d));
        if (v > vol) vol = v;
    }
    /* |det| is six times the tetrahedron's volume */
    return vol / 6.0 > 1e-12 * ext * ext * ext;
}

wc_status wci_convex_shape_create(wc_convex_shape *shape, wc_pose *pose,
                               const wc_convex_collider_def *def, wc_message *msg)
{
    memset(shape, 0, sizeof *shape);
    if (!def)
        return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT, "convex_collider_def is NULL");
    if (def->shape != WC_SHAPE_SPHERE && def->shape != WC_SHAPE_CAPSULE &&
        def->shape != WC_SHAPE_BOX && def->shape != WC_SHAPE_CONVEX_HULL)
        return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                       "convex_collider_def.shape must be WC_SHAPE_SPHERE (0), WC_SHAPE_CAPSULE (1), "
                       "WC_SHAPE_BOX (2) or WC_SHAPE_CONVEX_HULL (3) but is %d",
                       (int)def->shape);
    for (int k = 0; k < 3; ++k)
        if (!isfinite(def->position[k]))
            return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                           "convex_collider_def.position[%d] must be finite but is %g", k,
                           def->position[k]);
    double qn = 0.0;
    for (int k = 0; k < 4; ++k) {
        if (!isfinite(def->rotation[k]))
            return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                           "convex_collider_def.rotation[%d] must be finite but is %g", k,
                           def->rotation[k]);
        qn += def->rotation[k] * def->rotation[k];
    }
    qn = sqrt(qn);
    if (!(qn > 1e-12) || !isfinite(qn))
        return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                       "convex_collider_def.rotation must be a non-zero quaternion (w, x, y, z) but "
                       "has norm %g",
                       qn);
    wc_status s = WC_OK;
    switch (def->shape) {
    case WC_SHAPE_SPHERE: s = check_length(msg, "radius", def->radius, 0); break;
    case WC_SHAPE_CAPSULE:
        s = check_length(msg, "radius", def->radius, 0);
        if (!s) s = check_length(msg, "half_height", def->half_height, 1);
        break;
    case WC_SHAPE_BOX:
        for (int k = 0; k < 3 && !s; ++k) {
            char field[32] = "half_extents[0]";
            field[13] = (char)('0' + k);
            s = check_length(msg, field, def->half_extents[k], 0);
        }
        break;
    case WC_SHAPE_CONVEX_HULL:
        if (def->point_count < MIN_HULL_POINTS || def->point_count > MAX_HULL_POINTS)
            return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                           "convex_collider_def.point_count must be in [%d, %d] but is %d",
                           MIN_HULL_POINTS, MAX_HULL_POINTS, (int)def->point_count);
        if (!def->points)
            return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                           "convex_collider_def.points is NULL (point_count is %d)",
                           (int)def->point_count);
        for (int32_t i = 0; i < def->point_count; ++i)
            for (int k = 0; k < 3; ++k) {
                double v = def->points[3 * i + k];
                if (!isfinite(v) || fabs(v) > MAX_LENGTH)
                    return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                                   "convex_collider_def.points[%d] %c is %g; coordinates must be "
                                   "finite and within 1e6 m",
                                   (int)i, "xyz"[k], v);
            }
        if (!hull_has_volume(def->points, def->point_count))
            return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                           "convex_collider_def.points must span a volume, but the %d points lie "
                           "in one plane (or line)",
                           (int)def->point_count);
        break;
    }
    if (s) return s;
    if (!(isfinite(def->thickness) && def->thickness >= 0.0 && def->thickness <= 1.0))
        return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                       "convex_collider_def.thickness must be in [0, 1] m but is %g", def->thickness);
    if (!(isfinite(def->friction) && def->friction >= 0.0 && def->friction <= 10.0))
        return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                       "convex_collider_def.friction must be in [0, 10] but is %g", def->friction);

    shape->shape = def->shape;
    switch (def->shape) {
    case WC_SHAPE_SPHERE:
        shape->radius = def->radius;
        shape->bound_radius = def->radius;
        break;
    case WC_SHAPE_CAPSULE:
        shape->radius = def->radius;
        shape->half_height = def->half_height;
        shape->bound_radius = def->radius + def->half_height;
        break;
    case WC_SHAPE_BOX:
        for (int k = 0; k < 3; ++k) shape->half_extents[k] = def->half_extents[k];
        shape->bound_radius = norm3(def->half_extents);
        break;
    case WC_SHAPE_CONVEX_HULL: {
        size_t n = (size_t)def->point_count;
        shape->points = wci_alloc_array(3 * n, sizeof *shape->points);
        if (!shape->points)
            return wci_fail(msg, WC_ERROR_OUT_OF_MEMORY,
                           "out of memory copying %d convex hull points", (int)def->point_count);
        memcpy(shape->points, def->points, 3 * n * sizeof *shape->points);
        shape->point_count = def->point_count;
        double b = 0.0;
        for (size_t i = 0; i < n; ++i) {
            double l = norm3(shape->points + 3 * i);
            if (l > b) b = l;
        }
        shape->bound_radius = b;
        break;
    }
    }
    for (int k = 0; k < 3; ++k) pose->position[k] = def->position[k];
    for (int k = 0; k < 4; ++k) pose->rotation[k] = def->rotation[k] / qn;
    return WC_OK;
}

void wci_convex_shape_destroy(wc_convex_shape *shape)
{
    if (!shape) return;
    wci_free(shape->points);
    shape->points = NULL;
    shape->point_count = 0;
}

/* ------------------------------------------------------------------------ */
/* Support functions for libccd (local frame)                                */
/* ------------------------------------------------------------------------ */

/* The shape as libccd sees it: its geometry, the interior point MPR starts
 * from, and the support-call budget. libccd passes objects as const void *;
 * the budget is counted through a cast, which is well defined because every
 * shape_obj lives in a non-const local variable of this file. */
typedef struct shape_obj {
    const wc_convex_shape *shape;
    double center[3];
    long calls;
    long budget; /* support calls allowed, SUPPORT_BUDGET or less */
} shape_obj;

/* EPA inside a box or hull. Its polytope gains a vertex per support call
 * and each iteration scans all its faces (libccd's ccdPtNearest), so a call
 * that runs on rounding to the full SUPPORT_BUDGET costs ~budget^2: ~10 ms
 * each, and a fuzz input with a degenerate hull took 5 s of a 12-step run
 * in ccdPtNearest. The polytope's vertices are points of the shape (a box
 * has 8), so past GJK's iterations and a few per vertex there is nothing
 * new to find: that is the budget. */
static long epa_budget(const wc_convex_shape *s)
{
    long vertices = s->shape == WC_SHAPE_BOX ? 8 : (long)s->point_count;
    long budget = MPR_MAX_ITERATIONS + 64 + 4 * vertices;
    return budget < SUPPORT_BUDGET ? budget : SUPPORT_BUDGET;
}

/* A ball (the particle), a segment swept by a ball (the particle over a
 * step), a point, or a triangle: object 1 of every libccd call here. */
typedef struct probe_obj {
    double a[3], b[3], c[3];
    /* 1 point/ball at a, 2 segment a-b, 3 triangle a-b-c */
    int kind;
    double radius;
    double center[3];
} probe_obj;

static void shape_support(const void *obj, const ccd_vec3_t *dir, ccd_vec3_t *out)
{
    shape_obj *so = (shape_obj *)obj;
    const wc_convex_shape *s = so->shape;
    const double *d = dir->v;
    double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (++so->calls > so->budget) {
        /* A point far behind the direction asked for (libccd then sees no
         * progress and leaves whatever loop it is in); the caller sees the
         * exhausted budget and drops the result. */
        for (int k = 0; k < 3; ++k) out->v[k] = len > 0.0 ? -FAR_AWAY * d[k] / len : -FAR_AWAY;
        return;
    }
    switch (s->shape) {
    case WC_SHAPE_SPHERE:
    case WC_SHAPE_CAPSULE: {
        double k = len > 0.0 ? s->radius / len : 0.0;
        for (int i = 0; i < 3; ++i) out->v[i] = d[i] * k;
        if (s->shape == WC_SHAPE_CAPSULE) out->v[2] += d[2] >= 0.0 ? s->half_height : -s->half_height;
        break;
    }
    case WC_SHAPE_BOX:
        for (int i = 0; i < 3; ++i) out->v[i] = d[i] >= 0.0 ? s->half_extents[i] : -s->half_extents[i];
        break;
    case WC_SHAPE_CONVEX_HULL: {
        const double *p = s->points;
        int32_t best = 0;
        double best_dot = p[0] * d[0] + p[1] * d[1] + p[2] * d[2];
        for (int32_t i = 1; i < s->point_count; ++i) {
            double v = p[3 * i] * d[0] + p[3 * i + 1] * d[1] + p[3 * i + 2] * d[2];
            if (v > best_dot) best_dot = v, best = i;
        }
        for (int i = 0; i < 3; ++i) out->v[i] = p[3 * best + i];
        break;
    }
    }
}

static void shape_center(const void *obj, ccd_vec3_t *out)
{
    const shape_obj *so = obj;
    for (int k = 0; k < 3; ++k) out->v[k] = so->center[k];
}

static void probe_support(const void *obj, const ccd_vec3_t *dir, ccd_vec3_t *out)
{
    const probe_obj *p = obj;
    const double *d = dir->v;
    const double *best = p->a;
    if (p->kind >= 2) {
        double da = dot3(p->a, d), db = dot3(p->b, d);
        if (db > da) best = p->b, da = db;
        if (p->kind == 3 && dot3(p->c, d) > da) best = p->c;
    }
    double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    double k = len > 0.0 ? p->radius / len : 0.0;
    for (int i = 0; i < 3; ++i) out->v[i] = best[i] + d[i] * k;
}

static void probe_center(const void *obj, ccd_vec3_t *out)
{
    const probe_obj *p = obj;
    for (int k = 0; k < 3; ++k) out->v[k] = p->center[k];
}

/* A point strictly inside the shape: its origin, except for a hull, whose
 * points need not surround the origin; the mean of the points is inside the
 * hull's interior because they span a volume. */
static void interior_point(const wc_convex_shape *s, double out[3])
{
    out[0] = out[1] = out[2] = 0.0;
    if (s->shape != WC_SHAPE_CONVEX_HULL) return;
    for (int32_t i = 0; i < s->point_count; ++i)
        for (int k = 0; k < 3; ++k) out[k] += s->points[3 * i + k];
    for (int k = 0; k < 3; ++k) out[k] /= (double)s->point_count;
}

static void init_ccd(ccd_t *ccd, double scale)
{
    CCD_INIT(ccd);
    ccd->support1 = probe_support;
    ccd->support2 = shape_support;
    ccd->center1 = probe_center;
    ccd->center2 = shape_center;
    ccd->max_iterations = MPR_MAX_ITERATIONS;
    ccd->mpr_tolerance = MPR_TOLERANCE * scale;
    ccd->epa_tolerance = MPR_TOLERANCE * scale;
    ccd->dist_tolerance = MPR_TOLERANCE * scale;
}

static void ball_probe(probe_obj *p, const double c[3], double r)
{
    memset(p, 0, sizeof *p);
    p->kind = 1;
    p->radius = r;
    memcpy(p->a, c, sizeof p->a);
    memcpy(p->center, c, sizeof p->center);
}

/* What libccd's penetration call (status rc) gave: 1 with depth and unit
 * direction when it found a contact within the shape's support budget, 0
 * otherwise. A touching contact (depth 0) comes without a direction, and
 * a direction much shorter than unit means libccd had none to give. */
static int penetration_found(int rc, const shape_obj *so, ccd_real_t d, const ccd_vec3_t *v,
                             double *depth, double dir[3])
{
    if (rc != 0 || so->calls > so->budget) return 0;
    double len = sqrt(v->v[0] * v->v[0] + v->v[1] * v->v[1] + v->v[2] * v->v[2]);
    if (!isfinite(d) || !(d > 0.0) || !(len > 0.5)) return 0;
    *depth = d;
    for (int k = 0; k < 3; ++k) dir[k] = v->v[k] / len;
    return 1;
}

/* One MPR call: ball (c, r) against the whole shape, from its interior
 * point. Returns 1 with depth and direction on contact, 0 otherwise
 * (including a call that ran out of budget or produced something
 * non-finite). Used where the closest-point search below has no direction
 * to give: a ball centred exactly on a sphere's centre or a capsule's axis. */
static int mpr_ball(const wc_convex_shape *s, const double c[3], double r, double scale,
                    double *depth, double dir[3])
{
    probe_obj ball;
    ball_probe(&ball, c, r);
    shape_obj so = {s, {0.0, 0.0, 0.0}, 0, SUPPORT_BUDGET};
    interior_point(s, so.center);
    ccd_t ccd;
    init_ccd(&ccd, scale);
    ccd_real_t d = 0.0;
    ccd_vec3_t v, pos;
    int rc = ccdMPRPenetration(&ball, &so, &ccd, &d, &v, &pos);
    return penetration_found(rc, &so, d, &v, depth, dir);
}

/* Penetration of the point c into a box or hull that holds it, from
 * libccd's EPA, exact for polyhedra (measured: 0 error on 10^5 points).
 * Writes the distance to the nearest face and the direction from c away
 * from it, MPR's convention (c must move by -depth * dir to get out). */
static int epa_point(const wc_convex_shape *s, const double c[3], double scale, double *depth,
                     double dir[3])
{
    probe_obj pt;
    ball_probe(&pt, c, 0.0);
    shape_obj so = {s, {0.0, 0.0, 0.0}, 0, epa_budget(s)};
    interior_point(s, so.center);
    ccd_t ccd;
    init_ccd(&ccd, scale);
    ccd_real_t d = 0.0;
    ccd_vec3_t v, pos;
    int rc = ccdGJKPenetration(&pt, &so, &ccd, &d, &v, &pos);
    return penetration_found(rc, &so, d, &v, depth, dir);
}

/* ---- Closest point of the shape's core to a point (GJK) ----
 *
 * Every shape is a core inflated by a radius: a sphere is a point inflated
 * by its radius, a capsule a segment, a box and a hull themselves
 * (radius 0). A ball of radius r touches the shape when its centre is
 * closer than r + radius to the core, so the exact penetration is
 * r + radius - distance(c, core), along the line to the closest point.
 * libccd 2.1 has no GJK distance query (only intersection and EPA
 * penetration), so the few lines of Gilbert-Johnson-Keerthi below find the
 * closest point from the same support functions. */

static double core_radius(const wc_convex_shape *s)
{
    return s->shape == WC_SHAPE_SPHERE || s->shape == WC_SHAPE_CAPSULE ? s->radius : 0.0;
}

static void core_support(const wc_convex_shape *s, const double d[3], double out[3])
{
    switch (s->shape) {
    case WC_SHAPE_SPHERE: out[0] = out[1] = out[2] = 0.0; break;
    case WC_SHAPE_CAPSULE:
        out[0] = out[1] = 0.0;
        out[2] = d[2] >= 0.0 ? s->half_height : -s->half_height;
        break;
    case WC_SHAPE_BOX:
        for (int k = 0; k < 3; ++k) out[k] = d[k] >= 0.0 ? s->half_extents[k] : -s->half_extents[k];
        break;
    case WC_SHAPE_CONVEX_HULL: {
        const double *p = s->points;
        int32_t best = 0;
        double best_dot = dot3(p, d);
        for (int32_t i = 1; i < s->point_count; ++i) {
            double v = dot3(p + 3 * i, d);
            if (v > best_dot) best_dot = v, best = i;
        }
        memcpy(out, p + 3 * best, 3 * sizeof *out);
        break;
    }
    }
}

/* Up to four points of the core, relative to the query point. */
typedef struct simplex {
    double p[4][3];
    int n;
} simplex;

static void keep_vertices(simplex *s, int mask)
{
    int n = 0;
    for (int i = 0; i < s->n; ++i)
        if (mask & (1 << i)) {
            if (n != i) memcpy(s->p[n], s->p[i], sizeof s->p[n]);
            ++n;
        }
    s->n = n;
}

/* Closest point to the origin of segment (a, b): writes it and returns the
 * mask of the vertices (bit 0 a, bit 1 b) whose hull holds it. */
static int closest_on_segment(const double a[3], const double b[3], double v[3])
{
    double ab[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double len2 = dot3(ab, ab), t = len2 > 0.0 ? -dot3(a, ab) / len2 : 0.0;
    if (!(t > 0.0)) {
        memcpy(v, a, 3 * sizeof *v);
        return 1;
    }
    if (t >= 1.0) {
        memcpy(v, b, 3 * sizeof *v);
        return 2;
    }
    for (int k = 0; k < 3; ++k) v[k] = a[k] + t * ab[k];
    return 3;
}

/* Closest point to the origin of triangle (a, b, c); mask as above (bits
 * 0, 1, 2). Interior: the origin's projection has positive barycentric
 * weights; otherwise the nearest edge wins. A triangle too thin for its
 * normal to mean anything is treated as its edges. */
static int closest_on_triangle(const double a[3], const double b[3], const double c[3], double v[3])
{
    double ab[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double ac[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]}, n[3], t[3];
    cross3(ab, ac, n);
    double nn = dot3(n, n);
    if (nn > 1e-24 * dot3(ab, ab) * dot3(ac, ac)) {
        cross3(b, c, t);
        double wa = dot3(t, n);
        cross3(c, a, t);
        double wb = dot3(t, n);
        cross3(a, b, t);
        double wc = dot3(t, n);
        if (wa >= 0.0 && wb >= 0.0 && wc >= 0.0) {
            double k = dot3(a, n) / nn;
            for (int i = 0; i < 3; ++i) v[i] = n[i] * k;
            return 7;
        }
    }
    static const int edges[3][2] = {{0, 1}, {0, 2}, {1, 2}};
    const double *pts[3] = {a, b, c};
    double best = INFINITY;
    int best_mask = 1;
    for (int e = 0; e < 3; ++e) {
        double w[3];
        int m = closest_on_segment(pts[edges[e][0]], pts[edges[e][1]], w);
        double d = dot3(w, w);
        if (d < best) {
            best = d;
            memcpy(v, w, sizeof w);
            best_mask = ((m & 1) ? 1 << edges[e][0] : 0) | ((m & 2) ? 1 << edges[e][1] : 0);
        }
    }
    return best_mask;
}

/* Reduces the simplex to the smallest face holding its point closest to
 * the origin and writes that point. Returns 1 when the origin is inside the
 * (non-flat) tetrahedron: the query point is inside the core. */
static int simplex_closest(simplex *s, double v[3])
{
    int mask;
    if (s->n == 1) {
        memcpy(v, s->p[0], 3 * sizeof *v);
        return 0;
    }
    if (s->n == 2) {
        mask = closest_on_segment(s->p[0], s->p[1], v);
    } else if (s->n == 3) {
        mask = closest_on_triangle(s->p[0], s->p[1], s->p[2], v);
    } else {
        /* Tetrahedron: the origin is inside when it lies on the same side
         * of every face as the opposite vertex. */
        static const int faces[4][4] = {{1, 2, 3, 0}, {0, 2, 3, 1}, {0, 1, 3, 2}, {0, 1, 2, 3}};
        double e1[3], e2[3], e3[3], n[3];
        for (int k = 0; k < 3; ++k) {
            e1[k] = s->p[1][k] - s->p[0][k];
            e2[k] = s->p[2][k] - s->p[0][k];
            e3[k] = s->p[3][k] - s->p[0][k];
        }
        cross3(e1, e2, n);
        double vol = dot3(n, e3);
        double size = norm3(e1) * norm3(e2) * norm3(e3);
        int outside_any = 0;
        double best = INFINITY;
        mask = 0;
        for (int f = 0; f < 4; ++f) {
            const double *a = s->p[faces[f][0]], *b = s->p[faces[f][1]], *c = s->p[faces[f][2]];
            const double *o = s->p[faces[f][3]];
            double ab[3], ac[3], ao[3], fn[3];
            for (int k = 0; k < 3; ++k) ab[k] = b[k] - a[k], ac[k] = c[k] - a[k], ao[k] = o[k] - a[k];
            cross3(ab, ac, fn);
            /* signs of the origin and of the opposite vertex */
            double so = -dot3(fn, a), sv = dot3(fn, ao);
            int origin_out = fabs(vol) <= 1e-12 * size || so * sv <= 0.0;
            if (!origin_out) continue;
            outside_any = 1;
            double w[3];
            int m = closest_on_triangle(a, b, c, w);
            double d = dot3(w, w);
            if (d < best) {
                best = d;
                memcpy(v, w, sizeof w);
                mask = 0;
                for (int i = 0; i < 3; ++i)
                    if (m & (1 << i)) mask |= 1 << faces[f][i];
            }
        }
        if (!outside_any) return 1;
    }
    keep_vertices(s, mask);
    return 0;
}

/* Distance from c to the core. Returns 1 and writes the distance and the
 * closest point when c is outside the core (distance > 0), 0 when c is
 * inside it or on it. */
static int core_distance(const wc_convex_shape *s, const double c[3], double scale, double *dist,
                         double closest[3])
{
    simplex sx;
    double v[3], w[3], d[3], center[3];
    interior_point(s, center);
    /* Start with the support toward c: near the answer for most queries. */
    for (int k = 0; k < 3; ++k) d[k] = c[k] - center[k];
    core_support(s, d, w);
    for (int k = 0; k < 3; ++k) v[k] = w[k] - c[k];
    memcpy(sx.p[0], v, sizeof v);
    sx.n = 1;
    double tiny = 1e-14 * scale;
    for (int iter = 0; iter < 64; ++iter) {
        double vv = dot3(v, v);
        if (vv <= tiny * tiny) return 0;
        double nv[3] = {-v[0], -v[1], -v[2]};
        core_support(s, nv, w);
        for (int k = 0; k < 3; ++k) w[k] -= c[k];
        /* The support toward c gains (almost) nothing over v: v is the
         * closest point, to a relative 1e-13 of the distance. */
        if (vv - dot3(v, w) <= 1e-13 * vv) break;
        int repeat = 0;
        for (int i = 0; i < sx.n; ++i)
            if (w[0] == sx.p[i][0] && w[1] == sx.p[i][1] && w[2] == sx.p[i][2]) repeat = 1;
        if (repeat) break;
        simplex before = sx;
        memcpy(sx.p[sx.n], w, sizeof w);
        ++sx.n;
        double v2[3];
        if (simplex_closest(&sx, v2)) return 0;
        /* rounding can stall the descent; the last point stands then */
        if (dot3(v2, v2) >= vv) {
            sx = before;
            break;
        }
        memcpy(v, v2, sizeof v);
    }
    double len = norm3(v);
    if (!(len > tiny)) return 0;
    *dist = len;
    for (int k = 0; k < 3; ++k) closest[k] = c[k] + v[k];
    return 1;
}

static double scale_of(const wc_convex_shape *s, double r) { return s->bound_radius + r; }

/* Penetration of ball (c, r), without the contact threshold: 1 with
 * depth > 0 and dir (from c into the shape). */
static int penetration_raw(const wc_convex_shape *s, const double c[3], double r, double *depth,
                           double dir[3])
{
    double scale = scale_of(s, r);
    double reach = s->bound_radius + r;
    if (!(dot3(c, c) <= reach * reach)) return 0;
    double reach_core = r + core_radius(s), dist, q[3];
    if (core_distance(s, c, scale, &dist, q)) {
        if (!(dist < reach_core)) return 0;
        *depth = reach_core - dist;
        for (int k = 0; k < 3; ++k) dir[k] = (q[k] - c[k]) / dist;
        return 1;
    }
    /* c inside a box or hull: EPA finds its nearest face. c on a sphere's
     * centre or a capsule's axis (or EPA failing on a face): any direction
     * away from the core is right and MPR gives one. */
    double d;
    if (core_radius(s) == 0.0 && epa_point(s, c, scale, &d, dir)) {
        *depth = reach_core + d;
        return 1;
    }
    return mpr_ball(s, c, r, scale, depth, dir);
}

int wci_convex_penetration(const wc_convex_shape *shape, const double c[3], double r, double *depth,
                          double dir[3])
{
    double d, v[3];
    if (!penetration_raw(shape, c, r, &d, v)) return 0;
    if (!(d > CONTACT_EPS * scale_of(shape, r))) return 0;
    *depth = d;
    memcpy(dir, v, sizeof v);
    return 1;
}

/* ------------------------------------------------------------------------ */
/* Moving particles                                                          */
/* ------------------------------------------------------------------------ */

/* Whether the ball of radius r swept from p to q overlaps the shape.
 *
 * MPR's arithmetic needs the problem near the shape's size: libccd's portal
 * loop has no iteration cap, and with a path ~1e80 times the shape (an
 * exploded cloth moving 1e81 m in a step, found by fuzzing) rounding keeps
 * it turning forever, past the support budget's far point. A path that long
 * which the caller has already seen pass within reach of the shape (its
 * bounding-ball test) counts as a hit; first_contact's bisection then finds
 * where it enters, with bounded work. */
static int sweep_hits(const wc_convex_shape *s, const double p[3], const double q[3], double r)
{
    if (!(fmax(norm3(p), norm3(q)) <= MPR_LARGEST_PROBLEM * scale_of(s, r))) return 1;
    probe_obj cap;
    memset(&cap, 0, sizeof cap);
    cap.kind = 2;
    cap.radius = r;
    for (int k = 0; k < 3; ++k) {
        cap.a[k] = p[k];
        cap.b[k] = q[k];
        cap.center[k] = 0.5 * (p[k] + q[k]);
    }
    shape_obj so = {s, {0.0, 0.0, 0.0}, 0, SUPPORT_BUDGET};
    interior_point(s, so.center);
    ccd_t ccd;
    init_ccd(&ccd, scale_of(s, r) + norm3(p));
    int hit = ccdMPRIntersect(&cap, &so, &ccd);
    return so.calls > so.budget ? 0 : hit;
}

/* Distance from the origin to segment a-b. */
static double segment_origin_distance(const double a[3], const double b[3])
{
    double d[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double dd = dot3(d, d), t = 0.0;
    if (dd > 0.0) {
        t = -dot3(a, d) / dd;
        t = t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t;
    }
    double p[3] = {a[0] + t * d[0], a[1] + t * d[1], a[2] + t * d[2]};
    return norm3(p);
}

static void point_at(const double a[3], const double b[3], double t, double out[3])
{
    for (int k = 0; k < 3; ++k) out[k] = a[k] + (b[k] - a[k]) * t;
}

/* Puts a ball at p (that touches the shape or nearly does) at distance r
 * from the surface and gives the outward normal there. The probe radius is
 * grown by `slack` so that a ball just short of contact still yields a
 * direction; the push is for radius r. Returns 0 if no direction came. */
static int place_on_surface(const wc_convex_shape *s, const double p[3], double r, double slack,
                            double out[3], double normal[3])
{
    double d, v[3];
    if (!penetration_raw(s, p, r + slack, &d, v)) return 0;
    double push = d - slack; /* r - signed distance of p */
    for (int k = 0; k < 3; ++k) {
        out[k] = p[k] - push * v[k];
        normal[k] = -v[k];
    }
    return 1;
}

/* Earliest t in [0, 1] at which the ball on a-b touches the shape, given
 * that the ball at a does not and the sweep does: bisection on swept
 * sub-segments [0, t] (each test asks whether any point before t touches),
 * so the first contact is found even when later parts of the path are
 * deeper or leave the shape again. */
static double first_contact(const wc_convex_shape *s, const double a[3], const double b[3], double r)
{
    double lo = 0.0, hi = 1.0, p[3];
    while (hi - lo > FIRST_CONTACT_TOL) {
        double mid = 0.5 * (lo + hi);
        point_at(a, b, mid, p);
        if (sweep_hits(s, a, p, r)) hi = mid;
        else lo = mid;
    }
    return hi;
}

int wci_convex_resolve(const wc_convex_shape *shape, const double a[3], const double b[3], double r,
                      double out[3], double normal[3])
{
    /* Cheapest test first: the path never comes within r of the shape's
     * bounding ball. Every particle near a collider asks every step. */
    if (segment_origin_distance(a, b) > shape->bound_radius + r) return 0;
    double scale = scale_of(shape, r);
    double db = 0.0, vb[3] = {0.0, 0.0, 0.0};
    int in_b = wci_convex_penetration(shape, b, r, &db, vb);
    double ab[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double len = norm3(ab);
    /* A particle that moves less than r in the step cannot pass through
     * anything: the distance to the surface changes by at most the motion,
     * so its path never gets deeper than half its motion beyond where it
     * ends or starts. Only faster ones need the sweep. */
    /* A path whose length overflows (a coordinate near the double range or
     * infinite, as an exploded cloth's can be once taken into the shape's
     * frame) is not swept: bisecting it would hand libccd infinities, and
     * its EPA reads through a NULL pointer on those (found by fuzzing).
     * Such a particle has moved more than ~1e154 m in one step; only where
     * it ends is checked. */
    if (len > r && isfinite(len)) {
        double da, va[3];
        int in_a = wci_convex_penetration(shape, a, r, &da, va);
        /* The sweep with half the radius asks whether the path really went
         * through: grazing chords over a curved surface (a sliding particle
         * dips in by len^2 / 8R) are not collisions. */
        if (!in_a && (in_b || sweep_hits(shape, a, b, 0.5 * r))) {
            double t = first_contact(shape, a, b, r), p[3], q[3], nq[3];
            point_at(a, b, t, p);
            double slack = 2.0 * FIRST_CONTACT_TOL * len + CONTACT_EPS * scale;
            if (place_on_surface(shape, p, r, slack, q, nq)) {
                /* Where the particle ends up inside the shape near where it
                 * came in, pushing its end point out keeps its sliding
                 * motion; where that would take it out through another side
                 * (it went past the middle, or past an edge), it stops at
                 * its first contact instead. */
                if (in_b && -dot3(vb, nq) > 0.5) {
                    for (int k = 0; k < 3; ++k) {
                        out[k] = b[k] - db * vb[k];
                        normal[k] = -vb[k];
                    }
                } else {
                    memcpy(out, q, 3 * sizeof *out);
                    memcpy(normal, nq, 3 * sizeof *normal);
                }
                return 1;
            }
        }
    }
    if (!in_b) return 0;
    for (int k = 0; k < 3; ++k) {
        out[k] = b[k] - db * vb[k];
        normal[k] = -vb[k];
    }
    return 1;
}

/* ------------------------------------------------------------------------ */
/* Triangles (for the intersection checker)                                  */
/* ------------------------------------------------------------------------ */

int wci_convex_triangle_intersects(const wc_convex_shape *shape, const wc_pose *pose,
                                  const double a[3], const double b[3], const double c[3])
{
    probe_obj tri;
    memset(&tri, 0, sizeof tri);
    tri.kind = 3;
    wci_pose_to_local(pose, a, tri.a);
    wci_pose_to_local(pose, b, tri.b);
    wci_pose_to_local(pose, c, tri.c);
    /* Cheap rejection: the triangle's box misses the bounding ball. */
    double gap2 = 0.0, far = 0.0;
    for (int k = 0; k < 3; ++k) {
        double lo = fmin(tri.a[k], fmin(tri.b[k], tri.c[k]));
        double hi = fmax(tri.a[k], fmax(tri.b[k], tri.c[k]));
        double g = lo > 0.0 ? lo : hi < 0.0 ? -hi : 0.0;
        gap2 += g * g;
        far = fmax(far, fmax(fabs(lo), fabs(hi)));
        tri.center[k] = (tri.a[k] + tri.b[k] + tri.c[k]) / 3.0;
    }
    if (gap2 > shape->bound_radius * shape->bound_radius) return 0;
    /* A vertex that is not finite in the shape's frame (or a triangle so
     * large its centre overflows) gets no answer from libccd, only
     * infinities inside GJK, as wci_convex_resolve's overflowing paths did
     * inside EPA: it is not counted. */
    for (int k = 0; k < 3; ++k)
        if (!isfinite(tri.center[k])) return 0;
    shape_obj so = {shape, {0.0, 0.0, 0.0}, 0, SUPPORT_BUDGET};
    interior_point(shape, so.center);
    ccd_t ccd;
    init_ccd(&ccd, shape->bound_radius + far);
    /* GJK, not MPR: MPR is unreliable for flat objects (NOTES). */
    int hit = ccdGJKIntersect(&tri, &so, &ccd);
    return so.calls > so.budget ? 0 : hit;
}
