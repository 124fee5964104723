#include "wetness.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "alloc.h"

#include "convex.h"
#include "grid.h"
#include "parallel.h"
#include "primitives.h"

/* Thesis eq. 2.8 and 2.9, made independent of units:
 *  - a particle in contact with a surface of normal N (from the surface
 *    toward it) is pulled toward it with S = -s w N, s = adhesion * area,
 *    every step while in contact, so it touches again next step and stays
 *    until something pulls harder;
 *  - a particle not in contact, linked by stretch links to stuck
 *    particles, is pulled toward each one's surface with
 *    O = -s w beta (l / d) N_j, the pull weaker the more the link is
 *    stretched; the sum is capped at s w. The stuck area thus grows from its
 *    rim, one ring per contact, until bending resists more than adhesion
 *    pulls (thesis Fig. 3.5).
 * Each particle sums its own pulls, so the loop is parallel and the result
 * the same for any thread count. */
void wci_wet_forces(wc_cloth *c, int threads)
{
    int32_t n = c->particle_count, stretch_count = c->topology.stretch.count;
    const wc_material *m = &c->material;
    const wc_link_set *links = &c->topology.stretch;
    (void)threads;
#pragma omp parallel for schedule(static) num_threads(threads) if (n >= WC_PARALLEL_MIN)
    for (int32_t i = 0; i < n; ++i) {
        double w = c->wetness[i];
        if (w <= 0.0 || c->pin_slot[i] >= 0) continue;
        double s = m->adhesion * c->topology.area[i] * w;
        double f[3] = {0.0, 0.0, 0.0};
        if (c->contact[i] == WC_CONTACT_COLLIDER) {
            f[0] = -s * c->normal_x[i], f[1] = -s * c->normal_y[i], f[2] = -s * c->normal_z[i];
        } else if (c->contact[i] == WC_CONTACT_NONE && m->spread > 0.0) {
            for (int32_t k = c->link_start[i]; k < c->link_start[i + 1]; ++k) {
                int32_t e = c->link_list[k] >= 0 ? c->link_list[k] : ~c->link_list[k];
                if (e >= stretch_count) continue; /* bend links do not spread */
                int32_t j = links->a[e] == i ? links->b[e] : links->a[e];
                /* spreading follows collider contacts only: a pull toward
                 * another layer of the cloth would have no equal and
                 * opposite partner */
                if (!c->stuck[j] || c->contact[j] != WC_CONTACT_COLLIDER) continue;
                double dx = c->x[i] - c->x[j], dy = c->y[i] - c->y[j], dz = c->z[i] - c->z[j];
                double d = sqrt(dx * dx + dy * dy + dz * dz);
                double pull = s * m->spread * (d > links->rest[e] ? links->rest[e] / d : 1.0);
                f[0] -= pull * c->normal_x[j];
                f[1] -= pull * c->normal_y[j];
                f[2] -= pull * c->normal_z[j];
            }
            double len = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
            if (len > s) {
                double scale = s / len;
                f[0] *= scale, f[1] *= scale, f[2] *= scale;
            }
        }
        c->fx[i] += f[0];
        c->fy[i] += f[1];
        c->fz[i] += f[2];
    }
    if (c->adhesive_count) wci_wet_self_adhesion(c, c->fx, c->fy, c->fz);
}

/* ------------------------------------------------------------------------ */
/* Self-adhesion                                                            */
/* ------------------------------------------------------------------------ */

/* Wet cloth touching wet cloth: the water between two layers pulls
 * them together with equal and opposite forces. The self-collision's
 * vertex-face pairs carry it: a vertex v at distance ~h from a point
 * sum b_k X_k of a triangle of another layer, n the unit normal from that
 * point to v. The pull F acts as -F n on v and +F b_k n on the corners: the
 * forces sum to F n (sum b_k - 1) = 0 to rounding, so momentum is kept.
 * F = adhesion * A_v * w / 2 / n_v, w = the larger of the vertex's and the
 * face point's wetness (water in the gap comes from either side, as a wet
 * cloth sticks to a dry collider), n_v the vertex's number of adhesive pairs
 * (a vertex over an edge of the other layer touches both its triangles).
 * The 1/2: between two layers both sides' vertices make pairs against the
 * other's faces, so each patch of contact is counted twice; with it, two
 * wet layers press together with about the adhesion pressure a wet cloth
 * has on a collider. Pairs are kept, like collider contacts, while they
 * stay within (1 + WC_WET_HOLD_BAND) h. Rest neighbours in the cloth (pairs
 * closer than 2 h in the rest shape) never adhere: they are the cloth
 * itself, not a second layer. Between different cloths of a group the same
 * law acts on the pairs the group's collision answered (cloth_group.c),
 * with each side's own adhesion and wetness (wci_wet_pair_adhesion). */

void wci_wet_note_self_contact(wc_cloth *c, int32_t v, int32_t t)
{
    if (c->self_touched_count == c->self_touched_capacity) {
        int64_t capacity = c->self_touched_capacity ? 2 * c->self_touched_capacity : 256;
        int32_t *grown = wci_alloc_array((size_t)capacity, 2 * sizeof *grown);
        if (!grown) {
            c->self_touched_failed = 1;
            return;
        }
        if (c->self_touched_count)
            memcpy(grown, c->self_touched, (size_t)c->self_touched_count * 2 * sizeof *grown);
        wci_free(c->self_touched);
        c->self_touched = grown;
        c->self_touched_capacity = capacity;
    }
    c->self_touched[2 * c->self_touched_count] = v;
    c->self_touched[2 * c->self_touched_count + 1] = t;
    c->self_touched_count++;
}

static int compare_pair(const void *pa, const void *pb)
{
    const int32_t *p = pa, *q = pb;
    if (p[0] != q[0]) return p[0] < q[0] ? -1 : 1;
    if (p[1] != q[1]) return p[1] < q[1] ? -1 : 1;
    return 0;
}

wc_status wci_wet_self_pairs(wc_cloth *c, double h)
{
    int64_t old = c->adhesive_count, total = c->self_touched_count + old;
    if (c->self_touched_failed) {
        c->self_touched_failed = 0, c->self_touched_count = 0;
        return WC_ERROR_OUT_OF_MEMORY;
    }
    if (total == 0) return WC_OK;
    /* the answered pairs and last step's adhesive ones, sorted, unique */
    int32_t *keys = wci_alloc_array((size_t)total, 2 * sizeof *keys);
    int32_t *pairs = total > c->adhesive_capacity ? wci_alloc_array((size_t)total, 2 * sizeof *pairs) : NULL;
    double *data = total > c->adhesive_capacity ? wci_alloc_array((size_t)total, 6 * sizeof *data) : NULL;
    if (!keys || (total > c->adhesive_capacity && (!pairs || !data))) {
        wci_free(keys), wci_free(pairs), wci_free(data);
        c->self_touched_count = 0;
        return WC_ERROR_OUT_OF_MEMORY;
    }
    if (c->self_touched_count)
        memcpy(keys, c->self_touched, (size_t)c->self_touched_count * 2 * sizeof *keys);
    if (old) memcpy(keys + 2 * c->self_touched_count, c->adhesive_pairs, (size_t)old * 2 * sizeof *keys);
    c->self_touched_count = 0;
    if (pairs) {
        wci_free(c->adhesive_pairs), wci_free(c->adhesive_data);
        c->adhesive_pairs = pairs, c->adhesive_data = data, c->adhesive_capacity = total;
    }
    qsort(keys, (size_t)total, 2 * sizeof *keys, compare_pair);
    double reach = (1.0 + WC_WET_HOLD_BAND) * h;
    int64_t kept = 0;
    for (int64_t k = 0; k < total; ++k) {
        const int32_t *key = keys + 2 * k;
        if (k > 0 && key[0] == key[-2] && key[1] == key[-1]) continue;
        int32_t v = key[0];
        const int32_t *tri = c->topology.triangles + 3 * (size_t)key[1];
        double p[3] = {c->nx[v], c->ny[v], c->nz[v]}, corner[3][3], w[3], n[3];
        for (int j = 0; j < 3; ++j)
            corner[j][0] = c->nx[tri[j]], corner[j][1] = c->ny[tri[j]], corner[j][2] = c->nz[tri[j]];
        double d2 = wci_point_triangle_closest(p, corner[0], corner[1], corner[2], w);
        if (!(d2 < reach * reach) || !(d2 > 0.0)) continue; /* parted, or no direction */
        double d = sqrt(d2);
        for (int j = 0; j < 3; ++j) n[j] = (p[j] - (w[0] * corner[0][j] + w[1] * corner[1][j] + w[2] * corner[2][j])) / d;
        c->adhesive_pairs[2 * kept] = v, c->adhesive_pairs[2 * kept + 1] = key[1];
        double *out = c->adhesive_data + 6 * kept;
        for (int j = 0; j < 3; ++j) out[j] = w[j], out[3 + j] = n[j];
        ++kept;
    }
    c->adhesive_count = kept;
    wci_free(keys);
    return WC_OK;
}

void wci_wet_self_adhesion(const wc_cloth *c, double *fx, double *fy, double *fz)
{
    wc_wet_piece whole = {c->wetness, c->topology.area, c->material.adhesion, fx, fy, fz, 0};
    wci_wet_pair_adhesion(c->adhesive_pairs, c->adhesive_data, c->adhesive_count,
                         c->topology.triangles, &whole, 1);
}

/* Piece of particle i (pieces ascending by first). */
static const wc_wet_piece *piece_of(const wc_wet_piece *pieces, int32_t count, int32_t i)
{
    int32_t lo = 0, hi = count - 1;
    while (lo < hi) {
        int32_t mid = (lo + hi + 1) / 2;
        if (pieces[mid].first <= i) lo = mid;
        else hi = mid - 1;
    }
    return pieces + lo;
}

/* Between two cloths the pull is the larger of the two sides' adhesion
 * pressures a w: the water film in the gap is the wetter side's, and it
 * pulls as that cloth's film would (a soaked cloth on a dry one sticks as
 * it does to a dry collider, where only its own a w counts). Within one
 * cloth a is the same on both sides and this is a max(w_v, w_f), the rule
 * above; no combination (mean, product) keeps both that and the collider
 * case. */
void wci_wet_pair_adhesion(const int32_t *pairs, const double *data, int64_t count,
                          const int32_t *triangles, const wc_wet_piece *pieces,
                          int32_t piece_count)
{
    for (int64_t k = 0; k < count;) {
        /* the pairs of one vertex are consecutive (sorted by vertex) */
        int32_t v = pairs[2 * k];
        int64_t end = k;
        while (end < count && pairs[2 * end] == v) ++end;
        const wc_wet_piece *pv = piece_of(pieces, piece_count, v);
        int32_t lv = v - pv->first;
        double share = 0.5 * pv->area[lv] / (double)(end - k);
        double vertex_pull = pv->adhesion * pv->wetness[lv];
        for (; k < end; ++k) {
            const int32_t *tri = triangles + 3 * (size_t)pairs[2 * k + 1];
            const wc_wet_piece *pf = piece_of(pieces, piece_count, tri[0]);
            const double *b = data + 6 * k, *n = b + 3;
            double face_w = 0.0;
            for (int j = 0; j < 3; ++j) face_w += b[j] * pf->wetness[tri[j] - pf->first];
            double face_pull = pf->adhesion * face_w;
            double f = share * (vertex_pull > face_pull ? vertex_pull : face_pull);
            if (!(f > 0.0)) continue;
            /* (pinned particles ignore their force at integration) */
            pv->fx[lv] -= f * n[0], pv->fy[lv] -= f * n[1], pv->fz[lv] -= f * n[2];
            for (int j = 0; j < 3; ++j) {
                int32_t i = tri[j] - pf->first;
                pf->fx[i] += f * b[j] * n[0], pf->fy[i] += f * b[j] * n[1], pf->fz[i] += f * b[j] * n[2];
            }
        }
    }
}

/* ------------------------------------------------------------------------ */
/* Holding contact                                                          */
/* ------------------------------------------------------------------------ */

/* Why a band. A particle resting on a faceted collider is placed at exactly
 * the contact distance r from the face under it, and then the feature pass
 * (collider_contacts.c) lifts the cloth triangles that lie over the
 * collider's proud vertices and edges (6-11 mm proud on the thesis sphere)
 * to r from those, which lifts their corners 0.05-0.15 mm off the faces.
 * The next step's adhesion pulls such a particle back by less than that,
 * so it ends the step a little beyond r: no contact, hence no adhesion in
 * the step after, hence it falls back and touches again. Measured on the
 * thesis wrap (20 x 20, w = 1), 0.5-1 s: about 100 particles lost contact
 * every step and as many regained it, and particles resting within 0.5 mm
 * of the contact distance were in contact in only 81 % of the steps, so
 * adhesion and the stuck state flickered.
 * A contact is therefore made at r and broken only beyond (1 + band) r:
 * the water film between cloth and surface does not snap the moment the two
 * part by a tenth of a millimetre. The band only keeps contacts that exist
 * (it never makes one at a distance) and moves nothing. 10 % of r is 0.5 mm
 * at the default thickness: several times the lift, and still small against
 * the cloth's thickness. */

/* The nearest surface point of a mesh collider (at the end of the step)
 * within `reach` of p: returns 1 and its distance and the unit direction
 * from it to p. */
static int mesh_nearest(const wc_collider *col, const double p[3], double reach, double *dist,
                        double n[3])
{
    double box[6];
    for (int k = 0; k < 3; ++k) box[k] = p[k] - reach, box[k + 3] = p[k] + reach;
    if (!wc_boxes_overlap(box, col->bounds)) return 0;
    enum { CAPACITY = 256 };
    int32_t stack[CAPACITY], *found = stack;
    int32_t count = wci_bvh_query(&col->bvh, box, stack, CAPACITY);
    if (count > CAPACITY) {
        found = wci_alloc_array((size_t)count, sizeof *found);
        if (!found) return 0; /* no room to look: the contact is not held */
        wci_bvh_query(&col->bvh, box, found, count);
    }
    double best = reach * reach, offset[3] = {0.0, 0.0, 0.0};
    int hit = 0;
    for (int32_t k = 0; k < count; ++k) {
        const int32_t *v = col->triangles + 3 * (size_t)found[k];
        const double *a = col->next + 3 * (size_t)v[0], *b = col->next + 3 * (size_t)v[1],
                     *c = col->next + 3 * (size_t)v[2];
        double nrm[3];
        wci_triangle_normal(a, b, c, nrm);
        if (nrm[0] == 0.0 && nrm[1] == 0.0 && nrm[2] == 0.0) continue; /* degenerate: ignored */
        double w[3];
        double d2 = wci_point_triangle_closest(p, a, b, c, w);
        if (!(d2 < best)) continue;
        best = d2, hit = 1;
        for (int j = 0; j < 3; ++j) offset[j] = p[j] - (w[0] * a[j] + w[1] * b[j] + w[2] * c[j]);
    }
    if (found != stack) wci_free(found);
    double len = sqrt(best);
    if (!hit || !(len > 0.0)) return 0;
    for (int j = 0; j < 3; ++j) n[j] = offset[j] / len;
    *dist = len;
    return 1;
}

/* The same for a convex collider, through its exact ball distance. */
static int convex_nearest(const wc_collider *col, const double p[3], double reach, double *dist,
                          double n[3])
{
    double local[3], depth, dir[3], out[3];
    for (int k = 0; k < 3; ++k)
        if (p[k] < col->bounds[k] - reach || p[k] > col->bounds[k + 3] + reach) return 0;
    wci_pose_to_local(&col->pose_next, p, local);
    if (!wci_convex_penetration(&col->convex, local, reach, &depth, dir)) return 0;
    for (int k = 0; k < 3; ++k) out[k] = -dir[k];
    wci_pose_rotate(&col->pose_next, out, n);
    *dist = reach - depth;
    return 1;
}

void wci_wet_hold_contacts(wc_cloth *c, wc_collider *const *colliders, int32_t count, int threads)
{
    int32_t n = c->particle_count;
    double h = c->material.thickness;
    (void)threads;
#pragma omp parallel for schedule(dynamic, 256) num_threads(threads) if (n >= WC_PARALLEL_MIN)
    for (int32_t i = 0; i < n; ++i) {
        if (c->contact_prev[i] != WC_CONTACT_COLLIDER || c->contact[i] != WC_CONTACT_NONE ||
            !(c->wetness[i] > 0.0) || c->pin_slot[i] >= 0)
            continue;
        double p[3] = {c->nx[i], c->ny[i], c->nz[i]}, best = INFINITY, normal[3] = {0, 0, 0};
        for (int32_t k = 0; k < count; ++k) {
            const wc_collider *col = colliders[k];
            double r = fmax(h + col->thickness, 1e-6), reach = (1.0 + WC_WET_HOLD_BAND) * r;
            double d, dir[3];
            int near = col->is_mesh ? mesh_nearest(col, p, reach, &d, dir)
                                    : convex_nearest(col, p, reach, &d, dir);
            /* nearest relative to each collider's own contact distance */
            if (near && d / r < best) {
                best = d / r;
                for (int j = 0; j < 3; ++j) normal[j] = dir[j];
            }
        }
        if (best == INFINITY) continue;
        c->contact[i] = WC_CONTACT_COLLIDER;
        c->normal_x[i] = normal[0], c->normal_y[i] = normal[1], c->normal_z[i] = normal[2];
    }
}

int32_t wci_wet_mark_stuck(wc_cloth *c)
{
    int32_t stuck = 0;
    int adhesive = c->material.adhesion > 0.0;
    for (int32_t i = 0; i < c->particle_count; ++i) {
        c->stuck[i] = adhesive && c->wetness[i] > 0.0 && c->contact[i] != WC_CONTACT_NONE &&
                      c->contact_prev[i] != WC_CONTACT_NONE;
        stuck += c->stuck[i];
    }
    return stuck;
}

/* Wicking: dw_i/dt = D sum_j (w_j - w_i) / l_ij^2 over stretch links, the
 * graph form of the diffusion equation, explicit, in as many equal
 * sub-steps as its stability (D dt / l^2 below 1 / (2 * links)) needs.
 * Each particle gathers from its links into a second buffer (Jacobi), so
 * the order of particles does not matter. Drying: w *= exp(-rate dt),
 * exact for dw/dt = -rate w. */
#define WICKING_MAX_SUBSTEPS 64

void wci_wet_update(wc_cloth *c, double dt)
{
    const wc_material *m = &c->material;
    const wc_link_set *links = &c->topology.stretch;
    int32_t n = c->particle_count;
    if (m->wicking > 0.0 && c->wetness_next) {
        double worst = 0.0;
        for (int32_t i = 0; i < n; ++i) {
            double rate = 0.0;
            for (int32_t k = c->link_start[i]; k < c->link_start[i + 1]; ++k) {
                int32_t e = c->link_list[k] >= 0 ? c->link_list[k] : ~c->link_list[k];
                if (e < links->count && links->rest[e] > 0.0)
                    rate += m->wicking / (links->rest[e] * links->rest[e]);
            }
            if (rate > worst) worst = rate;
        }
        /* At most WICKING_MAX_SUBSTEPS: beyond them (links far shorter than
         * the cloth's scale, e.g. near-duplicate vertices) diffusion is
         * slowed to what that many substeps keep stable, instead of a step
         * that never ends. */
        double needed = ceil(dt * worst / 0.5), slow = 1.0;
        int substeps = 1;
        if (!isfinite(needed)) {
            substeps = 0; /* links so short that 1 / l^2 overflows: no wicking */
        } else if (needed > WICKING_MAX_SUBSTEPS) {
            substeps = WICKING_MAX_SUBSTEPS;
            slow = WICKING_MAX_SUBSTEPS / needed;
        } else if (needed > 1.0) {
            substeps = (int)needed;
        }
        double h = substeps ? dt / substeps * slow : 0.0;
        for (int sub = 0; sub < substeps; ++sub) {
            for (int32_t i = 0; i < n; ++i) {
                double change = 0.0;
                for (int32_t k = c->link_start[i]; k < c->link_start[i + 1]; ++k) {
                    int32_t e = c->link_list[k] >= 0 ? c->link_list[k] : ~c->link_list[k];
                    if (e >= links->count || !(links->rest[e] > 0.0)) continue;
                    int32_t j = links->a[e] == i ? links->b[e] : links->a[e];
                    change += (c->wetness[j] - c->wetness[i]) / (links->rest[e] * links->rest[e]);
                }
                double next = c->wetness[i] + h * m->wicking * change;
                c->wetness_next[i] = next < 0.0 ? 0.0 : (next > 1.0 ? 1.0 : next);
            }
            memcpy(c->wetness, c->wetness_next, (size_t)n * sizeof *c->wetness);
        }
    }
    if (m->drying > 0.0) {
        double keep = exp(-m->drying * dt);
        for (int32_t i = 0; i < n; ++i) c->wetness[i] *= keep;
    }
    wci_cloth_apply_material(c);
}
