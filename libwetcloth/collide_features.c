#include "collide_features.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "alloc.h"
#include "grid.h"
#include "near_list.h"
#include "primitives.h"

/* Passes over all features per step; a pair still moving things after the
 * last one sends the particles it moved back to the start of the step. */
#define MAX_PASSES 8
/* A contact counts only if it is deeper than this fraction of the contact
 * distance. The passes resolve contacts one after another, and where a
 * collider corner and its edges push the same cloth element in turn, what
 * is left shrinks geometrically rather than vanishing; an intersection needs
 * a violation of the whole contact distance, so 1 % of it left over is
 * harmless, and stopping there spares passes and fail-safes. */
#define SLACK 1e-2

struct wc_feature_state {
    int32_t triangle_count;
    int32_t edge_count;
    /// Unique triangle edges of the cloth, 2 particle indices each.
    int32_t *edges;
    /// The 3 edge ids of each triangle.
    int32_t *triangle_edges;
    /// Largest contact distance of the colliders in the running call.
    double r_max;
    /// Particles moved by the previous pass, and by the one being run (the
    /// last one's are what the fail-safe sends back).
    uint8_t *moved;
    uint8_t *moving;
    /// Per particle, xyz: how far the collider feature that last pushed it
    /// moved over the step. The fail-safe carries the particle along by it.
    double *carry;
    /// 0 in the first pass (test everything), 1 after (only elements with a
    /// particle the previous pass moved: nothing else can have changed).
    int only_moved;
    /// Candidate collider features of one cloth element.
    int32_t *found;
    int32_t found_capacity;
    /// Per collider (by index): the cloth elements near it, while it is
    /// static (near_list.h).
    wc_near_list *near;
    int32_t near_count;
    int skip_near_lists;
};

/* Plain comparisons: libm's fmin and fmax are calls (NaN rules), and the
 * box code runs for every candidate pair. Inputs here are finite. */
static double min2(double a, double b) { return a < b ? a : b; }
static double max2(double a, double b) { return a > b ? a : b; }

static double dot3(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static void cross3(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

static void lerp3(const double a[3], const double b[3], double t, double out[3])
{
    for (int k = 0; k < 3; ++k) out[k] = a[k] + (b[k] - a[k]) * t;
}

static int normalize3(double v[3])
{
    double len = sqrt(dot3(v, v));
    if (!(len > 0.0)) return 0;
    for (int k = 0; k < 3; ++k) v[k] /= len;
    return 1;
}

static void start_of(const wc_cloth *c, int32_t i, double out[3])
{
    out[0] = c->x[i], out[1] = c->y[i], out[2] = c->z[i];
}

static void end_of(const wc_cloth *c, int32_t i, double out[3])
{
    out[0] = c->nx[i], out[1] = c->ny[i], out[2] = c->nz[i];
}

static void vertex_of(const double *xyz, int32_t v, double out[3])
{
    out[0] = xyz[3 * (size_t)v], out[1] = xyz[3 * (size_t)v + 1], out[2] = xyz[3 * (size_t)v + 2];
}

/* ------------------------------------------------------------------------ */
/* State                                                                    */
/* ------------------------------------------------------------------------ */

static int compare_edge(const void *pa, const void *pb)
{
    const int32_t *p = pa, *q = pb;
    for (int k = 0; k < 3; ++k)
        if (p[k] != q[k]) return p[k] < q[k] ? -1 : 1;
    return 0;
}

wc_feature_state *wc_feature_state_create(const wc_cloth *c)
{
    wc_feature_state *s = wc_alloc_array(1, sizeof *s);
    if (!s) return NULL;
    int32_t nt = c->topology.triangle_count;
    s->triangle_count = nt;
    /* (a, b, 3 * triangle + corner) per triangle edge, sorted: equal edges
     * become neighbours, and the third field says where each came from. */
    int32_t *entries = wc_alloc_array(9 * (size_t)nt, sizeof *entries);
    s->edges = wc_alloc_array(6 * (size_t)nt, sizeof *s->edges);
    s->triangle_edges = wc_alloc_array(3 * (size_t)nt, sizeof *s->triangle_edges);
    s->moved = wc_alloc_array((size_t)c->particle_count, sizeof *s->moved);
    s->moving = wc_alloc_array((size_t)c->particle_count, sizeof *s->moving);
    s->carry = wc_alloc_array(3 * (size_t)c->particle_count, sizeof *s->carry);
    s->found_capacity = 256;
    s->found = wc_alloc_array((size_t)s->found_capacity, sizeof *s->found);
    if (!entries || !s->edges || !s->triangle_edges || !s->moved || !s->moving ||
        !s->carry || !s->found) {
        wc_free(entries);
        wc_feature_state_destroy(s);
        return NULL;
    }
    const int32_t *tri = c->topology.triangles;
    for (int32_t t = 0; t < nt; ++t)
        for (int k = 0; k < 3; ++k) {
            int32_t a = tri[3 * t + k], b = tri[3 * t + (k + 1) % 3];
            int32_t *e = entries + 3 * (3 * (size_t)t + k);
            e[0] = a < b ? a : b, e[1] = a < b ? b : a, e[2] = 3 * t + k;
        }
    qsort(entries, 3 * (size_t)nt, 3 * sizeof *entries, compare_edge);
    for (int32_t k = 0; k < 3 * nt; ++k) {
        const int32_t *e = entries + 3 * (size_t)k;
        if (k == 0 || e[0] != e[-3] || e[1] != e[-2]) {
            s->edges[2 * s->edge_count] = e[0];
            s->edges[2 * s->edge_count + 1] = e[1];
            ++s->edge_count;
        }
        s->triangle_edges[e[2]] = s->edge_count - 1;
    }
    wc_free(entries);
    return s;
}

void wc_feature_state_keep_near_lists(wc_feature_state *s, int keep) { s->skip_near_lists = !keep; }

const wc_near_list *wc_feature_state_near_list(const wc_feature_state *s, int32_t collider)
{
    if (!s || s->skip_near_lists || collider >= s->near_count) return NULL;
    return &s->near[collider];
}

void wc_feature_state_destroy(wc_feature_state *s)
{
    if (!s) return;
    wc_free(s->edges);
    wc_free(s->triangle_edges);
    wc_free(s->moved);
    wc_free(s->moving);
    wc_free(s->carry);
    wc_free(s->found);
    for (int32_t k = 0; k < s->near_count; ++k) wc_near_list_free(&s->near[k]);
    wc_free(s->near);
    wc_free(s);
}

/* Box of cloth triangle `tri` over the step (its corners' start and end
 * positions as they are now), grown by r. Made when used, not once per
 * call: the passes move particles, and a box from before they did could
 * miss what the move brought near. */
static void triangle_box(const wc_cloth *c, const int32_t *tri, double r, double box[6])
{
    for (int k = 0; k < 3; ++k) box[k] = INFINITY, box[k + 3] = -INFINITY;
    for (int k = 0; k < 3; ++k) {
        double p[2][3];
        start_of(c, tri[k], p[0]);
        end_of(c, tri[k], p[1]);
        for (int e = 0; e < 2; ++e)
            for (int d = 0; d < 3; ++d) {
                box[d] = min2(box[d], p[e][d] - r);
                box[d + 3] = max2(box[d + 3], p[e][d] + r);
            }
    }
}

/* Box around the whole cloth over the step as it is now, grown by r. */
static void cloth_bounds(const wc_cloth *c, double r, double box[6])
{
    for (int k = 0; k < 3; ++k) box[k] = INFINITY, box[k + 3] = -INFINITY;
    for (int32_t i = 0; i < c->particle_count; ++i) {
        double p[2][3];
        start_of(c, i, p[0]);
        end_of(c, i, p[1]);
        for (int e = 0; e < 2; ++e)
            for (int d = 0; d < 3; ++d) {
                box[d] = min2(box[d], p[e][d]);
                box[d + 3] = max2(box[d + 3], p[e][d]);
            }
    }
    for (int d = 0; d < 3; ++d) box[d] -= r, box[d + 3] += r;
}

/* ------------------------------------------------------------------------ */
/* Response                                                                 */
/* ------------------------------------------------------------------------ */

/* Velocity of particle i after the step as computed so far: through the
 * history override if a response already set one. */
static void velocity_of(const wc_cloth *c, int32_t i, double dt, double v[3])
{
    double e[3], from[3];
    end_of(c, i, e);
    if (c->history_override[i]) from[0] = c->qx[i], from[1] = c->qy[i], from[2] = c->qz[i];
    else start_of(c, i, from);
    for (int k = 0; k < 3; ++k) v[k] = (e[k] - from[k]) / dt;
}

/* A cloth element (count particles with barycentric weights w) is at signed
 * distance `gap` from a collider feature along n (pointing from the feature
 * to the cloth); the feature moves at v_feature. Moves the element out to
 * distance r and removes its approach velocity, with Coulomb friction, the
 * changes shared by w_k / m_k (Bridson et al. 2002): the contact point then
 * moves by exactly what is asked. Returns 1 if it moved anything. */
static int push_element(wc_cloth *c, wc_feature_state *s, const int32_t *idx, const double *w,
                        int count, const double n[3], double gap, double r,
                        const double v_feature[3], double mu, double dt)
{
    double inv[3], denom = 0.0;
    for (int k = 0; k < count; ++k) {
        inv[k] = c->pin_slot[idx[k]] >= 0 ? 0.0 : c->inv_mass[idx[k]];
        denom += w[k] * w[k] * inv[k];
    }
    double depth = r - gap;
    if (!(denom > 0.0) || !(depth > SLACK * r)) return 0;
    double v[3][3], vp[3] = {0, 0, 0};
    for (int k = 0; k < count; ++k) {
        velocity_of(c, idx[k], dt, v[k]);
        for (int d = 0; d < 3; ++d) vp[d] += w[k] * v[k][d];
    }
    double rel[3], change[3] = {0, 0, 0};
    for (int d = 0; d < 3; ++d) rel[d] = vp[d] - v_feature[d];
    double vn = dot3(rel, n);
    if (vn < 0.0) {
        double tangent[3];
        for (int d = 0; d < 3; ++d) tangent[d] = rel[d] - vn * n[d];
        double speed = sqrt(dot3(tangent, tangent));
        double cut = speed > 0.0 ? min2(1.0, mu * (-vn) / speed) : 0.0;
        /* Wet friction (thesis eq. 2.10), as for a particle on a face
         * (collide.c): in sustained contact the tangential velocity left
         * after Coulomb is scaled by 1 - w (1 - q), w the element's wetness
         * at the contact point over its corners that touched in the last
         * step. Dry cloth keeps exactly the Coulomb cut. */
        double wet = 0.0;
        for (int k = 0; k < count; ++k)
            if (c->contact_prev[idx[k]] != WC_CONTACT_NONE) wet += w[k] * c->wetness[idx[k]];
        if (wet > 0.0) cut = 1.0 - (1.0 - cut) * (1.0 - wet * (1.0 - c->material.wet_friction));
        for (int d = 0; d < 3; ++d) change[d] = -vn * n[d] - cut * tangent[d];
    }
    for (int k = 0; k < count; ++k) {
        if (inv[k] == 0.0) continue;
        int32_t i = idx[k];
        double share = w[k] * inv[k] / denom;
        c->nx[i] += share * depth * n[0];
        c->ny[i] += share * depth * n[1];
        c->nz[i] += share * depth * n[2];
        for (int d = 0; d < 3; ++d) v[k][d] += share * change[d];
        c->qx[i] = c->nx[i] - v[k][0] * dt;
        c->qy[i] = c->ny[i] - v[k][1] * dt;
        c->qz[i] = c->nz[i] - v[k][2] * dt;
        c->history_override[i] = 1;
        if (c->contact[i] == WC_CONTACT_NONE) {
            c->contact[i] = WC_CONTACT_COLLIDER;
            c->normal_x[i] = n[0], c->normal_y[i] = n[1], c->normal_z[i] = n[2];
        }
        s->moving[i] = 1;
        for (int d = 0; d < 3; ++d) s->carry[3 * (size_t)i + d] = v_feature[d] * dt;
    }
    return 1;
}

/* Box around points, grown by r. */
static void feature_box(const double *const *points, int count, double r, double box[6])
{
    for (int k = 0; k < 3; ++k) box[k] = INFINITY, box[k + 3] = -INFINITY;
    for (int p = 0; p < count; ++p)
        for (int k = 0; k < 3; ++k) {
            box[k] = min2(box[k], points[p][k] - r);
            box[k + 3] = max2(box[k + 3], points[p][k] + r);
        }
}

/* Largest displacement over the step among `count` start/end point pairs. */
static double largest_motion(const double *const *from, const double *const *to, int count)
{
    double m = 0.0;
    for (int k = 0; k < count; ++k) {
        double d[3] = {to[k][0] - from[k][0], to[k][1] - from[k][1], to[k][2] - from[k][2]};
        m = max2(m, dot3(d, d));
    }
    return sqrt(m);
}

/* Continuous detection is needed only when the pair moved relative to each
 * other by more than r: the pair was at least r apart at the start (the
 * previous step saw to it), and distance changes no faster than the points
 * move, so a crossing with less motion than that still ends within r of
 * each other, where the proximity test sees it (and takes the side from the
 * start). Twice the largest motion bounds the relative motion. */
static int needs_ccd(double largest, double r) { return 2.0 * largest > r; }

/* Collider vertex (v0 -> v1) against cloth triangle t. */
static int vertex_triangle(wc_cloth *c, wc_feature_state *s, int32_t t, const double v0[3],
                           const double v1[3], double r, double mu, double dt)
{
    const int32_t *idx = c->topology.triangles + 3 * (size_t)t;
    double a0[3], b0[3], c0[3], a1[3], b1[3], c1[3], w[3], p1[3], p0[3], n1[3], n0[3], tc;
    start_of(c, idx[0], a0), start_of(c, idx[1], b0), start_of(c, idx[2], c0);
    end_of(c, idx[0], a1), end_of(c, idx[1], b1), end_of(c, idx[2], c1);
    int hit = wc_point_triangle_closest(v1, a1, b1, c1, w) < r * r * (1.0 - SLACK);
    const double *from[4] = {v0, a0, b0, c0}, *to[4] = {v1, a1, b1, c1};
    if (!hit && needs_ccd(largest_motion(from, to, 4), r))
        hit = wc_ccd_point_triangle(v0, v1, a0, a1, b0, b1, c0, c1, 1e-9 * r, &tc, w);
    if (!hit) return 0;
    wc_triangle_normal(a1, b1, c1, n1);
    wc_triangle_normal(a0, b0, c0, n0);
    if (dot3(n1, n1) == 0.0 || dot3(n0, n0) == 0.0) return 0; /* crushed flat: the edges decide */
    for (int d = 0; d < 3; ++d) {
        p1[d] = w[0] * a1[d] + w[1] * b1[d] + w[2] * c1[d];
        p0[d] = w[0] * a0[d] + w[1] * b0[d] + w[2] * c0[d];
    }
    /* The cloth belongs on the side of the vertex it was on at the start. */
    double start_gap[3], end_gap[3], n[3];
    for (int d = 0; d < 3; ++d) start_gap[d] = p0[d] - v0[d], end_gap[d] = p1[d] - v1[d];
    double side = dot3(start_gap, n0);
    if (side == 0.0) side = dot3(end_gap, n1);
    side = side < 0.0 ? -1.0 : 1.0;
    for (int d = 0; d < 3; ++d) n[d] = side * n1[d];
    /* Off the face region, on the right side: push along the offset. */
    double along = dot3(end_gap, n), len = sqrt(dot3(end_gap, end_gap));
    if (along > 0.0 && len > 0.0 && (w[0] == 0.0 || w[1] == 0.0 || w[2] == 0.0))
        for (int d = 0; d < 3; ++d) n[d] = end_gap[d] / len;
    double v_feature[3];
    for (int d = 0; d < 3; ++d) v_feature[d] = (v1[d] - v0[d]) / dt;
    return push_element(c, s, idx, w, 3, n, dot3(end_gap, n), r, v_feature, mu, dt);
}

/* Collider edge (p, q) against cloth edge e; their boxes over the step
 * overlap (the edge grid's query saw to it). */
static int edge_edge(wc_cloth *c, wc_feature_state *s, int32_t e, const double p0[3],
                     const double p1[3], const double q0[3], const double q1[3], double r,
                     double mu, double dt)
{
    const int32_t *idx = s->edges + 2 * (size_t)e;
    double a0[3], b0[3], a1[3], b1[3], sp, u, tc;
    start_of(c, idx[0], a0), start_of(c, idx[1], b0);
    end_of(c, idx[0], a1), end_of(c, idx[1], b1);
    const double *from[4] = {p0, q0, a0, b0}, *to[4] = {p1, q1, a1, b1};
    int ccd = needs_ccd(largest_motion(from, to, 4), r);
    int hit = wc_segment_segment_closest(p1, q1, a1, b1, &sp, &u) < r * r * (1.0 - SLACK);
    if (!hit && ccd)
        hit = wc_ccd_edge_edge(p0, p1, q0, q1, a0, a1, b0, b1, 1e-9 * r, &tc, &sp, &u);
    if (!hit) return 0;
    /* A contact at an end of either edge is a vertex's business (a cloth
     * particle against a face, or a collider vertex against a triangle). */
    if (sp <= 0.0 || sp >= 1.0 || u <= 0.0 || u >= 1.0) return 0;
    double c0[3], c1[3], e0[3], e1[3], start_gap[3], end_gap[3], m0[3], m1[3], dp[3], de[3];
    lerp3(p0, q0, sp, c0), lerp3(p1, q1, sp, c1);
    lerp3(a0, b0, u, e0), lerp3(a1, b1, u, e1);
    for (int d = 0; d < 3; ++d) {
        start_gap[d] = e0[d] - c0[d], end_gap[d] = e1[d] - c1[d];
        dp[d] = q0[d] - p0[d], de[d] = b0[d] - a0[d];
    }
    cross3(dp, de, m0);
    for (int d = 0; d < 3; ++d) dp[d] = q1[d] - p1[d], de[d] = b1[d] - a1[d];
    cross3(dp, de, m1);
    if (!normalize3(m0) || !normalize3(m1)) return 0; /* parallel edges: the vertices decide */
    double side = dot3(start_gap, m0);
    if (side == 0.0) side = dot3(end_gap, m1);
    double n[3];
    for (int d = 0; d < 3; ++d) n[d] = (side < 0.0 ? -1.0 : 1.0) * m1[d];
    double w[2] = {1.0 - u, u}, v_feature[3];
    for (int d = 0; d < 3; ++d) v_feature[d] = ((1.0 - sp) * (p1[d] - p0[d]) + sp * (q1[d] - q0[d])) / dt;
    return push_element(c, s, idx, w, 2, n, dot3(end_gap, n), r, v_feature, mu, dt);
}

/* ------------------------------------------------------------------------ */
/* One pass                                                                 */
/* ------------------------------------------------------------------------ */

/* The items of one of the collider's feature grids whose boxes overlap
 * `box`, ascending, into s->found (grown when needed). -1 on out-of-memory. */
static int32_t candidates(wc_feature_state *s, const wc_grid *grid, const double box[6])
{
    int32_t n = wc_grid_query(grid, box, s->found, s->found_capacity);
    if (n <= s->found_capacity) return n;
    int32_t *grown = wc_alloc_array((size_t)n, 2 * sizeof *grown);
    if (!grown) return -1;
    wc_free(s->found);
    s->found = grown;
    s->found_capacity = 2 * n;
    return wc_grid_query(grid, box, s->found, s->found_capacity);
}

/* The collider features near a cloth element whose box is `box`: from the
 * near list (its element k) when there is one, else from the grid. A near
 * list's candidates include more than the grid would give; `exact` then
 * says the caller must test each against the box. -1 on out-of-memory. */
static int32_t features_near(wc_feature_state *s, const wc_near_elements *near, int32_t k,
                             const wc_grid *grid, const double box[6], const int32_t **found)
{
    if (near) {
        *found = near->found + near->start[k];
        return near->start[k + 1] - near->start[k];
    }
    int32_t n = candidates(s, grid, box);
    *found = s->found;
    return n;
}

/* One pass of a collider against the cloth, from the cloth's side: each
 * cloth triangle near the collider asks the collider's vertex grid (built
 * once for a static collider) for the vertices near it, each cloth edge its
 * edge grid for the edges near it; for a static collider the near list
 * remembers the answers across steps. Returns 1 if anything moved, 0 if
 * not, -1 on out-of-memory. */
static int collider_pass(wc_cloth *c, wc_feature_state *s, const wc_collider *col,
                         const wc_near_list *near, double r, double mu, double dt)
{
    int moved = 0;
    if (!near) {
        /* every element is visited: first see whether the cloth is near at all */
        double bounds[6];
        cloth_bounds(c, s->r_max, bounds);
        if (!wc_boxes_overlap(col->bounds, bounds)) return 0;
    }
    const wc_near_elements *tris = near ? &near->triangles : NULL, *edges = near ? &near->edges : NULL;
    int32_t count = tris ? tris->count : s->triangle_count;
    for (int32_t k = 0; k < count; ++k) {
        int32_t t = tris ? tris->element[k] : k;
        const int32_t *tri = c->topology.triangles + 3 * (size_t)t;
        if (s->only_moved && !(s->moved[tri[0]] | s->moved[tri[1]] | s->moved[tri[2]])) continue;
        double box[6];
        triangle_box(c, tri, s->r_max, box);
        if (!wc_boxes_overlap(box, col->bounds)) continue;
        const int32_t *found;
        int32_t n = features_near(s, tris, k, &col->vertex_grid, box, &found);
        if (n < 0) return -1;
        for (int32_t j = 0; j < n; ++j) {
            double v0[3], v1[3];
            if (tris && !wc_boxes_overlap(box, col->vertex_boxes + 6 * (size_t)found[j])) continue;
            vertex_of(col->current, found[j], v0);
            vertex_of(col->next, found[j], v1);
            moved |= vertex_triangle(c, s, t, v0, v1, r, mu, dt);
        }
    }
    count = edges ? edges->count : s->edge_count;
    for (int32_t k = 0; k < count; ++k) {
        int32_t e = edges ? edges->element[k] : k;
        double a0[3], a1[3], b0[3], b1[3], box[6];
        if (s->only_moved && !(s->moved[s->edges[2 * e]] | s->moved[s->edges[2 * e + 1]])) continue;
        start_of(c, s->edges[2 * e], a0), end_of(c, s->edges[2 * e], a1);
        start_of(c, s->edges[2 * e + 1], b0), end_of(c, s->edges[2 * e + 1], b1);
        const double *ends[4] = {a0, a1, b0, b1};
        feature_box(ends, 4, r, box);
        if (!wc_boxes_overlap(box, col->bounds)) continue;
        const int32_t *found;
        int32_t n = features_near(s, edges, k, &col->edge_grid, box, &found);
        if (n < 0) return -1;
        for (int32_t j = 0; j < n; ++j) {
            int32_t id = found[j];
            if (edges && !wc_boxes_overlap(box, col->edge_boxes + 6 * (size_t)id)) continue;
            double p0[3], p1[3], q0[3], q1[3];
            vertex_of(col->current, col->edges[2 * id], p0);
            vertex_of(col->next, col->edges[2 * id], p1);
            vertex_of(col->current, col->edges[2 * id + 1], q0);
            vertex_of(col->next, col->edges[2 * id + 1], q1);
            moved |= edge_edge(c, s, e, p0, p1, q0, q1, r, mu, dt);
        }
    }
    return moved;
}

/* The near list of collider k, made to hold for this pass; NULL when the
 * collider moves (its grids are rebuilt every step, so there is nothing to
 * keep). -1 in *status on out-of-memory. */
static const wc_near_list *near_list_for(wc_cloth *c, wc_feature_state *s, int32_t k,
                                         const wc_collider *col, double r_triangles, double r,
                                         int *failed)
{
    *failed = 0;
    if (!col->grid_static || s->skip_near_lists) return NULL;
    if (k >= s->near_count) {
        wc_near_list *grown = wc_alloc_array((size_t)k + 1, sizeof *grown);
        if (!grown) return *failed = 1, NULL;
        if (s->near_count) memcpy(grown, s->near, (size_t)s->near_count * sizeof *grown);
        for (int32_t j = s->near_count; j <= k; ++j) wc_near_list_init(&grown[j]);
        wc_free(s->near);
        s->near = grown, s->near_count = k + 1;
    }
    wc_near_list *l = &s->near[k];
    /* the particle pass grows its query boxes by twice the contact distance */
    if (wc_near_list_holds(l, c, col, r_triangles, r, 2 * r)) return l;
    if (wc_near_list_build(l, c, s->edges, s->edge_count, col, r_triangles, r, 2 * r))
        return *failed = 1, NULL;
    return l;
}

wc_status wc_collide_features(wc_cloth *c, wc_feature_state *s, wc_collider *const *colliders,
                              int32_t count, double dt, wc_step_stats *stats, int *moved_out)
{
    *moved_out = 0;
    double h = c->material.thickness, r_max = 0.0;
    int any = 0;
    for (int32_t k = 0; k < count; ++k)
        if (colliders[k]->is_mesh) r_max = max2(r_max, h + colliders[k]->thickness), any = 1;
    if (!any) return WC_OK;
    s->r_max = r_max;
    int moved = 1;
    for (int pass = 0; pass < MAX_PASSES && moved; ++pass) {
        s->only_moved = pass > 0;
        memset(s->moving, 0, (size_t)c->particle_count);
        moved = 0;
        for (int32_t k = 0; k < count; ++k) {
            const wc_collider *col = colliders[k];
            if (!col->is_mesh) continue;
            double r = fmax(h + col->thickness, 1e-6);
            int failed;
            const wc_near_list *near = near_list_for(c, s, k, col, r_max, r, &failed);
            if (failed) return WC_ERROR_OUT_OF_MEMORY;
            int result = collider_pass(c, s, col, near, r, sqrt(c->material.friction * col->friction), dt);
            if (result < 0) return WC_ERROR_OUT_OF_MEMORY;
            moved |= result;
        }
        uint8_t *swap = s->moved;
        s->moved = s->moving, s->moving = swap;
        *moved_out |= moved;
    }
    if (!moved) return WC_OK;
    /* Fail-safe: what the last pass still had to move keeps its position
     * relative to the collider feature that last pushed it, as at the start
     * of the step (which was free of intersection): it moves with the
     * feature and takes its velocity (for a static collider: stays where it
     * was, at rest). */
    for (int32_t i = 0; i < c->particle_count; ++i) {
        if (!s->moved[i]) continue;
        const double *carry = s->carry + 3 * (size_t)i;
        c->nx[i] = c->x[i] + carry[0], c->qx[i] = c->x[i];
        c->ny[i] = c->y[i] + carry[1], c->qy[i] = c->y[i];
        c->nz[i] = c->z[i] + carry[2], c->qz[i] = c->z[i];
        c->history_override[i] = 1;
        stats->failsafe_particles++;
    }
    return WC_OK;
}
