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
/* Clearances (near_list.h) are measured from this fraction of the contact
 * distance, the reach of a contact: a pair counts as one only nearer than
 * r sqrt(1 - SLACK) = 0.99499 r, 1.3e-5 r less than the reach, which is
 * far more than the rounding of the few operations behind a clearance.
 * Measured from r instead, a pair the last push left at exactly r would
 * have no clearance, and a cloth resting on the collider would test every
 * pair in contact at every step although it must sink 0.5 % of r before
 * one can count (the 20 x 20 drape in its second second: a third of its
 * pair tests, 394 per step against 269 with the reach). */
#define REACH 0.995

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
    /// The same as lists (in the order marked), so that a pass after the
    /// first and the near lists' check find them without reading a flag per
    /// particle; a flag array is zero but for its list's entries.
    int32_t *moved_list, *moving_list;
    int32_t moved_count, moving_count;
    /// Per particle, xyz: how far the collider feature that last pushed it
    /// moved over the step. The fail-safe carries the particle along by it.
    double *carry;
    /// 0 in the first pass (test everything), 1 after (only elements with a
    /// particle the previous pass moved: nothing else can have changed).
    int only_moved;
    /// Between rounds (collide.h): recheck for the particle pass, shifted
    /// for the first pass of the next call.
    wc_collide_marks marks;
    /// Per particle: the length of the path its end of step has taken
    /// (clearances, near_list.h), the end it was last brought up to, and
    /// its squared motion over the step; kept up to date through the
    /// passes, so an element's visit reads them instead of positions.
    double *path;
    double *path_end;
    double *motion2;
    /// Per particle: its path length at its start of step.
    double *path_start;
    /// Per particle, the cloth triangles and the edges it belongs to (CSR),
    /// so that a pass after the first finds the elements of the particles
    /// the last one moved without looking at every element; and scratch
    /// for that: a mark and a list per element slot.
    int32_t *triangles_start, *triangles_of, *edges_start, *edges_of;
    uint8_t *visit_mark;
    int32_t *visit_list;
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

/* Points along the step at which turning_cross follows a normal. */
#define NORMAL_SAMPLES 8

/* The unit normal m(t) = u(t) x v(t) of two vectors moving linearly over
 * the step (u0 to u1, v0 to v1) at its start and end, with the end's sign
 * chosen by following the normal along the step as an axis: at each of
 * NORMAL_SAMPLES points the sign nearest the last point's. A side judged
 * along m0 at the start then reads the same along m1 at the end unless the
 * elements crossed. Without this, two edges that pass through parallel
 * (or a triangle that turns over) within the step, where m(t) vanishes and
 * comes back reversed, would read as crossed, and the push would take the
 * cloth through the collider: cloth edges sliding over a sphere's edges,
 * both tangent to the sphere, do that at 8 implicit steps per frame. A
 * normal that keeps its length and turns past 90 degrees over the step is
 * followed too. Returns 0 if m0 or m1 has no direction. */
static int turning_cross(const double u0[3], const double u1[3], const double v0[3],
                         const double v1[3], double m0[3], double m1[3])
{
    double last[3], u[3], v[3], m[3];
    cross3(u0, v0, m0);
    if (!normalize3(m0)) return 0;
    memcpy(last, m0, sizeof last);
    for (int k = 1; k <= NORMAL_SAMPLES; ++k) {
        double t = (double)k / NORMAL_SAMPLES;
        if (k == NORMAL_SAMPLES) memcpy(u, u1, sizeof u), memcpy(v, v1, sizeof v);
        else lerp3(u0, u1, t, u), lerp3(v0, v1, t, v);
        cross3(u, v, m);
        if (!normalize3(m)) {
            if (k == NORMAL_SAMPLES) return 0;
            continue;
        }
        if (dot3(m, last) < 0.0)
            for (int d = 0; d < 3; ++d) m[d] = -m[d];
        memcpy(last, m, sizeof last);
    }
    memcpy(m1, last, sizeof last);
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

/* Inverts a list of elements (`per` particles each) into, per particle,
 * the elements it belongs to, ascending; 0 on out-of-memory. */
static int invert_elements(const int32_t *particles, int per, int32_t count, int32_t particle_count,
                           int32_t **start_out, int32_t **items_out)
{
    int32_t *start = wc_alloc_array((size_t)particle_count + 1, sizeof *start);
    int32_t *items = wc_alloc_array((size_t)per * (size_t)count, sizeof *items);
    *start_out = start, *items_out = items;
    if (!start || !items) return 0;
    for (size_t k = 0; k < (size_t)per * (size_t)count; ++k) start[particles[k] + 1]++;
    for (int32_t i = 0; i < particle_count; ++i) start[i + 1] += start[i];
    for (int32_t e = 0; e < count; ++e)
        for (int p = 0; p < per; ++p) {
            int32_t i = particles[(size_t)per * (size_t)e + (size_t)p];
            /* start[i] advances as i's slots fill; undone below */
            items[start[i]++] = e;
        }
    for (int32_t i = particle_count; i > 0; --i) start[i] = start[i - 1];
    start[0] = 0;
    return 1;
}

static int particle_elements(const wc_cloth *c, wc_feature_state *s)
{
    int32_t n = c->particle_count, most = s->triangle_count > s->edge_count ? s->triangle_count : s->edge_count;
    s->visit_mark = wc_alloc_array((size_t)most, sizeof *s->visit_mark);
    s->visit_list = wc_alloc_array((size_t)most, sizeof *s->visit_list);
    return s->visit_mark && s->visit_list &&
           invert_elements(c->topology.triangles, 3, s->triangle_count, n, &s->triangles_start,
                           &s->triangles_of) &&
           invert_elements(s->edges, 2, s->edge_count, n, &s->edges_start, &s->edges_of);
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
    s->moved_list = wc_alloc_array((size_t)c->particle_count, sizeof *s->moved_list);
    s->moving_list = wc_alloc_array((size_t)c->particle_count, sizeof *s->moving_list);
    s->carry = wc_alloc_array(3 * (size_t)c->particle_count, sizeof *s->carry);
    s->marks.recheck = wc_alloc_array((size_t)c->particle_count, sizeof *s->marks.recheck);
    s->marks.shifted = wc_alloc_array((size_t)c->particle_count, sizeof *s->marks.shifted);
    s->path = wc_alloc_array((size_t)c->particle_count, sizeof *s->path);
    s->path_end = wc_alloc_array(3 * (size_t)c->particle_count, sizeof *s->path_end);
    s->motion2 = wc_alloc_array((size_t)c->particle_count, sizeof *s->motion2);
    s->path_start = wc_alloc_array((size_t)c->particle_count, sizeof *s->path_start);
    s->found_capacity = 256;
    s->found = wc_alloc_array((size_t)s->found_capacity, sizeof *s->found);
    if (!entries || !s->edges || !s->triangle_edges || !s->moved || !s->moving ||
        !s->moved_list || !s->moving_list ||
        !s->carry || !s->marks.recheck || !s->marks.shifted || !s->path || !s->path_end ||
        !s->motion2 || !s->path_start || !s->found) {
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
    if (!particle_elements(c, s)) {
        wc_feature_state_destroy(s);
        return NULL;
    }
    return s;
}

void wc_feature_state_keep_near_lists(wc_feature_state *s, int keep) { s->skip_near_lists = !keep; }

const wc_collide_marks *wc_feature_state_marks(const wc_feature_state *s) { return &s->marks; }

wc_near_list *wc_feature_state_near_list(wc_feature_state *s, int32_t collider)
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
    wc_free(s->moved_list);
    wc_free(s->moving_list);
    wc_free(s->carry);
    wc_free(s->marks.recheck);
    wc_free(s->marks.shifted);
    wc_free(s->path);
    wc_free(s->path_end);
    wc_free(s->motion2);
    wc_free(s->path_start);
    wc_free(s->triangles_start);
    wc_free(s->triangles_of);
    wc_free(s->edges_start);
    wc_free(s->edges_of);
    wc_free(s->visit_mark);
    wc_free(s->visit_list);
    wc_free(s->found);
    for (int32_t k = 0; k < s->near_count; ++k) wc_near_list_free(&s->near[k]);
    wc_free(s->near);
    wc_free(s);
}

/* Box of a cloth element (`count` particles idx) over the step (its
 * particles' start and end positions as they are now), grown by r. Made
 * when used, not once per call: the passes move particles, and a box from
 * before they did could miss what the move brought near. */
static void element_box(const wc_cloth *c, const int32_t *idx, int count, double r, double box[6])
{
    for (int k = 0; k < 3; ++k) box[k] = INFINITY, box[k + 3] = -INFINITY;
    for (int k = 0; k < count; ++k) {
        double p[2][3];
        start_of(c, idx[k], p[0]);
        end_of(c, idx[k], p[1]);
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

/* Brings particle i's path and motion up to its end of step as it is now. */
static void track_particle(const wc_cloth *c, wc_feature_state *s, int32_t i)
{
    double *last = s->path_end + 3 * (size_t)i, end[3], d[3];
    end_of(c, i, end);
    for (int k = 0; k < 3; ++k) d[k] = end[k] - last[k], last[k] = end[k];
    double step2 = dot3(d, d);
    if (step2 > 0.0) s->path[i] += sqrt(step2);
    double start[3];
    start_of(c, i, start);
    for (int k = 0; k < 3; ++k) d[k] = end[k] - start[k];
    s->motion2[i] = dot3(d, d);
}

void wc_feature_state_track(wc_feature_state *s, const wc_cloth *c, int32_t i)
{
    track_particle(c, s, i);
}

void wc_feature_state_begin_step(wc_feature_state *s, const wc_cloth *c)
{
    for (int32_t i = 0; i < c->particle_count; ++i) {
        /* the start is where the end was committed, after whatever moved it
         * since it was last tracked (self-collision, wet contacts) */
        double *last = s->path_end + 3 * (size_t)i, start[3], d[3];
        start_of(c, i, start);
        for (int k = 0; k < 3; ++k) d[k] = start[k] - last[k], last[k] = start[k];
        double step2 = dot3(d, d);
        if (step2 > 0.0) s->path[i] += sqrt(step2);
        s->path_start[i] = s->path[i];
        track_particle(c, s, i);
    }
}

double wc_feature_state_path(const wc_feature_state *s, int32_t i) { return s->path[i]; }

double wc_feature_state_drift(const wc_feature_state *s, int32_t i, double path_at)
{
    /* the end is on the path after path_at; the start after it too when
     * path_at is from an earlier step, else before it */
    return max2(s->path[i] - path_at, path_at - s->path_start[i]);
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
        track_particle(c, s, i);
        for (int d = 0; d < 3; ++d) v[k][d] += share * change[d];
        c->qx[i] = c->nx[i] - v[k][0] * dt;
        c->qy[i] = c->ny[i] - v[k][1] * dt;
        c->qz[i] = c->nz[i] - v[k][2] * dt;
        c->history_override[i] = 1;
        if (c->contact[i] == WC_CONTACT_NONE) {
            c->contact[i] = WC_CONTACT_COLLIDER;
            c->normal_x[i] = n[0], c->normal_y[i] = n[1], c->normal_z[i] = n[2];
        }
        if (!s->moving[i]) s->moving[i] = 1, s->moving_list[s->moving_count++] = i;
        s->marks.recheck[i] = 1;
        for (int d = 0; d < 3; ++d) s->carry[3 * (size_t)i + d] = v_feature[d] * dt;
    }
    return 1;
}

/* Largest squared displacement over the step of the given particles. */
static double element_motion2(const wc_feature_state *s, const int32_t *idx, int count)
{
    double m = 0.0;
    for (int k = 0; k < count; ++k) m = max2(m, s->motion2[idx[k]]);
    return m;
}

/* Largest squared displacement over the step of collider vertices. */
static double feature_motion2(const wc_collider *col, const int32_t *vertices, int count)
{
    double m = 0.0;
    for (int k = 0; k < count; ++k) {
        double v0[3], v1[3], d[3];
        vertex_of(col->current, vertices[k], v0);
        vertex_of(col->next, vertices[k], v1);
        for (int j = 0; j < 3; ++j) d[j] = v1[j] - v0[j];
        m = max2(m, dot3(d, d));
    }
    return m;
}

/* Continuous detection is needed only when the pair moved relative to each
 * other by more than r: the pair was at least r apart at the start (the
 * previous step saw to it), and distance changes no faster than the points
 * move, so a crossing with less motion than that still ends within r of
 * each other, where the proximity test sees it (and takes the side from the
 * start). Twice the largest squared motion `largest2` of the pair's points
 * bounds the relative motion. */
static int needs_ccd(double largest2, double r) { return 2.0 * sqrt(largest2) > r; }

/* The largest squared motion that needs no continuous detection: then
 * needs_ccd(m, r) is m > ccd_limit2(r), with no square root per element.
 * 2 sqrt(m) is correctly rounded and never falls as m grows, so stepping
 * from (r / 2)^2 by single ulps finds the exact boundary. */
static double ccd_limit2(double r)
{
    double m = 0.25 * r * r;
    while (m > 0.0 && needs_ccd(m, r)) m = nextafter(m, 0.0);
    while (!needs_ccd(nextafter(m, INFINITY), r)) m = nextafter(m, INFINITY);
    return m;
}

/* The pair's own test, unless the collider stands still: then only the
 * cloth element moves, and its motion was measured once for all its
 * candidates. */
static int pair_needs_ccd(const wc_collider *col, double element2, const int32_t *vertices,
                          int count, double limit2)
{
    if (!col->moving) return element2 > limit2;
    return max2(element2, feature_motion2(col, vertices, count)) > limit2;
}

/* Collider vertex (v0 -> v1) against cloth triangle t; `ccd` says whether
 * the pair moved enough to need continuous detection. *d2 gets the squared
 * distance between the vertex and the triangle at the end of the step as
 * they were before any push. */
static int vertex_triangle(wc_cloth *c, wc_feature_state *s, int32_t t, const double v0[3],
                           const double v1[3], int ccd, double r, double mu, double dt, double *d2)
{
    const int32_t *idx = c->topology.triangles + 3 * (size_t)t;
    double a0[3], b0[3], c0[3], a1[3], b1[3], c1[3], w[3], p1[3], p0[3], n1[3], n0[3], tc;
    start_of(c, idx[0], a0), start_of(c, idx[1], b0), start_of(c, idx[2], c0);
    end_of(c, idx[0], a1), end_of(c, idx[1], b1), end_of(c, idx[2], c1);
    *d2 = wc_point_triangle_closest(v1, a1, b1, c1, w);
    int hit = *d2 < r * r * (1.0 - SLACK);
    if (!hit && ccd)
        hit = wc_ccd_point_triangle(v0, v1, a0, a1, b0, b1, c0, c1, 1e-9 * r, &tc, w);
    if (!hit) return 0;
    double ab0[3], ac0[3], ab1[3], ac1[3];
    for (int d = 0; d < 3; ++d) {
        ab0[d] = b0[d] - a0[d], ac0[d] = c0[d] - a0[d];
        ab1[d] = b1[d] - a1[d], ac1[d] = c1[d] - a1[d];
    }
    /* crushed flat at either end: the edges decide */
    if (!turning_cross(ab0, ab1, ac0, ac1, n0, n1)) return 0;
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

/* The way an edge-edge contact pushes the cloth's edge, from the collider's
 * closest point toward the cloth's (unit, into n): `start_gap` and
 * `end_gap` join the closest points' places at the start and end of the
 * step, the edges run p-q (collider) and a-b (cloth). `crossed` says the
 * continuous test saw the edges meet; `ccd` that they moved far enough to
 * need it. Returns 0 for edges parallel at the start or end: the vertices
 * decide those. */
static int edge_push_normal(const double p0[3], const double p1[3], const double q0[3],
                            const double q1[3], const double a0[3], const double a1[3],
                            const double b0[3], const double b1[3], const double start_gap[3],
                            const double end_gap[3], int ccd, int crossed, double r, double n[3])
{
    /* Near at the end after a large motion without meeting on the way: the
     * cloth's edge is on its side still, and the line between the closest
     * points is the way out. The side judged at the start along the edges'
     * common normal is not reliable there: the closest points at the start
     * can lie elsewhere, and the normal of two nearly parallel edges swings
     * (both happen to cloth edges sliding over a sphere's edges at 8
     * implicit steps per frame; judged so, the push took the cloth into the
     * sphere). */
    double gap = sqrt(dot3(end_gap, end_gap)), t, sp, u;
    if (ccd && !crossed && gap > 1e-3 * r &&
        !wc_ccd_edge_edge(p0, p1, q0, q1, a0, a1, b0, b1, 1e-9 * r, &t, &sp, &u)) {
        for (int d = 0; d < 3; ++d) n[d] = end_gap[d] / gap;
        return 1;
    }
    /* They met, or moved too little to have come round, or touch at the
     * end: the side they were on at the start decides. */
    double dp0[3], de0[3], dp1[3], de1[3], m0[3], m1[3];
    for (int d = 0; d < 3; ++d) {
        dp0[d] = q0[d] - p0[d], de0[d] = b0[d] - a0[d];
        dp1[d] = q1[d] - p1[d], de1[d] = b1[d] - a1[d];
    }
    if (!turning_cross(dp0, dp1, de0, de1, m0, m1)) return 0;
    double side = dot3(start_gap, m0);
    if (side == 0.0) side = dot3(end_gap, m1);
    for (int d = 0; d < 3; ++d) n[d] = (side < 0.0 ? -1.0 : 1.0) * m1[d];
    return 1;
}

/* Collider edge (p, q) against cloth edge e; their boxes over the step
 * overlap (the edge grid's query saw to it). `ccd` and *d2 as for
 * vertex_triangle. */
static int edge_edge(wc_cloth *c, wc_feature_state *s, int32_t e, const double p0[3],
                     const double p1[3], const double q0[3], const double q1[3], int ccd,
                     double r, double mu, double dt, double *d2)
{
    const int32_t *idx = s->edges + 2 * (size_t)e;
    double a0[3], b0[3], a1[3], b1[3], sp, u, tc;
    start_of(c, idx[0], a0), start_of(c, idx[1], b0);
    end_of(c, idx[0], a1), end_of(c, idx[1], b1);
    *d2 = wc_segment_segment_closest(p1, q1, a1, b1, &sp, &u);
    int hit = *d2 < r * r * (1.0 - SLACK), crossed = 0;
    if (!hit && ccd)
        hit = crossed = wc_ccd_edge_edge(p0, p1, q0, q1, a0, a1, b0, b1, 1e-9 * r, &tc, &sp, &u);
    if (!hit) return 0;
    /* A contact at an end of either edge is a vertex's business (a cloth
     * particle against a face, or a collider vertex against a triangle). */
    if (sp <= 0.0 || sp >= 1.0 || u <= 0.0 || u >= 1.0) return 0;
    double c0[3], c1[3], e0[3], e1[3], start_gap[3], end_gap[3], n[3];
    lerp3(p0, q0, sp, c0), lerp3(p1, q1, sp, c1);
    lerp3(a0, b0, u, e0), lerp3(a1, b1, u, e1);
    for (int d = 0; d < 3; ++d) start_gap[d] = e0[d] - c0[d], end_gap[d] = e1[d] - c1[d];
    if (!edge_push_normal(p0, p1, q0, q1, a0, a1, b0, b1, start_gap, end_gap, ccd, crossed, r, n))
        return 0;
    double w[2] = {1.0 - u, u}, v_feature[3];
    for (int d = 0; d < 3; ++d) v_feature[d] = ((1.0 - sp) * (p1[d] - p0[d]) + sp * (q1[d] - q0[d])) / dt;
    return push_element(c, s, idx, w, 2, n, dot3(end_gap, n), r, v_feature, mu, dt);
}

/* ------------------------------------------------------------------------ */
/* Clearances (near_list.h)                                                 */
/* ------------------------------------------------------------------------ */

/* How far the element's particles (their ends) have gone at most since
 * its clearances were measured: the longest path since. */
static double drift(const wc_feature_state *s, const double *path_at, const int32_t *idx, int count)
{
    double m = 0.0;
    for (int k = 0; k < count; ++k) m = max2(m, s->path[idx[k]] - path_at[k]);
    return m;
}

/* Distance between two boxes: no point of one is nearer to a point of
 * the other. */
static double box_gap(const double a[6], const double b[6])
{
    double g2 = 0.0;
    for (int k = 0; k < 3; ++k) {
        double g = max2(0.0, max2(b[k] - a[k + 3], a[k] - b[k + 3]));
        g2 += g * g;
    }
    return sqrt(g2);
}

/* Box around the element's particles at the end of the step. */
static void end_box(const wc_cloth *c, const int32_t *idx, int count, double box[6])
{
    for (int k = 0; k < 3; ++k) box[k] = INFINITY, box[k + 3] = -INFINITY;
    for (int p = 0; p < count; ++p) {
        double e[3];
        end_of(c, idx[p], e);
        for (int k = 0; k < 3; ++k) box[k] = min2(box[k], e[k]), box[k + 3] = max2(box[k + 3], e[k]);
    }
}

/* After a visit of near-list element k: its clearances were measured at
 * the particles' present ends, unless a push moved them part-way through
 * the candidates, which leaves them unknown until the next visit. */
static void settle_clearances(const wc_feature_state *s, wc_near_elements *near, int32_t k,
                              const int32_t *idx, int count, int pushed, double least)
{
    double *clearance = near->clearance + near->start[k];
    int32_t n = near->start[k + 1] - near->start[k];
    if (pushed) {
        for (int32_t j = 0; j < n; ++j) clearance[j] = -1.0;
        near->least_clearance[k] = -1.0;
        return;
    }
    double *at = near->path_at + (size_t)count * (size_t)k;
    for (int p = 0; p < count; ++p) at[p] = s->path[idx[p]];
    near->least_clearance[k] = least;
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

/* One cloth element's visit: what it needs to know about itself before
 * its candidates are tested. */
typedef struct element_visit {
    const int32_t *idx; /* its particles */
    int count;          /* 3 for a triangle, 2 for an edge */
    double motion2;     /* largest squared motion of its particles */
    double drift;       /* from where its clearances were measured */
    double box[6];      /* over the step, grown by the largest contact distance */
    double end[6];      /* at the end of the step, made when first needed */
    int has_end;
} element_visit;

/* Whether the element must be visited at all: with a near list only if it
 * has drifted as far as its least clearance or moves enough for
 * continuous detection. */
static int must_visit(const wc_feature_state *s, const wc_near_elements *near, int32_t k,
                      double limit2, element_visit *v)
{
    v->motion2 = element_motion2(s, v->idx, v->count);
    v->has_end = 0;
    v->drift = 0.0;
    if (!near) return 1;
    v->drift = drift(s, near->path_at + (size_t)v->count * (size_t)k, v->idx, v->count);
    return v->motion2 > limit2 || !(v->drift < near->least_clearance[k]);
}

/* A candidate's clearance from the element's present ends when the pair
 * needs no test: its last one less the drift since, while that is left
 * (and no continuous detection is needed); else, when the boxes are apart
 * (the pair cannot touch), from the boxes. Negative when the pair must be
 * tested.
 *
 * A skipped pair is at least its clearance beyond the reach (REACH r)
 * apart, and a contact needs it nearer than r sqrt(1 - SLACK), 1.3e-5 r
 * nearer still: far more than the rounding of the few operations behind a
 * clearance, so skipping never misses a contact the test would have
 * found. */
static double untested_clearance(const wc_cloth *c, const wc_near_elements *near, int32_t k,
                                 int32_t j, element_visit *v, const double *feature_box, int ccd,
                                 double r)
{
    double last = near ? near->clearance[near->start[k] + j] : -1.0;
    if (!ccd && last > v->drift) return last - v->drift;
    if (wc_boxes_overlap(v->box, feature_box)) return -1.0;
    if (!near) return 0.0;
    if (!v->has_end) end_box(c, v->idx, v->count, v->end), v->has_end = 1;
    return max2(0.0, box_gap(v->end, feature_box) - REACH * r);
}

/* Collider vertices against cloth triangles, or collider edges against
 * cloth edges: what a pass over one kind of cloth element needs. */
typedef struct element_kind {
    int count;                  /* particles per element */
    int feature_count;          /* collider vertices per feature */
    const wc_grid *grid;        /* the collider's grid of these features */
    const double *feature_boxes; /* their boxes, 6 per feature */
    double ccd_limit2;          /* ccd_limit2 of the collider's contact distance */
} element_kind;

static element_kind triangles_of(const wc_collider *col, double r)
{
    element_kind kind = {3, 1, &col->vertex_grid, col->vertex_boxes, ccd_limit2(r)};
    return kind;
}

static element_kind edges_of(const wc_collider *col, double r)
{
    element_kind kind = {2, 2, &col->edge_grid, col->edge_boxes, ccd_limit2(r)};
    return kind;
}

/* Collider vertex indices of feature `id`. */
static const int32_t *feature_vertices(const wc_collider *col, const element_kind *kind,
                                       const int32_t *id)
{
    return kind->feature_count == 1 ? id : col->edges + 2 * (size_t)*id;
}

/* The exact test of cloth element `element` against a collider feature
 * (its vertices `f`); as vertex_triangle and edge_edge. */
static int test_pair(wc_cloth *c, wc_feature_state *s, const wc_collider *col,
                     const element_kind *kind, int32_t element, const int32_t *f, int ccd,
                     double r, double mu, double dt, double *d2)
{
    double p0[3], p1[3], q0[3], q1[3];
    vertex_of(col->current, f[0], p0);
    vertex_of(col->next, f[0], p1);
    if (kind->feature_count == 1)
        return vertex_triangle(c, s, element, p0, p1, ccd, r, mu, dt, d2);
    vertex_of(col->current, f[1], q0);
    vertex_of(col->next, f[1], q1);
    return edge_edge(c, s, element, p0, p1, q0, q1, ccd, r, mu, dt, d2);
}

/* Element k (its slot in the near list, else its id) against the collider
 * features near it, testing those it may touch. Returns 1 if anything
 * moved, 0 if not, -1 on out-of-memory. */
static int visit_element(wc_cloth *c, wc_feature_state *s, const wc_collider *col,
                         wc_near_elements *near, const element_kind *kind, int32_t k, double r,
                         double mu, double dt)
{
    int32_t element = near ? near->element[k] : k;
    const int32_t *particles = kind->count == 3 ? c->topology.triangles : s->edges;
    element_visit v;
    v.idx = particles + (size_t)kind->count * (size_t)element, v.count = kind->count;
    if (!must_visit(s, near, k, kind->ccd_limit2, &v)) return 0;
    /* triangles grow by the largest contact distance, as their near lists
     * were made; edges by this collider's */
    element_box(c, v.idx, v.count, kind->count == 3 ? s->r_max : r, v.box);
    if (!wc_boxes_overlap(v.box, col->bounds)) return 0;
    const int32_t *found;
    int32_t n = features_near(s, near, k, kind->grid, v.box, &found);
    if (n < 0) return -1;
    int pushed = 0;
    double least = INFINITY;
    for (int32_t j = 0; j < n; ++j) {
        const int32_t *f = feature_vertices(col, kind, found + j);
        int ccd = pair_needs_ccd(col, v.motion2, f, kind->feature_count, kind->ccd_limit2);
        double clear = untested_clearance(c, near, k, j, &v,
                                          kind->feature_boxes + 6 * (size_t)found[j], ccd, r);
        if (clear < 0.0) {
            double d2;
            pushed |= test_pair(c, s, col, kind, element, f, ccd, r, mu, dt, &d2);
            clear = sqrt(d2) - REACH * r;
        }
        if (near) near->clearance[near->start[k] + j] = clear;
        least = min2(least, clear);
    }
    if (near) settle_clearances(s, near, k, v.idx, v.count, pushed, least);
    return pushed;
}

/* Into s->visit_list, ascending, the elements (slots in the near list, else
 * ids) with a particle the last pass moved; returns how many. They are
 * marked first and then read off in order between the least and the
 * greatest marked, which spares a sort. */
static int32_t moved_elements(wc_feature_state *s, const wc_near_elements *near,
                              const element_kind *kind)
{
    const int32_t *start = kind->count == 3 ? s->triangles_start : s->edges_start;
    const int32_t *items = kind->count == 3 ? s->triangles_of : s->edges_of;
    int32_t lo = INT32_MAX, hi = -1;
    for (int32_t m = 0; m < s->moved_count; ++m) {
        int32_t i = s->moved_list[m];
        for (int32_t j = start[i]; j < start[i + 1]; ++j) {
            int32_t k = near ? near->slot_of[items[j]] : items[j];
            if (k < 0) continue;
            s->visit_mark[k] = 1;
            if (k < lo) lo = k;
            if (k > hi) hi = k;
        }
    }
    int32_t n = 0;
    for (int32_t k = lo; k <= hi; ++k)
        if (s->visit_mark[k]) s->visit_mark[k] = 0, s->visit_list[n++] = k;
    return n;
}

/* One kind of cloth element against the collider's features: in the first
 * pass every element near the collider, in a later one only those with a
 * particle the last pass moved (nothing else can have changed), in the
 * same ascending order. Returns 1 if anything moved, 0 if not, -1 on
 * out-of-memory. */
static int element_pass(wc_cloth *c, wc_feature_state *s, const wc_collider *col,
                        wc_near_elements *near, const element_kind *kind, double r, double mu,
                        double dt)
{
    int moved = 0;
    int32_t count = s->only_moved ? moved_elements(s, near, kind)
                    : near        ? near->count
                    : kind->count == 3 ? s->triangle_count : s->edge_count;
    for (int32_t m = 0; m < count; ++m) {
        int32_t k = s->only_moved ? s->visit_list[m] : m;
        int result = visit_element(c, s, col, near, kind, k, r, mu, dt);
        if (result < 0) return -1;
        moved |= result;
    }
    return moved;
}

/* One pass of a collider against the cloth, from the cloth's side: its
 * vertices against the cloth's triangles, its edges against the cloth's
 * edges; for a static collider the near list remembers the candidates
 * (and their clearances) across steps. Returns 1 if anything moved, 0 if
 * not, -1 on out-of-memory. */
static int collider_pass(wc_cloth *c, wc_feature_state *s, const wc_collider *col,
                         wc_near_list *near, double r, double mu, double dt)
{
    if (!near) {
        /* every element is visited: first see whether the cloth is near at all */
        double bounds[6];
        cloth_bounds(c, s->r_max, bounds);
        if (!wc_boxes_overlap(col->bounds, bounds)) return 0;
    }
    element_kind triangles = triangles_of(col, r), edges = edges_of(col, r);
    int moved = element_pass(c, s, col, near ? &near->triangles : NULL, &triangles, r, mu, dt);
    if (moved < 0) return -1;
    int edges_moved = element_pass(c, s, col, near ? &near->edges : NULL, &edges, r, mu, dt);
    return edges_moved < 0 ? -1 : moved | edges_moved;
}

/* The near list of collider k, made to hold for this pass; NULL when the
 * collider moves (its grids are rebuilt every step, so there is nothing to
 * keep). -1 in *status on out-of-memory. */
static wc_near_list *near_list_for(wc_cloth *c, wc_feature_state *s, int32_t k,
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
    /* in a pass after the first only the particles that pass marked moved
     * can have left their boxes since the list was last found to hold */
    if (wc_near_list_holds(l, c, col, r_triangles, r, 2 * r, s->only_moved ? s->moved_list : NULL,
                           s->moved_count))
        return l;
    if (wc_near_list_build(l, c, s->edges, s->edge_count, col, r_triangles, r, 2 * r))
        return *failed = 1, NULL;
    return l;
}

/* Zeroes a flag array through its list and empties the list. */
static void clear_marks(uint8_t *flags, const int32_t *list, int32_t *count)
{
    for (int32_t k = 0; k < *count; ++k) flags[list[k]] = 0;
    *count = 0;
}

wc_status wc_collide_features(wc_cloth *c, wc_feature_state *s, wc_collider *const *colliders,
                              int32_t count, double dt, int all, wc_step_stats *stats,
                              int *moved_out)
{
    *moved_out = 0;
    double h = c->material.thickness, r_max = 0.0;
    int any = 0;
    for (int32_t k = 0; k < count; ++k)
        if (colliders[k]->is_mesh) r_max = max2(r_max, h + colliders[k]->thickness), any = 1;
    if (!any) return WC_OK;
    s->r_max = r_max;
    /* the first pass looks at what the particle pass moved as if a pass of
     * its own had moved it */
    clear_marks(s->moved, s->moved_list, &s->moved_count);
    clear_marks(s->moving, s->moving_list, &s->moving_count);
    for (int32_t i = 0; i < c->particle_count && !all; ++i)
        if (s->marks.shifted[i]) s->moved[i] = 1, s->moved_list[s->moved_count++] = i;
    memset(s->marks.shifted, 0, (size_t)c->particle_count);
    /* the particles' paths are up to date: wc_feature_state_begin_step
     * started them for this step, and every move since was tracked */
    int moved = 1;
    for (int pass = 0; pass < MAX_PASSES && moved; ++pass) {
        s->only_moved = pass > 0 || !all;
        clear_marks(s->moving, s->moving_list, &s->moving_count);
        moved = 0;
        for (int32_t k = 0; k < count; ++k) {
            const wc_collider *col = colliders[k];
            if (!col->is_mesh) continue;
            double r = fmax(h + col->thickness, 1e-6);
            int failed;
            wc_near_list *near = near_list_for(c, s, k, col, r_max, r, &failed);
            if (failed) return WC_ERROR_OUT_OF_MEMORY;
            int result = collider_pass(c, s, col, near, r, sqrt(c->material.friction * col->friction), dt);
            if (result < 0) return WC_ERROR_OUT_OF_MEMORY;
            moved |= result;
        }
        uint8_t *swap = s->moved;
        s->moved = s->moving, s->moving = swap;
        int32_t *swap_list = s->moved_list, swap_count = s->moved_count;
        s->moved_list = s->moving_list, s->moved_count = s->moving_count;
        s->moving_list = swap_list, s->moving_count = swap_count;
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
        s->marks.shifted[i] = 1;
        track_particle(c, s, i);
        stats->failsafe_particles++;
    }
    return WC_OK;
}
