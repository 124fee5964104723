#include "collide.h"

#include <math.h>
#include <string.h>

#include "collide_features.h"
#include "convex.h"
#include "near_list.h"
#include "parallel.h"
#include "primitives.h"

/* A contact distance of zero would leave a resting particle exactly in the
 * surface, where the side it came from is ambiguous; keep it at least this. */
#define MIN_CONTACT_DISTANCE 1e-6
/* Projections per particle per step: enough for a particle wedged in a
 * concave corner of two or three surfaces; past it the fail-safe applies. */
#define MAX_PASSES 4
/* Candidate triangles a particle keeps on the stack; more than this (a
 * collider far finer than the cloth) falls back to testing every triangle. */
#define MAX_CANDIDATES 256
/* A particle skips a collider while its clearance exceeds its drift by
 * this fraction of the contact distance: far more than rounding. */
#define CLEARANCE_MARGIN 1e-6
/* near_slot's answer for a particle its near list gives no triangle. */
#define NO_CANDIDATES (-2)

static double dot3(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static void corner(const double *xyz, int32_t v, double out[3])
{
    out[0] = xyz[3 * (size_t)v], out[1] = xyz[3 * (size_t)v + 1], out[2] = xyz[3 * (size_t)v + 2];
}

static void bary_point(const double a[3], const double b[3], const double c[3], const double w[3],
                       double out[3])
{
    for (int k = 0; k < 3; ++k) out[k] = w[0] * a[k] + w[1] * b[k] + w[2] * c[k];
}

/* ------------------------------------------------------------------------ */
/* Colliders over a step                                                    */
/* ------------------------------------------------------------------------ */

static void grow_box(double box[6], const double p[3])
{
    for (int k = 0; k < 3; ++k) {
        if (p[k] < box[k]) box[k] = p[k];
        if (p[k] > box[k + 3]) box[k + 3] = p[k];
    }
}

static void empty_box(double box[6])
{
    for (int k = 0; k < 3; ++k) box[k] = INFINITY, box[k + 3] = -INFINITY;
}

static wc_status mesh_begin_step(wc_collider *c, double share)
{
    size_t nv = 3 * (size_t)c->vertex_count;
    if (c->moving && share >= 1.0)
        memcpy(c->next, c->target, nv * sizeof *c->next); /* exactly there: static again */
    else if (c->moving)
        for (size_t k = 0; k < nv; ++k) c->next[k] = wc_lerp(c->current[k], c->target[k], share);
    else if (c->grid_static)
        return WC_OK; /* static and indexed: nothing to do */
    else
        memcpy(c->next, c->current, nv * sizeof *c->next);
    empty_box(c->bounds);
    double extent = 0.0;
    for (int32_t t = 0; t < c->triangle_count; ++t) {
        double *box = c->boxes + 6 * (size_t)t, p0[3][3], p1[3][3];
        empty_box(box);
        for (int k = 0; k < 3; ++k) {
            corner(c->current, c->triangles[3 * (size_t)t + k], p0[k]);
            grow_box(box, p0[k]);
            corner(c->next, c->triangles[3 * (size_t)t + k], p1[k]);
            grow_box(box, p1[k]);
        }
        wc_triangle_normal(p0[0], p0[1], p0[2], c->normal_current + 3 * (size_t)t);
        wc_triangle_normal(p1[0], p1[1], p1[2], c->normal_next + 3 * (size_t)t);
        extent += fmax(box[3] - box[0], fmax(box[4] - box[1], box[5] - box[2]));
        grow_box(c->bounds, box);
        grow_box(c->bounds, box + 3);
    }
    /* Cells about one triangle across: each triangle lands in a few cells
     * and a particle's query visits a few. */
    double cell = extent / c->triangle_count;
    if (!(cell > 1e-9)) cell = 1e-9;
    wc_status s = wc_grid_build(&c->grid, c->boxes, c->triangle_count, cell);
    /* Vertices and edges get grids of their own for the feature pass. */
    for (int32_t v = 0; v < c->vertex_count && !s; ++v) {
        double *box = c->vertex_boxes + 6 * (size_t)v, p[3];
        empty_box(box);
        corner(c->current, v, p), grow_box(box, p);
        corner(c->next, v, p), grow_box(box, p);
    }
    for (int32_t e = 0; e < c->edge_count && !s; ++e) {
        double *box = c->edge_boxes + 6 * (size_t)e, p[3];
        empty_box(box);
        for (int k = 0; k < 2; ++k) {
            corner(c->current, c->edges[2 * e + k], p), grow_box(box, p);
            corner(c->next, c->edges[2 * e + k], p), grow_box(box, p);
        }
    }
    if (!s) s = wc_grid_build(&c->vertex_grid, c->vertex_boxes, c->vertex_count, cell);
    if (!s) s = wc_grid_build(&c->edge_grid, c->edge_boxes, c->edge_count, cell);
    c->grid_static = !c->moving && s == WC_OK;
    c->grid_version++;
    return s;
}

static void convex_begin_step(wc_collider *c, double share)
{
    if (c->moving && share >= 1.0) c->pose_next = c->pose_target;
    else if (c->moving) wc_pose_lerp(&c->pose_current, &c->pose_target, share, &c->pose_next);
    else c->pose_next = c->pose_current;
    empty_box(c->bounds);
    const double *p0 = c->pose_current.position, *p1 = c->pose_next.position;
    double r = c->convex.bound_radius;
    for (int k = 0; k < 3; ++k) {
        c->bounds[k] = fmin(p0[k], p1[k]) - r;
        c->bounds[k + 3] = fmax(p0[k], p1[k]) + r;
    }
}

wc_status wc_collider_begin_step(wc_collider *c, double share)
{
    if (c->is_mesh) return mesh_begin_step(c, share);
    convex_begin_step(c, share);
    return WC_OK;
}

void wc_collider_end_step(wc_collider *c)
{
    if (!c->moving) return;
    if (c->is_mesh) {
        size_t bytes = 3 * (size_t)c->vertex_count * sizeof *c->current;
        memcpy(c->current, c->next, bytes);
        c->moving = memcmp(c->current, c->target, bytes) != 0;
    } else {
        c->pose_current = c->pose_next;
        c->moving = memcmp(&c->pose_current, &c->pose_target, sizeof c->pose_current) != 0;
    }
}

/* ------------------------------------------------------------------------ */
/* One particle                                                             */
/* ------------------------------------------------------------------------ */

/* A particle's motion over the step and what the response has made of it. */
typedef struct particle_motion {
    double start[3]; /* position at the start of the step */
    double end[3];   /* position at the end, as corrected so far */
    double vel[3];   /* velocity after the step, as corrected so far */
    double normal[3];
    /* velocity of the surface point it last touched (for the fail-safe) */
    double surface_velocity[3];
    /* factor on the tangential velocity from wet friction: 1 - w (1 - q) in
     * sustained contact (touching in the last step too), else 1 */
    double wet_keep;
    int touched;
    /* where the velocity so far is measured from (the history override if
     * an earlier response this step set one); the velocity itself is made
     * at the first response, as most particles get none */
    double from[3];
    int has_velocity;
} particle_motion;

/* The response to one contact (thesis eq. 2.7, corrected): with the surface
 * point moving at v_surface and the normal n toward the particle, remove the
 * approaching normal part of the relative velocity and let Coulomb friction
 * take at most mu times that change off the tangential part (mu is the
 * square root of `friction`, the product of the two coefficients). The same
 * tangential reduction is applied to this step's displacement, so a
 * particle held by friction does not slide during the step either: to the
 * displacement the particle has at its new place, which for a particle
 * stopped where its path met the surface is only the part up to there.
 * Taken off the whole step's motion instead, the reduction would put such
 * a particle behind where it started, against its motion: at large steps
 * that ratchet pushed the cloth outward round the sphere's pole every step
 * until its links there stretched without bound. */
static void respond(particle_motion *m, const double surface[3], const double n[3],
                    const double v_surface[3], double r, double friction, double wet_keep, double dt)
{
    double rel[3], vn, tangent[3], speed_t, mu = sqrt(friction);
    if (!m->has_velocity)
        for (int k = 0; k < 3; ++k) m->vel[k] = (m->end[k] - m->from[k]) / dt;
    m->has_velocity = 1;
    for (int k = 0; k < 3; ++k) {
        m->end[k] = surface[k] + n[k] * r;
        rel[k] = m->vel[k] - v_surface[k];
    }
    vn = dot3(rel, n);
    if (vn < 0.0) {
        for (int k = 0; k < 3; ++k) tangent[k] = rel[k] - vn * n[k];
        speed_t = sqrt(dot3(tangent, tangent));
        double keep = speed_t > 0.0 ? 1.0 - mu * (-vn) / speed_t : 1.0;
        if (keep < 0.0) keep = 0.0;
        keep *= wet_keep; /* wet friction (thesis eq. 2.10) in sustained contact */
        double moved[3];
        for (int k = 0; k < 3; ++k) moved[k] = m->end[k] - m->from[k] - v_surface[k] * dt;
        double moved_n = dot3(moved, n);
        for (int k = 0; k < 3; ++k) {
            m->end[k] -= (1.0 - keep) * (moved[k] - moved_n * n[k]);
            m->vel[k] = v_surface[k] + keep * tangent[k];
        }
    }
    for (int k = 0; k < 3; ++k) m->normal[k] = n[k], m->surface_velocity[k] = v_surface[k];
    m->touched = 1;
}

/* Which side of a triangle the particle belongs on: the side it was on at
 * the start of the step (it never crossed before), else the side it is on
 * now, else the front. */
static double side_of(const particle_motion *m, const double corner0[3], const double n0[3],
                      const double end_offset[3], const double n1[3])
{
    double rel[3] = {m->start[0] - corner0[0], m->start[1] - corner0[1], m->start[2] - corner0[2]};
    double s = dot3(rel, n0);
    if (s == 0.0) s = dot3(end_offset, n1);
    return s < 0.0 ? -1.0 : 1.0;
}

/* Static triangle: the thesis' test (eq. 2.5-2.6). The motion crosses the
 * plane when the signed distances at its two ends differ in sign; the
 * crossing point C = start + d_s / (d_s + d_e) (end - start) must lie in the
 * triangle (within the contact distance). */
static int crosses_static(const particle_motion *m, double t0[3][3], const double n[3], double r,
                          double w[3])
{
    double ds = (m->start[0] - t0[0][0]) * n[0] + (m->start[1] - t0[0][1]) * n[1] +
                (m->start[2] - t0[0][2]) * n[2];
    double de = (m->end[0] - t0[0][0]) * n[0] + (m->end[1] - t0[0][1]) * n[1] +
                (m->end[2] - t0[0][2]) * n[2];
    if (ds * de > 0.0 || (ds == 0.0 && de == 0.0)) return 0;
    double f = ds / (ds - de), cross[3];
    for (int k = 0; k < 3; ++k) cross[k] = m->start[k] + (m->end[k] - m->start[k]) * f;
    return wc_point_triangle_closest(cross, t0[0], t0[1], t0[2], w) <= r * r;
}

/* Tests one collider triangle; returns 1 when it moved the particle. */
static int mesh_triangle(particle_motion *m, const wc_collider *c, int32_t t, double r, double friction,
                         double dt)
{
    const double *n0 = c->normal_current + 3 * (size_t)t, *n1 = c->normal_next + 3 * (size_t)t;
    if (n1[0] == 0.0 && n1[1] == 0.0 && n1[2] == 0.0) return 0; /* degenerate: ignored */
    if (!c->moving) {
        /* Cheap rejection for a static triangle: the particle stays on one
         * side of its plane, farther than r at the end of the step. */
        const double *a = c->current + 3 * (size_t)c->triangles[3 * (size_t)t];
        double ds = (m->start[0] - a[0]) * n0[0] + (m->start[1] - a[1]) * n0[1] + (m->start[2] - a[2]) * n0[2];
        double de = (m->end[0] - a[0]) * n0[0] + (m->end[1] - a[1]) * n0[1] + (m->end[2] - a[2]) * n0[2];
        if (ds * de > 0.0 && fabs(de) >= r) return 0;
    }
    double t0[3][3], t1[3][3], w[3], cp[3], tc, offset[3];
    for (int k = 0; k < 3; ++k) {
        corner(c->current, c->triangles[3 * (size_t)t + k], t0[k]);
        corner(c->next, c->triangles[3 * (size_t)t + k], t1[k]);
    }
    double d2 = wc_point_triangle_closest(m->end, t1[0], t1[1], t1[2], w);
    bary_point(t1[0], t1[1], t1[2], w, cp);
    for (int k = 0; k < 3; ++k) offset[k] = m->end[k] - cp[k];
    double side = side_of(m, t0[0], n0, offset, n1);
    /* A particle the last pass put at distance r may sit a rounding error
     * inside it; the slack keeps it from counting as a new contact. */
    int hit = d2 < r * r * (1.0 - 1e-9);
    /* Crossed the surface during the step (possibly far through it). For a
     * moving triangle the coplanarity cubic on the relative motion finds
     * when. The contact is then placed where the particle met the triangle,
     * on the end-of-step triangle. */
    if (!hit) {
        hit = c->moving ? wc_ccd_point_triangle(m->start, m->end, t0[0], t1[0], t0[1], t1[1],
                                                t0[2], t1[2], r, &tc, w)
                        : crosses_static(m, t0, n0, r, w);
        if (hit) {
            bary_point(t1[0], t1[1], t1[2], w, cp);
            for (int k = 0; k < 3; ++k) offset[k] = 0.0;
        }
    }
    if (!hit) return 0;
    double n[3], len = sqrt(dot3(offset, offset));
    /* Off an edge or corner, on the particle's own side: push along the
     * offset (smooth round edges). In the face region, or on the wrong
     * side, push along the face normal to the particle's side. */
    if (len > 1e-12 * r && dot3(offset, n1) * side > 0.0)
        for (int k = 0; k < 3; ++k) n[k] = offset[k] / len;
    else
        for (int k = 0; k < 3; ++k) n[k] = side * n1[k];
    double p0[3], v_surface[3];
    bary_point(t0[0], t0[1], t0[2], w, p0);
    for (int k = 0; k < 3; ++k) v_surface[k] = (cp[k] - p0[k]) / dt;
    respond(m, cp, n, v_surface, r, friction, m->wet_keep, dt);
    return 1;
}

/* Candidate triangles of one mesh collider for one particle, found once per
 * step and kept across the passes: the query box covers the particle's
 * motion grown by twice the contact distance, and a later pass queries
 * again only if the corrected end has left that box shrunk by r. */
typedef struct candidates {
    double box[6];
    int32_t count; /* -1: not queried yet */
    int32_t found[MAX_CANDIDATES];
} candidates;

/* The grid's answer for cand->box, or the same answer from the near list
 * (its candidates that meet the box) while the particle is inside the box
 * the list was made with. */
static void query_candidates(candidates *cand, const particle_motion *m, const wc_collider *c,
                             const wc_near_list *near, int32_t particle, double r)
{
    if (cand->count >= 0) {
        int inside = 1;
        for (int k = 0; k < 3; ++k)
            inside &= m->end[k] >= cand->box[k] + r && m->end[k] <= cand->box[k + 3] - r;
        if (inside) return;
    }
    empty_box(cand->box);
    grow_box(cand->box, m->start);
    grow_box(cand->box, m->end);
    for (int k = 0; k < 3; ++k) cand->box[k] -= 2 * r, cand->box[k + 3] += 2 * r;
    const int32_t *listed;
    int32_t listed_count;
    if (near && wc_near_list_particle(near, c, 2 * r, particle, m->start[0], m->start[1],
                                      m->start[2], m->end[0], m->end[1], m->end[2], &listed,
                                      &listed_count)) {
        cand->count = 0;
        for (int32_t k = 0; k < listed_count; ++k)
            if (wc_boxes_overlap(cand->box, c->boxes + 6 * (size_t)listed[k])) {
                if (cand->count < MAX_CANDIDATES) cand->found[cand->count] = listed[k];
                cand->count++;
            }
        return;
    }
    cand->count = wc_boxes_overlap(cand->box, c->bounds)
                      ? wc_grid_query(&c->grid, cand->box, cand->found, MAX_CANDIDATES)
                      : 0;
}

/* A lower bound, less r, on the distance from the particle's end to every
 * triangle in `listed`: for each the larger of its distance to the
 * triangle's plane and to the triangle's box, both no more than its
 * distance to the triangle. Degenerate triangles are never tested. */
static double particle_clearance(const particle_motion *m, const wc_collider *c,
                                 const int32_t *listed, int32_t count, double r)
{
    double least = INFINITY;
    for (int32_t k = 0; k < count; ++k) {
        int32_t t = listed[k];
        const double *n = c->normal_current + 3 * (size_t)t, *box = c->boxes + 6 * (size_t)t;
        if (n[0] == 0.0 && n[1] == 0.0 && n[2] == 0.0) continue;
        const double *a = c->current + 3 * (size_t)c->triangles[3 * (size_t)t];
        double plane = fabs((m->end[0] - a[0]) * n[0] + (m->end[1] - a[1]) * n[1] + (m->end[2] - a[2]) * n[2]);
        double gap2 = 0.0;
        for (int j = 0; j < 3; ++j) {
            double below = box[j] - m->end[j], above = m->end[j] - box[j + 3];
            if (below > 0.0) gap2 += below * below;
            else if (above > 0.0) gap2 += above * above;
        }
        double distance = sqrt(gap2);
        if (plane > distance) distance = plane;
        if (distance < least) least = distance;
    }
    return least - r;
}

/* The particle's slot in the near list's particle part when the list
 * holds for its motion and gives it candidates; NO_CANDIDATES when it
 * holds and gives none (nothing near: the particle is done with this
 * collider); else -1. */
static int32_t near_slot(const wc_near_list *near, const particle_motion *m, const wc_collider *c,
                         int32_t particle, double r, const int32_t **listed, int32_t *count)
{
    if (!near || !wc_near_list_particle(near, c, 2 * r, particle, m->start[0], m->start[1],
                                        m->start[2], m->end[0], m->end[1], m->end[2], listed, count))
        return -1;
    return *count ? near->particle_slot[particle] : NO_CANDIDATES;
}

/* One mesh collider against one particle. In the first test of a particle
 * nothing has moved yet this round, a static collider's near list keeps
 * the particle's clearance (near_list.h): while its start and end stay
 * within it of where it was measured, nothing can touch and the tests are
 * skipped; else they run, and if they move nothing it is measured anew.
 * A contact needs the particle within r; the margin covers rounding. */
static int mesh_collider(particle_motion *m, const wc_collider *c, wc_near_list *near,
                         const wc_feature_state *fs, int first, int32_t particle,
                         candidates *cand, double r, double friction, double dt)
{
    const int32_t *listed = NULL;
    int32_t count = 0, slot = first && fs ? near_slot(near, m, c, particle, r, &listed, &count) : -1;
    if (slot == NO_CANDIDATES) return 0;
    wc_near_elements *kept = near ? &near->particles : NULL;
    if (slot >= 0 && wc_feature_state_drift(fs, particle, kept->path_at[slot]) + CLEARANCE_MARGIN * r <
                         kept->least_clearance[slot])
        return 0;
    query_candidates(cand, m, c, near, particle, r);
    int moved = 0;
    if (cand->count <= MAX_CANDIDATES) {
        for (int32_t k = 0; k < cand->count; ++k) moved |= mesh_triangle(m, c, cand->found[k], r, friction, dt);
    } else {
        /* more candidates than the buffer holds: test every triangle */
        for (int32_t t = 0; t < c->triangle_count; ++t)
            if (wc_boxes_overlap(cand->box, c->boxes + 6 * (size_t)t)) moved |= mesh_triangle(m, c, t, r, friction, dt);
    }
    if (slot >= 0) {
        kept->least_clearance[slot] = moved ? -1.0 : particle_clearance(m, c, listed, count, r);
        kept->path_at[slot] = wc_feature_state_path(fs, particle);
    }
    return moved;
}

/* Convex shapes move rigidly: the particle's motion is taken into the
 * shape's frame (start in the pose at the start of the step, end in the pose
 * at its end), where the shape stands still. */
static int convex_collider(particle_motion *m, const wc_collider *c, double r, double friction,
                           double dt)
{
    double box[6];
    empty_box(box);
    grow_box(box, m->start);
    grow_box(box, m->end);
    for (int k = 0; k < 3; ++k) box[k] -= r, box[k + 3] += r;
    if (!wc_boxes_overlap(box, c->bounds)) return 0;
    double a[3], b[3], out[3], n_local[3], surface[3], n[3], before[3], v_surface[3];
    wc_pose_to_local(&c->pose_current, m->start, a);
    wc_pose_to_local(&c->pose_next, m->end, b);
    if (!wc_convex_resolve(&c->convex, a, b, r, out, n_local)) return 0;
    wc_pose_rotate(&c->pose_next, n_local, n);
    /* the surface point under the particle, at the end and the start */
    for (int k = 0; k < 3; ++k) out[k] -= n_local[k] * r;
    wc_pose_to_world(&c->pose_next, out, surface);
    wc_pose_to_world(&c->pose_current, out, before);
    for (int k = 0; k < 3; ++k) v_surface[k] = (surface[k] - before[k]) / dt;
    respond(m, surface, n, v_surface, r, friction, m->wet_keep, dt);
    return 1;
}

void wc_collide_cloth(wc_cloth *cl, wc_collider *const *colliders, int32_t count, double dt,
                      int threads, int all, const wc_collide_marks *marks, wc_step_stats *stats)
{
    int32_t n = cl->particle_count;
    int failsafe = 0;
    double h = cl->material.thickness, mu_cloth = cl->material.friction;
    (void)threads;
#pragma omp parallel for schedule(dynamic, 256) num_threads(threads) if (n >= WC_PARALLEL_MIN) \
    reduction(+ : failsafe)
    for (int32_t i = 0; i < n; ++i) {
        if (cl->pin_slot[i] >= 0 || !(all || marks->recheck[i])) continue;
        marks->recheck[i] = 0;
        particle_motion m;
        m.start[0] = cl->x[i], m.start[1] = cl->y[i], m.start[2] = cl->z[i];
        m.end[0] = cl->nx[i], m.end[1] = cl->ny[i], m.end[2] = cl->nz[i];
        /* the velocity so far: through the history override if an earlier
         * response this step already set one */
        for (int k = 0; k < 3; ++k) m.from[k] = m.start[k];
        if (cl->history_override[i]) m.from[0] = cl->qx[i], m.from[1] = cl->qy[i], m.from[2] = cl->qz[i];
        m.has_velocity = 0;
        m.touched = 0;
        m.wet_keep = cl->contact_prev[i] != WC_CONTACT_NONE
                         ? 1.0 - cl->wetness[i] * (1.0 - cl->material.wet_friction)
                         : 1.0;
        /* One collider's candidates are kept across passes; with several
         * mesh colliders the others are queried again each pass. */
        candidates cand;
        int32_t cand_owner = -1;
        int moved = 1;
        for (int pass = 0; pass < MAX_PASSES && moved; ++pass) {
            moved = 0;
            for (int32_t c = 0; c < count; ++c) {
                const wc_collider *col = colliders[c];
                double r = h + col->thickness;
                if (r < MIN_CONTACT_DISTANCE) r = MIN_CONTACT_DISTANCE;
                /* the contact's mu is its square root, taken only for a
                 * response */
                double friction = mu_cloth * col->friction;
                if (col->is_mesh) {
                    if (cand_owner != c) cand.count = -1, cand_owner = c;
                    moved |= mesh_collider(&m, col, wc_feature_state_near_list(cl->features, c),
                                           cl->features, pass == 0 && !m.touched, i, &cand, r,
                                           friction, dt);
                } else {
                    moved |= convex_collider(&m, col, r, friction, dt);
                }
            }
        }
        if (!m.touched) continue;
        if (moved) {
            /* Still pushed around after every pass: wedged between
             * surfaces. Fail-safe: keep the place relative to the surface
             * it last touched that it had at the start of the step, free of
             * intersection: move with that surface (at rest if static). */
            for (int k = 0; k < 3; ++k) {
                m.vel[k] = m.surface_velocity[k];
                m.end[k] = m.start[k] + m.vel[k] * dt;
            }
            ++failsafe;
            marks->recheck[i] = 1;
        }
        marks->shifted[i] = 1;
        cl->nx[i] = m.end[0], cl->ny[i] = m.end[1], cl->nz[i] = m.end[2];
        if (cl->features) wc_feature_state_track(cl->features, cl, i);
        cl->qx[i] = m.end[0] - m.vel[0] * dt;
        cl->qy[i] = m.end[1] - m.vel[1] * dt;
        cl->qz[i] = m.end[2] - m.vel[2] * dt;
        cl->history_override[i] = 1;
        cl->contact[i] = WC_CONTACT_COLLIDER;
        cl->normal_x[i] = m.normal[0], cl->normal_y[i] = m.normal[1], cl->normal_z[i] = m.normal[2];
    }
    stats->failsafe_particles += failsafe;
}
