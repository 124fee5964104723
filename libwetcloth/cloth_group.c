#include "cloth_group.h"

#include <string.h>

#include "alloc.h"
#include "selfcollide.h"
#include "wetness.h"

/* The combined cloth's per-particle arrays that a step copies in and out.
 * The first OUT_DOUBLES are the answer (copied back), the rest only read;
 * likewise for the byte arrays. */
enum { DOUBLE_FIELDS = 14, OUT_DOUBLES = 9, BYTE_FIELDS = 3, OUT_BYTES = 2 };

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
    /// The combined cloth: only what collision reads (see selfcollide.c).
    /// Its adhesive pairs are the wet pairs between different members
    /// (wetness.c), in combined numbering.
    wc_cloth combined;
    /// Those pairs as wci_cloth_group_save found them, for
    /// wci_cloth_group_restore.
    int32_t *saved_pairs;
    double *saved_data;
    int64_t saved_count, saved_capacity;
    /// Per member, for the adhesion between members.
    wc_wet_piece *pieces;
};

static void double_fields(wc_cloth *c, double **out[DOUBLE_FIELDS])
{
    double **f[DOUBLE_FIELDS] = {&c->nx, &c->ny, &c->nz, &c->normal_x, &c->normal_y, &c->normal_z,
                                 &c->qx, &c->qy, &c->qz, &c->x, &c->y, &c->z, &c->inv_mass,
                                 &c->wetness};
    memcpy(out, f, sizeof f);
}

static void byte_fields(wc_cloth *c, uint8_t **out[BYTE_FIELDS])
{
    uint8_t **f[BYTE_FIELDS] = {&c->contact, &c->history_override, &c->contact_prev};
    memcpy(out, f, sizeof f);
}

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
    double **d[DOUBLE_FIELDS];
    uint8_t **b[BYTE_FIELDS];
    double_fields(c, d);
    byte_fields(c, b);
    for (int k = 0; k < DOUBLE_FIELDS; ++k) wci_free(*d[k]);
    for (int k = 0; k < BYTE_FIELDS; ++k) wci_free(*b[k]);
    wci_free(c->pin_slot);
    wci_free(c->topology.triangles);
    wci_free(c->self_touched);
    wci_free(c->adhesive_pairs);
    wci_free(c->adhesive_data);
    wci_self_state_destroy(c->self);
    void *blocks[] = {g->member, g->first, g->first_triangle, g->self, g->friction,
                      g->wet_friction, g->handled, g->saved_pairs, g->saved_data, g->pieces};
    for (size_t k = 0; k < sizeof blocks / sizeof blocks[0]; ++k) wci_free(blocks[k]);
    wci_free(g);
}

/* Members, offsets and the combined cloth's arrays; 0 on out-of-memory. */
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
    size_t n = (size_t)g->first[m];
    comb->particle_count = g->first[m];
    comb->topology.triangle_count = g->first_triangle[m];
    double **d[DOUBLE_FIELDS];
    uint8_t **b[BYTE_FIELDS];
    double_fields(comb, d);
    byte_fields(comb, b);
    int ok = 1;
    for (int k = 0; k < DOUBLE_FIELDS; ++k) ok &= (*d[k] = wci_alloc_array(n, sizeof(double))) != NULL;
    for (int k = 0; k < BYTE_FIELDS; ++k) ok &= (*b[k] = wci_alloc_array(n, 1)) != NULL;
    comb->pin_slot = wci_alloc_array(n, sizeof *comb->pin_slot);
    comb->topology.triangles =
        wci_alloc_array(3 * (size_t)g->first_triangle[m], sizeof *comb->topology.triangles);
    return ok && comb->pin_slot && comb->topology.triangles;
}

/* The combined cloth's triangles and rest shape (each self-colliding
 * member's own rest shape, so its pairs keep the thickness they had alone),
 * then its self-collision state. */
static int build_combined(wc_cloth_group *g, wc_cloth *const *cloths)
{
    wc_cloth *comb = &g->combined;
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

/* The members' state into the combined cloth (all fields) or the answer
 * back out (out = 1: the answer's fields only). */
static void copy_state(wc_cloth_group *g, wc_cloth *const *cloths, int out)
{
    wc_cloth *comb = &g->combined;
    double **cd[DOUBLE_FIELDS], **md[DOUBLE_FIELDS];
    uint8_t **cb[BYTE_FIELDS], **mb[BYTE_FIELDS];
    double_fields(comb, cd);
    byte_fields(comb, cb);
    for (int32_t k = 0; k < g->count; ++k) {
        wc_cloth *cl = cloths[g->member[k]];
        size_t off = (size_t)g->first[k], n = (size_t)cl->particle_count;
        double_fields(cl, md);
        byte_fields(cl, mb);
        for (int f = 0; f < (out ? OUT_DOUBLES : DOUBLE_FIELDS); ++f)
            memcpy(out ? *md[f] : *cd[f] + off, out ? *cd[f] + off : *md[f], n * sizeof(double));
        for (int f = 0; f < (out ? OUT_BYTES : BYTE_FIELDS); ++f)
            memcpy(out ? *mb[f] : *cb[f] + off, out ? *cb[f] + off : *mb[f], n);
        if (!out) memcpy(comb->pin_slot + off, cl->pin_slot, n * sizeof *cl->pin_slot);
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
    copy_state(g, cloths, 0);
    if (wci_self_collide(comb, dt, threads, stats)) return WC_ERROR_OUT_OF_MEMORY;
    copy_state(g, cloths, 1);
    for (int32_t k = 0; k < g->count; ++k) {
        wc_cloth *cl = cloths[g->member[k]];
        g->handled[g->member[k]] = 1;
        /* its own candidates will be out of date when it next runs alone */
        if (cl->self) wci_self_state_invalidate(cl->self);
    }
    return comb->wet_forces ? hand_out_adhesion(g, cloths, h) : WC_OK;
}

int wci_cloth_group_handled(const wc_cloth_group *g, int32_t cloth)
{
    return g && cloth < g->world_cloths && g->handled[cloth];
}
