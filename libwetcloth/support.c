#include "support.h"

#include <math.h>
#include <string.h>

#include "alloc.h"
#include "narrowphase.h"
#include "primitives.h"
#include "vec3.h"

/* Deep enough for any tree wci_bvh_create builds (it stops splitting at
 * depth 94): a depth-first walk holds at most one pending node per level. */
#define WALK_STACK 128
/* The reaches are measured up to CAP_R r + CAP_EDGE longest_edge: room for
 * what a held particle needs (wci_support_holds: its distance from t, about
 * r, and r, and the longest edge) and a motion of half r plus half the
 * longest edge over the step (a particle falling at 3 m/s moves 10 mm, half
 * of Blender's collider thickness, in a step of 1/288 s). The walk's cost
 * grows with the square of the cap on a dense collider. */
#define CAP_R 2.5
#define CAP_EDGE 1.5

void wci_support_destroy(wc_support *s)
{
    wci_free(s->reach);
    memset(s, 0, sizeof *s);
}

int wci_support_ready(const wc_support *s, const wc_collider *c, double r)
{
    return s->made && !c->moving && s->shape == c->shape && s->r == r;
}

static const double *corner(const wc_collider *c, int32_t t, int k)
{
    return c->current + 3 * (size_t)c->triangles[3 * (size_t)t + k];
}

static double longest_edge(const wc_collider *c)
{
    double most2 = 0.0;
    for (int32_t t = 0; t < c->triangle_count; ++t)
        for (int k = 0; k < 3; ++k) {
            double d[3];
            sub3(corner(c, t, (k + 1) % 3), corner(c, t, k), d);
            if (dot3(d, d) > most2) most2 = dot3(d, d);
        }
    return sqrt(most2);
}

/* The square of the gap between two boxes (0 where they meet). */
static double box_gap2(const double a[6], const double b[6])
{
    double g2 = 0.0;
    for (int k = 0; k < 3; ++k) {
        double g = a[k] - b[k + 3] > b[k] - a[k + 3] ? a[k] - b[k + 3] : b[k] - a[k + 3];
        if (g > 0.0) g2 += g * g;
    }
    return g2;
}

/* The greatest height over the box above the plane through `a` with unit
 * normal n (times `sign`: -1 measures behind it). */
static double box_height(const double box[6], const double a[3], const double n[3], double sign)
{
    double h = 0.0;
    for (int k = 0; k < 3; ++k) {
        double centre = 0.5 * (box[k] + box[k + 3]) - a[k], half = 0.5 * (box[k + 3] - box[k]);
        h += sign * n[k] * centre + fabs(n[k]) * half;
    }
    return h;
}

/* Triangle t's reach beyond its plane on the side `sign` (+1 front, -1
 * back): the least distance from t of a vertex more than the tolerance
 * beyond the plane, at most `cap`. A walk of the collider's tree, nearer
 * child first, that leaves out every node no nearer to t than the best
 * found (or the cap) and every node whose box lies wholly behind the plane:
 * on a convex collider only the leaves around t whose boxes rise above the
 * surface are read, and behind it the nearest vertex soon bounds the rest. */
static double reach_of(const wc_collider *c, int32_t t, double sign, double cap, double tolerance)
{
    const double *n = c->normals + 3 * (size_t)t, *a = corner(c, t, 0);
    const double *b = corner(c, t, 1), *d = corner(c, t, 2);
    const wc_bvh *tree = &c->bvh;
    double box[6], best2 = cap * cap, w[3];
    for (int k = 0; k < 3; ++k) {
        box[k] = fmin(a[k], fmin(b[k], d[k]));
        box[k + 3] = fmax(a[k], fmax(b[k], d[k]));
    }
    int32_t stack[WALK_STACK], depth = 0;
    stack[depth++] = 0;
    while (depth > 0) {
        const wc_bvh_node *node = tree->nodes + stack[--depth];
        if (box_gap2(node->box, box) >= best2 || box_height(node->box, a, n, sign) <= tolerance) continue;
        if (node->count == 0) {
            int32_t near = node->first, far = node->first + 1;
            if (box_gap2(tree->nodes[far].box, box) < box_gap2(tree->nodes[near].box, box))
                near = far, far = node->first;
            stack[depth++] = far;
            stack[depth++] = near;
            continue;
        }
        for (int32_t j = 0; j < node->count; ++j) {
            int32_t u = tree->order[node->first + j];
            for (int k = 0; k < 3; ++k) {
                const double *v = corner(c, u, k);
                double rel[3], point[6] = {v[0], v[1], v[2], v[0], v[1], v[2]};
                sub3(v, a, rel);
                if (!(sign * dot3(rel, n) > tolerance) || box_gap2(point, box) >= best2) continue;
                double d2 = wci_point_triangle_closest(v, a, b, d, w);
                if (d2 < best2) best2 = d2;
            }
        }
    }
    return sqrt(best2);
}

wc_status wci_support_prepare(wc_support *s, const wc_collider *c, double r)
{
    if (wci_support_ready(s, c, r)) return WC_OK;
    if (s->triangle_count != c->triangle_count) {
        wci_support_destroy(s);
        s->reach = wci_alloc_array(2 * (size_t)(c->triangle_count > 0 ? c->triangle_count : 1),
                                   sizeof *s->reach);
        if (!s->reach) return WC_ERROR_OUT_OF_MEMORY;
        s->triangle_count = c->triangle_count;
    }
    for (size_t k = 0; k < 2 * (size_t)c->triangle_count; ++k) s->reach[k] = -1.0;
    s->longest_edge = longest_edge(c);
    s->r = r;
    s->cap = CAP_R * r + CAP_EDGE * s->longest_edge;
    /* a vertex measured lies within cap + longest_edge of the corner its
     * height is taken from */
    s->tolerance = 1e-12 * (s->cap + s->longest_edge);
    s->shape = c->shape;
    s->made = 1;
    return WC_OK;
}

int wci_support_side(const wc_collider *c, int32_t t, const double point[3])
{
    double rel[3];
    sub3(point, corner(c, t, 0), rel);
    return !(dot3(rel, c->normals + 3 * (size_t)t) > 0.0);
}

int wci_support_measured(const wc_support *s, int32_t t, int side)
{
    return s->reach[2 * (size_t)t + side] >= 0.0;
}

void wci_support_measure(wc_support *s, const wc_collider *c, int32_t t, int side)
{
    const double *n = c->normals + 3 * (size_t)t;
    int degenerate = n[0] == 0.0 && n[1] == 0.0 && n[2] == 0.0;
    s->reach[2 * (size_t)t + side] = degenerate ? 0.0 : reach_of(c, t, side ? -1.0 : 1.0, s->cap, s->tolerance);
}

int wci_support_holds(const wc_support *s, const wc_collider *c, int32_t t, const double start[3],
                      const double end[3])
{
    const double *n = c->normals + 3 * (size_t)t, *a = corner(c, t, 0);
    double rel[3];
    sub3(start, a, rel);
    double hs = dot3(rel, n);
    sub3(end, a, rel);
    int side = !(hs > 0.0);
    double he = dot3(rel, n), sign = side ? -1.0 : 1.0;
    hs *= sign, he *= sign;
    /* A triangle behind the plane (its corners at most the tolerance in
     * front) is no nearer to the end than he - tolerance, which the face
     * test must not count as a touch; the path, in front of the plane by
     * more than the tolerance all along, does not meet it. */
    double clear = he - s->tolerance, r = s->r;
    if (!(hs > s->tolerance) || !(clear > 0.0) || !(clear * clear >= r * r * (1.0 - WC_FACE_SLACK)))
        return 0;
    /* Every other triangle has a corner at least the reach from t, so all
     * of it lies at least reach - longest_edge from t, and at least that
     * less the end's distance from t and the motion from every point of
     * the path: more than r. (Degenerate triangles, whose normal is zero,
     * never get here: their heights are 0.) */
    double w[3], motion[3];
    sub3(end, start, motion);
    double from_t = sqrt(wci_point_triangle_closest(end, a, corner(c, t, 1), corner(c, t, 2), w));
    double needed = from_t + sqrt(dot3(motion, motion)) + s->longest_edge + r;
    return s->reach[2 * (size_t)t + side] > needed * (1.0 + 1e-9);
}
