#include "cloth_group.h"

#include <string.h>

#include "alloc.h"
#include "invariant.h"
#include "particles.h"
#include "selfcollide.h"
#include "wetness.h"

struct wc_cloth_group {
    /// Members and their world indices.
    int32_t count;
    int32_t *member;
    /// First particle and first triangle of each member in the combined
    /// cloth (count + 1 entries).
    int32_t *first, *first_triangle;
    /// Per member: self-collision on, friction, wet friction (refreshed
    /// each step: materials can change).
    uint8_t *self;
    double *friction, *wet_friction;
    /// Cloths in the world the group was made for, and which of them the
    /// last step resolved here.
    int32_t world_cloths;
    uint8_t *handled;
    /// Per combined particle: moved again by the collider stage after the
    /// combined pass (wci_cloth_group_flags, wci_cloth_group_verify).
    uint8_t *again;
    /// The combined cloth: only what collision reads (see selfcollide.c).
    /// Its per-particle arrays are views of the world's, whose members are
    /// one range (particles.h), set before each pass; it owns its
    /// triangles, its self-collision state and its adhesive pairs, the wet
    /// pairs between different members (wetness.c), in combined numbering.
    wc_cloth combined;
    /// Those pairs as wci_cloth_group_save found them, for
    /// wci_cloth_group_restore.
    int32_t *saved_pairs;
    double *saved_data;
    int64_t saved_count, saved_capacity;
    /// Per member, for the adhesion between members.
    wc_wet_piece *pieces;
};

int wci_cloth_group_possible(wc_cloth *const *cloths, int32_t cloth_count)
{
    int32_t members = 0;
    for (int32_t c = 0; c < cloth_count; ++c) members += cloths[c]->collide_cloths != 0;
    return members >= 2;
}

void wci_cloth_group_destroy(wc_cloth_group *g)
{
    if (!g) return;
    wc_cloth *c = &g->combined;
    wci_free(c->topology.triangles);
    wci_free(c->self_touched);
    wci_free(c->adhesive_pairs);
    wci_free(c->adhesive_data);
    wci_self_state_destroy(c->self);
    void *blocks[] = {g->member, g->first, g->first_triangle, g->self, g->friction,
                      g->wet_friction, g->handled, g->saved_pairs, g->saved_data, g->pieces,
                      g->again};
    for (size_t k = 0; k < sizeof blocks / sizeof blocks[0]; ++k) wci_free(blocks[k]);
    wci_free(g);
}

/* Members, offsets and the combined cloth's triangles; 0 on out-of-memory. */
static int allocate(wc_cloth_group *g, wc_cloth *const *cloths, int32_t cloth_count)
{
    int32_t m = 0;
    for (int32_t c = 0; c < cloth_count; ++c) m += cloths[c]->collide_cloths != 0;
    g->count = m;
    g->world_cloths = cloth_count;
    g->member = wci_alloc_array((size_t)m, sizeof *g->member);
    g->first = wci_alloc_array((size_t)m + 1, sizeof *g->first);
    g->first_triangle = wci_alloc_array((size_t)m + 1, sizeof *g->first_triangle);
    g->self = wci_alloc_array((size_t)m, 1);
    g->friction = wci_alloc_array((size_t)m, sizeof *g->friction);
    g->wet_friction = wci_alloc_array((size_t)m, sizeof *g->wet_friction);
    g->handled = wci_alloc_array((size_t)cloth_count, 1);
    g->pieces = wci_alloc_array((size_t)m, sizeof *g->pieces);
    if (!g->member || !g->first || !g->first_triangle || !g->self || !g->friction ||
        !g->wet_friction || !g->handled || !g->pieces)
        return 0;
    for (int32_t c = 0, k = 0; c < cloth_count; ++c) {
        const wc_cloth *cl = cloths[c];
        if (!cl->collide_cloths) continue;
        g->member[k] = c;
        g->self[k] = cl->self != NULL;
        g->first[k + 1] = g->first[k] + cl->particle_count;
        g->first_triangle[k + 1] = g->first_triangle[k] + cl->topology.triangle_count;
        ++k;
    }
    wc_cloth *comb = &g->combined;
    comb->particle_count = g->first[m];
    comb->topology.triangle_count = g->first_triangle[m];
    if (!(g->again = wci_alloc_array((size_t)g->first[m] + 1, 1))) return 0;
    comb->topology.triangles =
        wci_alloc_array(3 * (size_t)g->first_triangle[m], sizeof *comb->topology.triangles);
    return comb->topology.triangles != NULL;
}

/* The combined cloth's triangles and rest shape (each self-colliding
 * member's own rest shape, so its pairs keep the thickness they had alone),
 * then its self-collision state, which keeps its own copy of the rest
 * shape: the positions given to it here are scratch. */
static int build_combined(wc_cloth_group *g, wc_cloth *const *cloths)
{
    wc_cloth *comb = &g->combined;
    size_t total = (size_t)comb->particle_count;
    double *rest_xyz = wci_alloc_array(3 * total, sizeof *rest_xyz);
    if (!rest_xyz) return 0;
    comb->x = rest_xyz, comb->y = rest_xyz + total, comb->z = rest_xyz + 2 * total;
    for (int32_t k = 0; k < g->count; ++k) {
        const wc_cloth *cl = cloths[g->member[k]];
        int32_t off = g->first[k], n = cl->particle_count;
        const int32_t *tri = cl->topology.triangles;
        int32_t *out = comb->topology.triangles + 3 * (size_t)g->first_triangle[k];
        for (size_t t = 0; t < 3 * (size_t)cl->topology.triangle_count; ++t) out[t] = tri[t] + off;
        const double *rest = cl->self ? wci_self_state_rest(cl->self) : NULL;
        for (int32_t i = 0; i < n; ++i) {
            comb->x[off + i] = rest ? rest[3 * (size_t)i] : cl->x[i];
            comb->y[off + i] = rest ? rest[3 * (size_t)i + 1] : cl->y[i];
            comb->z[off + i] = rest ? rest[3 * (size_t)i + 2] : cl->z[i];
        }
        g->friction[k] = cl->material.friction;
        g->wet_friction[k] = cl->material.wet_friction;
    }
    wc_self_pieces pieces = {g->count, g->first, g->self, g->friction, g->wet_friction};
    comb->self = wci_self_state_create_pieces(comb, &pieces);
    wci_free(rest_xyz);
    comb->x = comb->y = comb->z = NULL;
    return comb->self != NULL;
}

int wci_cloth_group_update(wc_cloth_group **group, wc_cloth *const *cloths, int32_t cloth_count)
{
    if (*group && (*group)->world_cloths == cloth_count) return 0;
    if (!wci_cloth_group_possible(cloths, cloth_count)) {
        wci_cloth_group_destroy(*group);
        *group = NULL;
        return 0;
    }
    wc_cloth_group *g = wci_alloc_array(1, sizeof *g);
    if (!g) return 1;
    if (!allocate(g, cloths, cloth_count) || !build_combined(g, cloths)) {
        wci_cloth_group_destroy(g);
        return 1;
    }
    wci_cloth_group_destroy(*group);
    *group = g;
    return 0;
}

/* Box of a cloth's motion x -> nx. */
static void motion_box(const wc_cloth *c, double box[6])
{
    box[0] = box[3] = c->x[0], box[1] = box[4] = c->y[0], box[2] = box[5] = c->z[0];
    for (int32_t i = 0; i < c->particle_count; ++i) {
        const double p[6] = {c->x[i], c->y[i], c->z[i], c->nx[i], c->ny[i], c->nz[i]};
        for (int k = 0; k < 6; ++k) {
            int axis = k % 3;
            if (p[k] < box[axis]) box[axis] = p[k];
            if (p[k] > box[axis + 3]) box[axis + 3] = p[k];
        }
    }
}

/* Whether the motions of two members come within h of each other. */
static int members_meet(const wc_cloth_group *g, wc_cloth *const *cloths, double h)
{
    enum { STACK = 16 };
    double stack[6 * STACK], *boxes = stack;
    if (g->count > STACK) boxes = wci_alloc_array(6 * (size_t)g->count, sizeof *boxes);
    if (!boxes) return 1; /* cannot tell: run the combined pass, which is always right */
    for (int32_t k = 0; k < g->count; ++k) motion_box(cloths[g->member[k]], boxes + 6 * k);
    int meet = 0;
    for (int32_t a = 0; a < g->count && !meet; ++a)
        for (int32_t b = a + 1; b < g->count && !meet; ++b) {
            const double *p = boxes + 6 * a, *q = boxes + 6 * b;
            meet = p[0] - h <= q[3] && q[0] <= p[3] + h && p[1] - h <= q[4] && q[1] <= p[4] + h &&
                   p[2] - h <= q[5] && q[2] <= p[5] + h;
        }
    if (boxes != stack) wci_free(boxes);
    return meet;
}

/* The combined cloth's per-particle arrays: the members' range of the
 * world's (particles.h), which starts at the first member; with `on` 0, no
 * arrays, so that nothing keeps pointers the next commit or added cloth
 * moves. */
static void view_members(wc_cloth_group *g, wc_cloth *const *cloths, int on)
{
    static const wc_cloth none;
    wc_cloth *comb = &g->combined;
    wci_particles_view(comb, on ? cloths[g->member[0]] : &none);
    for (int32_t k = 0; k < g->count && on; ++k) {
        const wc_cloth *cl = cloths[g->member[k]];
        (void)cl;
        WC_ASSERT(cl->x == comb->x + g->first[k] && cl->pin_slot == comb->pin_slot + g->first[k]);
    }
}

/* Member of a combined particle index (first[] ascending). */
static int32_t member_of(const wc_cloth_group *g, int32_t i)
{
    int32_t lo = 0, hi = g->count - 1;
    while (lo < hi) {
        int32_t mid = (lo + hi + 1) / 2;
        if (g->first[mid] <= i) lo = mid;
        else hi = mid - 1;
    }
    return lo;
}

/* Self-adhesion: the vertex-face pairs the combined pass answered within
 * one wet self-colliding member go to that member, which keeps its
 * adhesive pairs as it would alone. Those between two members stay with
 * the combined cloth, which keeps them the same way (wci_wet_self_pairs: the
 * answered ones and last step's still within the hold band), so that wet
 * cloths stick to each other (wci_cloth_group_adhesion). */
static wc_status hand_out_adhesion(wc_cloth_group *g, wc_cloth *const *cloths, double h)
{
    wc_cloth *comb = &g->combined;
    int failed = comb->self_touched_failed;
    int64_t across = 0;
    for (int64_t p = 0; p < comb->self_touched_count && !failed; ++p) {
        int32_t v = comb->self_touched[2 * p], t = comb->self_touched[2 * p + 1];
        int32_t k = member_of(g, v);
        wc_cloth *cl = cloths[g->member[k]];
        if (member_of(g, comb->topology.triangles[3 * (size_t)t]) != k) {
            comb->self_touched[2 * across] = v, comb->self_touched[2 * across + 1] = t;
            ++across;
        } else if (cl->self && cl->wet_forces) {
            wci_wet_note_self_contact(cl, v - g->first[k], t - g->first_triangle[k]);
        }
    }
    comb->self_touched_count = failed ? 0 : across, comb->self_touched_failed = 0;
    if (failed) return WC_ERROR_OUT_OF_MEMORY;
    for (int32_t k = 0; k < g->count; ++k) {
        wc_cloth *cl = cloths[g->member[k]];
        if (cl->self && cl->wet_forces && wci_wet_self_pairs(cl, h)) return WC_ERROR_OUT_OF_MEMORY;
    }
    return wci_wet_self_pairs(comb, h);
}

int wci_cloth_group_save(wc_cloth_group *g)
{
    if (!g) return 0;
    const wc_cloth *comb = &g->combined;
    int64_t n = comb->adhesive_count;
    if (n > g->saved_capacity) {
        int32_t *pairs = wci_alloc_array((size_t)n, 2 * sizeof *pairs);
        double *data = wci_alloc_array((size_t)n, 6 * sizeof *data);
        if (!pairs || !data) {
            wci_free(pairs), wci_free(data);
            return 1;
        }
        wci_free(g->saved_pairs), wci_free(g->saved_data);
        g->saved_pairs = pairs, g->saved_data = data, g->saved_capacity = n;
    }
    if (n) {
        memcpy(g->saved_pairs, comb->adhesive_pairs, (size_t)n * 2 * sizeof *g->saved_pairs);
        memcpy(g->saved_data, comb->adhesive_data, (size_t)n * 6 * sizeof *g->saved_data);
    }
    g->saved_count = n;
    return 0;
}

void wci_cloth_group_restore(wc_cloth_group *g)
{
    if (!g) return;
    wc_cloth *comb = &g->combined;
    /* the pair buffers only grow, so the saved pairs still fit */
    if (g->saved_count) {
        memcpy(comb->adhesive_pairs, g->saved_pairs, (size_t)g->saved_count * 2 * sizeof *g->saved_pairs);
        memcpy(comb->adhesive_data, g->saved_data, (size_t)g->saved_count * 6 * sizeof *g->saved_data);
    }
    comb->adhesive_count = g->saved_count;
    comb->self_touched_count = 0, comb->self_touched_failed = 0;
}

void wci_cloth_group_adhesion(wc_cloth_group *g, wc_cloth *const *cloths)
{
    if (!g || g->combined.adhesive_count == 0) return;
    for (int32_t k = 0; k < g->count; ++k) {
        wc_cloth *cl = cloths[g->member[k]];
        wc_wet_piece piece = {cl->wetness, cl->topology.area, cl->material.adhesion,
                              cl->fx, cl->fy, cl->fz, g->first[k]};
        g->pieces[k] = piece;
    }
    const wc_cloth *comb = &g->combined;
    wci_wet_pair_adhesion(comb->adhesive_pairs, comb->adhesive_data, comb->adhesive_count,
                         comb->topology.triangles, g->pieces, g->count);
}

wc_status wci_cloth_group_collide(wc_cloth_group *g, wc_cloth *const *cloths, double dt,
                                 int threads, wc_step_stats *stats)
{
    wc_cloth *comb = &g->combined;
    memset(g->handled, 0, (size_t)g->world_cloths);
    comb->dt_step = dt;
    comb->material.thickness = 0.0;
    comb->wet_forces = 0;
    for (int32_t k = 0; k < g->count; ++k) {
        const wc_cloth *cl = cloths[g->member[k]];
        if (cl->material.thickness > comb->material.thickness)
            comb->material.thickness = cl->material.thickness;
        comb->wet_forces |= cl->wet_forces;
        g->friction[k] = cl->material.friction;
        g->wet_friction[k] = cl->material.wet_friction;
    }
    double h = wci_self_thickness(comb);
    /* pairs between dry members do not pull; adhering ones hold within the
     * band, so while there are any the pass runs within the band too */
    if (!comb->wet_forces) comb->adhesive_count = 0;
    if (!members_meet(g, cloths, comb->adhesive_count ? (1.0 + WC_WET_HOLD_BAND) * h : h)) {
        /* the candidates were made for motions of an earlier step */
        wci_self_state_invalidate(comb->self);
        comb->adhesive_count = 0;
        return WC_OK;
    }
    wci_self_state_set_friction(comb->self, g->friction, g->wet_friction);
    view_members(g, cloths, 1);
    wc_status s = wci_self_collide(comb, dt, threads, stats) ? WC_ERROR_OUT_OF_MEMORY : WC_OK;
    if (!s) {
        for (int32_t k = 0; k < g->count; ++k) {
            wc_cloth *cl = cloths[g->member[k]];
            g->handled[g->member[k]] = 1;
            /* its own candidates will be out of date when it next runs alone */
            if (cl->self) wci_self_state_invalidate(cl->self);
        }
        if (comb->wet_forces) s = hand_out_adhesion(g, cloths, h);
    }
    view_members(g, cloths, 0);
    return s;
}

int wci_cloth_group_handled(const wc_cloth_group *g, int32_t cloth)
{
    return g && cloth < g->world_cloths && g->handled[cloth];
}

uint8_t *wci_cloth_group_flags(wc_cloth_group *g, int32_t cloth)
{
    if (!wci_cloth_group_handled(g, cloth)) return NULL;
    for (int32_t k = 0; k < g->count; ++k)
        if (g->member[k] == cloth) return g->again + g->first[k];
    return NULL;
}

wc_status wci_cloth_group_verify(wc_cloth_group *g, wc_cloth *const *cloths, int threads,
                                 wc_step_stats *stats)
{
    int any = 0;
    for (int32_t i = 0; i < g->combined.particle_count && !any; ++i) any = g->again[i];
    if (!any) return WC_OK;
    view_members(g, cloths, 1);
    wc_status s = wci_self_verify(&g->combined, g->again, threads, stats);
    view_members(g, cloths, 0);
    memset(g->again, 0, (size_t)g->combined.particle_count);
    return s;
}

const uint8_t *wci_cloth_group_moved(const wc_cloth_group *g, int32_t cloth, int32_t *any)
{
    *any = 0;
    if (!wci_cloth_group_handled(g, cloth)) return NULL;
    int32_t total;
    const uint8_t *moved = wci_self_state_moved(g->combined.self, &total);
    for (int32_t k = 0; k < g->count; ++k)
        if (g->member[k] == cloth) {
            *any = total > 0;
            return moved + g->first[k];
        }
    return NULL;
}
