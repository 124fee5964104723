/* Self-collision of one cloth over one step (docs/model.md, Collisions), after Bridson, Fedkiw
 * & Anderson 2002, "Robust treatment of collisions, contact and friction for
 * cloth animation", with the normal-cone culling of Volino & Magnenat-
 * Thalmann 1994 ("Efficient self-collision detection on smoothly
 * discretized surface animations") in the broadphase.
 *
 * What is tested: vertex-face pairs (vertex not a corner of the face) for
 * proximity at the end of the step and for collision during it (the
 * coplanarity cubic); edge-edge pairs (no shared vertex) for collision
 * during the step. Edges get no proximity repulsion: the model asks particles
 * to keep the thickness, which vertex-face proximity does, and edge pairs within
 * h of each other are several times more numerous than vertex-face ones in
 * stacked layers; crossing edges are still stopped by the continuous test.
 *
 *  1. Broadphase. The triangles are grouped once, in the rest shape, into
 *     small connected patches (about 4 x 4 quads; pieces a bin's walls cut
 *     off are merged into a neighbour). Every particle gets a box around its
 *     motion x -> nx, grown by a margin g; patches get the union of their
 *     particles' boxes and a cone that holds every triangle normal of the
 *     patch over the whole step. A region of cloth (a patch, two side by
 *     side, or two joined by a third) whose normals all stay within 90
 *     degrees of one direction cannot pass through itself if it is an
 *     oriented disk whose boundary, projected onto the plane across that
 *     direction, stays a simple loop over the step: then the projection is
 *     one-to-one, a height field (the contour condition of Volino &
 *     Magnenat-Thalmann; contour.h has the argument). Without the contour
 *     check a crushed free edge folding over itself in the plane, every
 *     triangle still facing the same way, was culled and crossed itself.
 *     Within 60 degrees a height field cannot even bring two points closer
 *     than half their distance along the surface (see REST_EXCLUSION). So a
 *     region with a narrow cone and a simple contour needs no element tests
 *     at all. Only the other pairs of patches whose boxes come within the
 *     thickness h (a uniform grid finds them) are opened up into element
 *     pairs with overlapping boxes. A falling or draped cloth costs a pass
 *     over its particles and triangles and one over the regions'
 *     boundaries; folds cost what they touch.
 *     The candidates stay valid while every particle's motion stays inside
 *     its box and the culled regions keep their narrow cones and simple
 *     contours: a response that breaks either triggers a rebuild, and the
 *     next step reuses them when neither broke (cloth at rest or moving
 *     slowly skips the broadphase).
 *  2. Passes. Each pass evaluates (in parallel, one status byte per pair)
 *     the pairs with a particle that moved since their last evaluation: the
 *     continuous test and, when that finds nothing, the distance at the end
 *     of the step. Then, serially and in candidate order (so the result does
 *     not depend on the thread count), each flagged pair is evaluated again
 *     against the current state and answered: an inelastic impulse that
 *     removes the approach along the contact normal, a position correction
 *     (not velocity) to the pair's thickness, and Coulomb friction; impulses
 *     are split by inverse mass with the barycentric weights (Bridson et al.
 *     eq. 4).
 *  3. Fail-safe. Pairs whose motion still collides after the passes put
 *     their particles back where the step started, at rest: the start state
 *     was free of intersection. Reverted particles can now be hit by moving
 *     neighbours, so detection repeats until nothing collides (in the worst
 *     case the whole cloth stays where it was).
 *
 * Everything works in displacements over the step, u = nx - x (= v dt): an
 * impulse on the velocity is a change of nx, so dt drops out. A change of nx
 * alone changes the velocity the next step starts with (it comes from
 * nx - px at commit); a position correction that must not become velocity
 * shifts the history override q by the same amount.
 *
 * The side a vertex is on comes from the start of the step: every contact
 * normal is oriented so that the relative position of the two contact
 * points at the start of the step lies on its positive side, and responses
 * only push along it, so nothing is pushed across. A particle resting on a
 * collider (marked earlier in the step) is not pushed into it: along that
 * surface's normal it counts as pinned. */
#include "selfcollide.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "alloc.h"
#include "contour.h"
#include "grid.h"
#include "parallel.h"
#include "primitives.h"
#include "response.h"
#include "wetness.h"
#include "invariant.h"
#include "vec3.h"

/* Response passes before the fail-safe. Each pass re-evaluates only what
 * moved, so the later passes are cheap. */
#define SELF_PASSES 4
/* Variable-length outputs of parallel loops (candidate pairs) are written
 * per slice of the loop, slices being fixed ranges independent of the thread
 * count, and concatenated in slice order: the same order as a serial loop. */
#define SLICES 64
/* Margin g around each particle's motion, as a fraction of the thickness:
 * responses that stay within it need no new broadphase. */
#define BOX_MARGIN 0.25
/* Pairs closer than this many thicknesses in the rest shape are neighbours
 * in the cloth itself (for instance across a quad's diagonal): the cloth's
 * own links keep them apart, so they keep only half their rest distance
 * (pair_thickness), not h, which would fight those links. With 2, and culled
 * patches whose normals stay within 60 degrees of a common direction (so
 * distances in space are at least cos 60 = 1/2 of those along the surface),
 * no culled pair can come within its thickness unless the cloth is
 * compressed. */
#define REST_EXCLUSION 2.0
/* Largest angle between a culled region's normals and its cone axis. */
#define CONE_COS 0.5
/* Its sine, sqrt(1 - CONE_COS^2) = sqrt(3) / 2. */
#define CONE_SIN 0.8660254037844386
/* fits_cone: how near the closed form a comparison goes to libm. */
#define FIT_TIE 1e-12
/* Patches: triangles binned by rest centroid into cubes of this many mean
 * edge lengths, split into connected pieces of at most PATCH_MAX triangles. */
#define PATCH_CELL_EDGES 4.0
#define PATCH_MAX 64
/* Patches smaller than this are merged into a neighbour (merge_small_patches). */
#define PATCH_MIN 16
/* After the first pass, proximity corrections smaller than this fraction of
 * the thickness are left alone: they would only buy more passes. */
#define RESIDUAL 1e-3
/* The continuous test counts a coplanarity as a collision when the two
 * elements are within this fraction of the thickness. */
#define CCD_TOLERANCE 0.01
/* Smallest thickness used, as a fraction of the mean rest edge length:
 * a thickness of zero would let responses stop two layers exactly touching. */
#define MIN_THICKNESS 0.01

typedef struct pair_slice {
    /// Scratch for the contour of a region (contour.h), room for the
    /// boundaries of three patches.
    wc_contour_segment *contour;
    int32_t *pairs;
    int64_t count, capacity;
    /// One double per pair where the pairs carry one (vertex-face: the
    /// pair's thickness).
    double *values;
    int64_t value_capacity;
    int32_t *query;
    int32_t query_capacity;
    int failed;
    /* Slices sit side by side and are written by different threads: keep
     * each one's fields off its neighbours' cache lines. */
    char pad[64];
} pair_slice;

/* Compressed lists: the items of list k are items[start[k] .. start[k+1]). */
typedef struct csr {
    int32_t *start;
    int32_t *items;
} csr;

struct wc_self_state {
    int32_t particle_count, triangle_count, edge_count, patch_count;
    /// The cloth's triangles (owned by its topology).
    const int32_t *triangles;
    /// Unique edges of the triangles, 2 particles each (lower index first).
    int32_t *edges;
    /// Lowest-index triangle holding each edge.
    int32_t *edge_owner;
    /// Rest shape (positions at creation), xyz per particle, and the boxes of
    /// the triangles and edges in it.
    double *rest, *rest_triangle_boxes, *rest_edge_boxes;
    double mean_edge;

    /* Patches (built once). */
    int32_t *triangle_patch;
    /// Triangles of each patch, all its particles, the particles it owns
    /// (those whose lowest-index triangle it holds), the edges it owns (the
    /// patch of the edge's owner triangle), and the patches sharing a
    /// particle with it (ascending, itself excluded). Owned particles and
    /// edges are tested once, from their own patch.
    csr patch_triangles, patch_particles, patch_owned_particles, patch_owned_edges, patch_adjacent;
    /// Boundary half-edges of each patch (patch p's are boundary[3 k ..] for
    /// k in [boundary_start[p], boundary_start[p + 1])): from, to (the
    /// triangle's direction) and the patch across the edge (-1: none).
    int32_t *boundary, *boundary_start;
    /// Largest boundary of a patch, in half-edges.
    int32_t boundary_most;
    /// Whether each patch, and each adjacency entry's two patches together,
    /// form an oriented disk (contour.h): only those can be culled.
    uint8_t *patch_disk, *adjacent_disk;
    /// Contour scratch for serial checks (still_valid).
    wc_contour_segment *contour;

    /* Per step. */
    /// Particle boxes (motion grown by g); triangle boxes (corners' boxes
    /// grown by h); edge boxes (ends' boxes).
    double *particle_boxes, *triangle_boxes, *edge_boxes;
    /// Per triangle: normal at the start (3) and end (3) of the step, their
    /// lengths, and a quarter of the length of the t^2 term of the normal
    /// over the step (the bound on how far it bulges between the two).
    double *triangle_normals;
    /// Per patch: box (union of its particles' boxes), the same grown by h
    /// (the grid indexes those), cone axis, and a lower bound on the cosine
    /// of the angle between the axis and any of its normals over the step;
    /// for a patch within CONE_COS, the least cosine between its axis and
    /// a joint axis that still holds it (cones_fit), in closed form
    /// (fits_cone).
    double *patch_boxes, *patch_grown, *patch_axis, *patch_cos, *patch_fit;
    /// Culling decisions of the current broadphase: the patch alone, and
    /// each adjacency entry (overlapping neighbours culled together).
    uint8_t *patch_culled, *adjacent_culled, *patch_touched;
    wc_grid patch_grid;
    /// Patch pairs (P <= Q) opened up into element pairs, and the triples
    /// (P, Q, R) of patches two apart culled with R between them.
    int32_t *open, *joined;
    int64_t open_count, open_capacity, joined_count, joined_capacity;
    pair_slice slices[SLICES];
    /// Candidates: vertex-face (vertex, triangle) and edge-edge (edge, edge)
    /// pairs, with the status of their last evaluation (0 none, 1 proximity,
    /// 2 collision during the step).
    int32_t *vf, *ee;
    uint8_t *vf_status, *ee_status;
    int64_t vf_count, vf_capacity, ee_count, ee_capacity;
    /// Thickness of each vertex-face pair (see pair_thickness).
    double *vf_h;
    int64_t vf_h_capacity;
    /// Per particle: moved since its pairs were last evaluated; put back by
    /// the fail-safe; moved at all by the last wci_self_collide (and how
    /// many were).
    uint8_t *dirty, *reverted, *moved;
    int32_t moved_count;
    /// Whether the candidates were built (for the thickness built_h): a step
    /// whose motion stays inside the boxes and keeps the culling reuses them.
    int built;
    /// Whether triangle_normals, patch_axis and patch_cos describe the
    /// current motion (still_valid brought them up to date and nothing has
    /// moved since), so a broadphase right after need not make them again.
    int cones_current;
    double built_h;

    /* Pieces (NULL for one cloth): see wc_self_pieces. */
    int32_t piece_count;
    /// Piece of each particle and of each patch (patches never span pieces:
    /// they are connected across shared edges).
    int32_t *particle_piece, *patch_piece;
    /// Per piece: whether pairs within it are tested; friction and wet
    /// friction of its material.
    uint8_t *piece_self;
    double *piece_friction, *piece_wet_friction;
};

/* ------------------------------------------------------------------------ */
/* Small vector helpers                                                     */
/* ------------------------------------------------------------------------ */

static void load(const double *x, const double *y, const double *z, int32_t i, double out[3])
{
    out[0] = x[i], out[1] = y[i], out[2] = z[i];
}

/* Whether a (grown by margin) and b overlap. */
static int boxes_overlap_by(const double a[6], const double b[6], double margin)
{
    return a[0] - margin <= b[3] && b[0] <= a[3] + margin && a[1] - margin <= b[4] &&
           b[1] <= a[4] + margin && a[2] - margin <= b[5] && b[2] <= a[5] + margin;
}

static void union_box(double box[6], const double add[6])
{
    for (int k = 0; k < 3; ++k) {
        if (add[k] < box[k]) box[k] = add[k];
        if (add[k + 3] > box[k + 3]) box[k + 3] = add[k + 3];
    }
}

/* Grows an int32 buffer to hold at least `needed` elements, keeping its
 * contents; doubles so that growth is rare. */
static int grow_int32(int32_t **buf, int64_t *capacity, int64_t needed)
{
    if (needed <= *capacity) return 1;
    int64_t cap = *capacity > 0 ? *capacity : 256;
    while (cap < needed) cap *= 2;
    int32_t *p = wci_alloc_array((size_t)cap, sizeof *p);
    if (!p) return 0;
    if (*capacity > 0) memcpy(p, *buf, (size_t)*capacity * sizeof *p);
    wci_free(*buf);
    *buf = p;
    *capacity = cap;
    return 1;
}

static int32_t max2i(int32_t a, int32_t b) { return a > b ? a : b; }
static int32_t min2i(int32_t a, int32_t b) { return a < b ? a : b; }

static int sorted_contains(const int32_t *list, int32_t count, int32_t item)
{
    int32_t lo = 0, hi = count;
    while (lo < hi) {
        int32_t mid = (lo + hi) / 2;
        if (list[mid] < item) lo = mid + 1;
        else hi = mid;
    }
    return lo < count && list[lo] == item ? lo : -1;
}

static void csr_free(csr *c)
{
    wci_free(c->start);
    wci_free(c->items);
    c->start = c->items = NULL;
}

/* ------------------------------------------------------------------------ */
/* Edges and patches (built once)                                           */
/* ------------------------------------------------------------------------ */

/* Sorts pairs (key, value) of int32 by key then value. */
static int compare_pairs(const void *pa, const void *pb)
{
    const int32_t *p = pa, *q = pb;
    if (p[0] != q[0]) return p[0] < q[0] ? -1 : 1;
    return p[1] < q[1] ? -1 : (p[1] > q[1]);
}

/* Builds a CSR of `lists` lists from (list, item) pairs; with `unique`,
 * repeated pairs are dropped. Items come out ascending. */
static int csr_from_pairs(csr *out, int32_t lists, int32_t *pairs, int64_t count, int unique)
{
    qsort(pairs, (size_t)count, 2 * sizeof *pairs, compare_pairs);
    out->start = wci_alloc_array((size_t)lists + 1, sizeof *out->start);
    out->items = wci_alloc_array((size_t)count, sizeof *out->items);
    if (!out->start || !out->items) return 0;
    int64_t n = 0;
    for (int64_t k = 0; k < count; ++k) {
        if (unique && k > 0 && pairs[2 * k] == pairs[2 * k - 2] && pairs[2 * k + 1] == pairs[2 * k - 1])
            continue;
        out->start[pairs[2 * k] + 1]++;
        out->items[n++] = pairs[2 * k + 1];
    }
    for (int32_t k = 0; k < lists; ++k) out->start[k + 1] += out->start[k];
    return 1;
}

typedef struct edge_entry {
    int32_t a, b, triangle, slot;
} edge_entry;

static int compare_edge_entries(const void *pa, const void *pb)
{
    const edge_entry *p = pa, *q = pb;
    if (p->a != q->a) return p->a < q->a ? -1 : 1;
    if (p->b != q->b) return p->b < q->b ? -1 : 1;
    if (p->triangle != q->triangle) return p->triangle < q->triangle ? -1 : 1;
    return p->slot < q->slot ? -1 : (p->slot > q->slot);
}

/* The unique edges of the triangles, each edge's owner triangle, the mean
 * rest edge length, and (for growing patches) each triangle's neighbours
 * across edges shared by exactly two triangles. */
static int build_edges(wc_self_state *s, const wc_cloth *c, int32_t *neighbours)
{
    int32_t t_count = s->triangle_count;
    size_t entries = 3 * (size_t)t_count;
    edge_entry *e = wci_alloc_array(entries, sizeof *e);
    if (!e) return 0;
    for (int32_t t = 0; t < t_count; ++t)
        for (int k = 0; k < 3; ++k) {
            int32_t a = s->triangles[3 * (size_t)t + k], b = s->triangles[3 * (size_t)t + (k + 1) % 3];
            edge_entry *x = e + 3 * (size_t)t + k;
            x->a = a < b ? a : b, x->b = a < b ? b : a, x->triangle = t, x->slot = k;
        }
    qsort(e, entries, sizeof *e, compare_edge_entries);
    int32_t unique = 0;
    for (size_t k = 0; k < entries; ++k)
        if (k == 0 || e[k].a != e[k - 1].a || e[k].b != e[k - 1].b) ++unique;
    s->edge_count = unique;
    s->edges = wci_alloc_array(2 * (size_t)unique, sizeof *s->edges);
    s->edge_owner = wci_alloc_array((size_t)unique, sizeof *s->edge_owner);
    if (!s->edges || !s->edge_owner) {
        wci_free(e);
        return 0;
    }
    for (size_t k = 0; k < entries; ++k) neighbours[k] = -1;
    int32_t id = -1;
    double total = 0.0;
    for (size_t k = 0; k < entries; ++k) {
        int first = k == 0 || e[k].a != e[k - 1].a || e[k].b != e[k - 1].b;
        if (first) {
            ++id;
            s->edges[2 * (size_t)id] = e[k].a;
            s->edges[2 * (size_t)id + 1] = e[k].b;
            s->edge_owner[id] = e[k].triangle; /* sorted by triangle: the lowest */
            double pa[3], pb[3];
            load(c->x, c->y, c->z, e[k].a, pa);
            load(c->x, c->y, c->z, e[k].b, pb);
            total += dist3(pa, pb);
            /* manifold edge: exactly two triangles */
            int two = k + 1 < entries && e[k + 1].a == e[k].a && e[k + 1].b == e[k].b &&
                      !(k + 2 < entries && e[k + 2].a == e[k].a && e[k + 2].b == e[k].b);
            if (two) {
                neighbours[3 * (size_t)e[k].triangle + e[k].slot] = e[k + 1].triangle;
                neighbours[3 * (size_t)e[k + 1].triangle + e[k + 1].slot] = e[k].triangle;
            }
        }
    }
    s->mean_edge = unique ? total / unique : 0.0;
    wci_free(e);
    return 1;
}

/* Bin of a triangle: the cube of side `cell` holding the rest position of
 * its lowest-index particle, as a key that sorts the same on every
 * platform. By that particle rather than the centroid: the two triangles of
 * a quad of a grid or quad mesh share it and fall in one bin, so the bins'
 * walls run along quad edges, and patches are whole quads with boundaries
 * that the contour check passes in one sweep round their centre (a wall
 * between the two triangles of each quad would leave a saw-tooth edge). */
static void triangle_bin(const wc_self_state *s, int32_t t, double cell, int64_t key[3])
{
    const int32_t *tri = s->triangles + 3 * (size_t)t;
    int32_t lowest = min2i(tri[0], min2i(tri[1], tri[2]));
    for (int k = 0; k < 3; ++k) {
        double b = floor(s->rest[3 * (size_t)lowest + k] / cell);
        key[k] = b < -1e15 ? (int64_t)-1e15 : b > 1e15 ? (int64_t)1e15 : (int64_t)b;
    }
}

typedef struct bin_entry {
    int64_t key[3];
    int32_t triangle, bin;
} bin_entry;

static int compare_bins(const void *pa, const void *pb)
{
    const bin_entry *p = pa, *q = pb;
    for (int k = 0; k < 3; ++k)
        if (p->key[k] != q->key[k]) return p->key[k] < q->key[k] ? -1 : 1;
    return p->triangle < q->triangle ? -1 : (p->triangle > q->triangle);
}

static int32_t group_of(int32_t *root, int32_t p)
{
    while (root[p] != p) p = root[p] = root[root[p]];
    return p;
}

/* Patches of fewer than PATCH_MIN triangles are pieces of a bin that its
 * walls cut off (along a cloth's border, a strip one quad wide). Each is
 * merged, in patch order, into the smallest patch across one of its edges
 * that has room (lowest index on a tie), so every patch stays connected;
 * fewer patches mean fewer pairs of them to check and shorter boundaries in
 * all. Renumbers triangle_patch; returns the new count, or -1 on
 * out-of-memory. */
static int32_t merge_small_patches(wc_self_state *s, const int32_t *neighbours, int32_t patches)
{
    int32_t nt = s->triangle_count;
    int32_t *size = wci_alloc_array((size_t)patches + 1, sizeof *size);
    int32_t *root = wci_alloc_array((size_t)patches + 1, sizeof *root);
    int32_t *start = wci_alloc_array((size_t)patches + 2, sizeof *start);
    int32_t *order = wci_alloc_array((size_t)nt + 1, sizeof *order);
    int32_t count = -1;
    if (size && root && start && order) {
        for (int32_t t = 0; t < nt; ++t) ++start[s->triangle_patch[t] + 2];
        for (int32_t p = 0; p < patches; ++p) start[p + 2] += start[p + 1], root[p] = p;
        for (int32_t t = 0; t < nt; ++t) order[start[s->triangle_patch[t] + 1]++] = t;
        /* start[p] .. start[p + 1] now holds patch p's triangles */
        for (int32_t p = 0; p < patches; ++p) size[p] = start[p + 1] - start[p];
        for (int32_t p = 0; p < patches; ++p) {
            int32_t g = group_of(root, p), best = -1;
            if (size[g] >= PATCH_MIN) continue;
            for (int32_t k = start[p]; k < start[p + 1]; ++k)
                for (int j = 0; j < 3; ++j) {
                    int32_t u = neighbours[3 * (size_t)order[k] + j];
                    if (u < 0) continue;
                    int32_t h = group_of(root, s->triangle_patch[u]);
                    if (h == g || size[g] + size[h] > PATCH_MAX) continue;
                    if (best < 0 || size[h] < size[best] || (size[h] == size[best] && h < best)) best = h;
                }
            if (best >= 0) root[g] = best, size[best] += size[g];
        }
        count = 0;
        for (int32_t p = 0; p < patches; ++p) start[p] = group_of(root, p) == p ? count++ : -1;
        for (int32_t t = 0; t < nt; ++t) s->triangle_patch[t] = start[group_of(root, s->triangle_patch[t])];
    }
    wci_free(size);
    wci_free(root);
    wci_free(start);
    wci_free(order);
    return count;
}

/* Patches: the triangles of each bin, lowest index first, grown breadth-first
 * across manifold edges within the bin up to PATCH_MAX triangles, small ones
 * merged into a neighbour. Each patch is connected, which the culling needs. */
static int build_patches(wc_self_state *s, const int32_t *neighbours)
{
    int32_t nt = s->triangle_count, n = s->particle_count;
    double cell = PATCH_CELL_EDGES * (s->mean_edge > 0.0 ? s->mean_edge : 1.0);
    bin_entry *bins = wci_alloc_array((size_t)nt, sizeof *bins);
    int32_t *bin_of = wci_alloc_array((size_t)nt, sizeof *bin_of);
    int32_t *queue = wci_alloc_array((size_t)nt, sizeof *queue);
    s->triangle_patch = wci_alloc_array((size_t)nt, sizeof *s->triangle_patch);
    int ok = bins && bin_of && queue && s->triangle_patch;
    if (ok) {
        for (int32_t t = 0; t < nt; ++t) {
            triangle_bin(s, t, cell, bins[t].key);
            bins[t].triangle = t;
            s->triangle_patch[t] = -1;
        }
        qsort(bins, (size_t)nt, sizeof *bins, compare_bins);
        int32_t b = -1;
        for (int32_t k = 0; k < nt; ++k) {
            const int64_t *p = bins[k].key, *q = k ? bins[k - 1].key : NULL;
            if (!q || p[0] != q[0] || p[1] != q[1] || p[2] != q[2]) ++b;
            bin_of[bins[k].triangle] = b;
        }
        int32_t patches = 0;
        for (int32_t k = 0; k < nt; ++k) {
            int32_t seed = bins[k].triangle;
            if (s->triangle_patch[seed] >= 0) continue;
            int32_t head = 0, tail = 0, size = 0;
            queue[tail++] = seed;
            s->triangle_patch[seed] = patches;
            while (head < tail && size < PATCH_MAX) {
                int32_t t = queue[head++];
                ++size;
                for (int j = 0; j < 3; ++j) {
                    int32_t u = neighbours[3 * (size_t)t + j];
                    if (u < 0 || s->triangle_patch[u] >= 0 || bin_of[u] != bin_of[t]) continue;
                    if (size + (tail - head) >= PATCH_MAX) continue;
                    s->triangle_patch[u] = patches;
                    queue[tail++] = u;
                }
            }
            /* Nothing is queued beyond PATCH_MAX (checked when queueing), so
             * the patch is exactly queue[0 .. tail). */
            ++patches;
        }
        s->patch_count = merge_small_patches(s, neighbours, patches);
        ok = s->patch_count >= 0;
    }
    wci_free(bins);
    wci_free(bin_of);
    wci_free(queue);
    if (!ok) return 0;

    /* Lists per patch, from (patch, item) pairs. */
    int32_t np = s->patch_count;
    size_t most = 3 * (size_t)nt > (size_t)s->edge_count ? 3 * (size_t)nt : (size_t)s->edge_count;
    int32_t *pairs = wci_alloc_array(2 * most, sizeof *pairs);
    int32_t *owner = wci_alloc_array((size_t)n, sizeof *owner);
    if (!pairs || !owner) {
        wci_free(pairs);
        wci_free(owner);
        return 0;
    }
    for (int32_t t = 0; t < nt; ++t) pairs[2 * t] = s->triangle_patch[t], pairs[2 * t + 1] = t;
    ok = csr_from_pairs(&s->patch_triangles, np, pairs, nt, 0);
    for (int32_t t = 0; t < nt && ok; ++t)
        for (int j = 0; j < 3; ++j) {
            pairs[2 * (3 * (size_t)t + j)] = s->triangle_patch[t];
            pairs[2 * (3 * (size_t)t + j) + 1] = s->triangles[3 * (size_t)t + j];
        }
    ok = ok && csr_from_pairs(&s->patch_particles, np, pairs, 3 * (int64_t)nt, 1);
    /* owner triangle of a particle: its lowest-index triangle */
    for (int32_t i = 0; i < n; ++i) owner[i] = -1;
    for (int32_t t = nt - 1; t >= 0; --t)
        for (int j = 0; j < 3; ++j) owner[s->triangles[3 * (size_t)t + j]] = t;
    int64_t owned = 0;
    for (int32_t i = 0; i < n && ok; ++i)
        if (owner[i] >= 0) pairs[2 * owned] = s->triangle_patch[owner[i]], pairs[2 * owned + 1] = i, ++owned;
    ok = ok && csr_from_pairs(&s->patch_owned_particles, np, pairs, owned, 0);
    for (int32_t e = 0; e < s->edge_count && ok; ++e)
        pairs[2 * e] = s->triangle_patch[s->edge_owner[e]], pairs[2 * e + 1] = e;
    ok = ok && csr_from_pairs(&s->patch_owned_edges, np, pairs, s->edge_count, 0);
    wci_free(pairs);
    wci_free(owner);
    if (!ok) return 0;

    /* Adjacency: patches sharing a particle. Invert the particle lists, then
     * pair up the patches of each particle. */
    csr of_particle = {NULL, NULL};
    int64_t entries = s->patch_particles.start[np];
    pairs = wci_alloc_array(2 * (size_t)entries, sizeof *pairs);
    if (!pairs) return 0;
    for (int32_t p = 0; p < np; ++p)
        for (int32_t k = s->patch_particles.start[p]; k < s->patch_particles.start[p + 1]; ++k)
            pairs[2 * (size_t)k] = s->patch_particles.items[k], pairs[2 * (size_t)k + 1] = p;
    ok = csr_from_pairs(&of_particle, n, pairs, entries, 0);
    wci_free(pairs);
    int64_t links = 0;
    for (int32_t i = 0; i < n && ok; ++i) {
        int64_t m = of_particle.start[i + 1] - of_particle.start[i];
        links += m * (m - 1);
    }
    pairs = ok ? wci_alloc_array(2 * (size_t)(links > 0 ? links : 1), sizeof *pairs) : NULL;
    if (pairs) {
        int64_t at = 0;
        for (int32_t i = 0; i < n; ++i)
            for (int32_t a = of_particle.start[i]; a < of_particle.start[i + 1]; ++a)
                for (int32_t b = of_particle.start[i]; b < of_particle.start[i + 1]; ++b)
                    if (a != b)
                        pairs[2 * at] = of_particle.items[a], pairs[2 * at + 1] = of_particle.items[b], ++at;
        ok = csr_from_pairs(&s->patch_adjacent, np, pairs, links, 1);
    } else {
        ok = 0;
    }
    wci_free(pairs);
    csr_free(&of_particle);
    return ok;
}

/* Whether the triangles of one patch, or of two together, form an oriented
 * disk; halves and vertices hold 3 * (their triangle count) entries. */
static int patches_disk(const wc_self_state *s, int32_t p, int32_t q, int32_t *list,
                        wc_half_edge *halves, int32_t *vertices)
{
    const csr *pt = &s->patch_triangles;
    int32_t count = 0;
    for (int32_t k = pt->start[p]; k < pt->start[p + 1]; ++k) list[count++] = pt->items[k];
    for (int32_t k = q >= 0 ? pt->start[q] : 0; q >= 0 && k < pt->start[q + 1]; ++k)
        list[count++] = pt->items[k];
    return wci_region_is_disk(s->triangles, list, count, halves, vertices);
}

/* Each patch's boundary half-edges and which patches, alone and in adjacent
 * pairs, are oriented disks (the contour condition's topology, fixed by the
 * rest mesh). */
static int build_contours(wc_self_state *s, const int32_t *neighbours)
{
    int32_t np = s->patch_count, most = 0;
    const csr *pt = &s->patch_triangles, *adj = &s->patch_adjacent;
    s->boundary_start = wci_alloc_array((size_t)np + 1, sizeof *s->boundary_start);
    s->patch_disk = wci_alloc_array((size_t)np, 1);
    s->adjacent_disk = wci_alloc_array((size_t)adj->start[np] + 1, 1);
    if (!s->boundary_start || !s->patch_disk || !s->adjacent_disk) return 0;
    for (int pass = 0; pass < 2; ++pass) {
        int32_t at = 0;
        for (int32_t p = 0; p < np; ++p) {
            s->boundary_start[p] = at;
            for (int32_t k = pt->start[p]; k < pt->start[p + 1]; ++k) {
                int32_t t = pt->items[k];
                const int32_t *tri = s->triangles + 3 * (size_t)t;
                for (int j = 0; j < 3; ++j) {
                    int32_t across = neighbours[3 * (size_t)t + j];
                    int32_t other = across < 0 ? -1 : s->triangle_patch[across];
                    if (other == p) continue;
                    if (pass) {
                        int32_t *b = s->boundary + 3 * (size_t)at;
                        b[0] = tri[j], b[1] = tri[(j + 1) % 3], b[2] = other;
                    }
                    ++at;
                }
            }
            most = max2i(most, at - s->boundary_start[p]);
        }
        s->boundary_start[np] = at;
        if (!pass && !(s->boundary = wci_alloc_array(3 * (size_t)at + 3, sizeof *s->boundary))) return 0;
    }
    s->boundary_most = most;
    int32_t largest = 0;
    for (int32_t p = 0; p < np; ++p) largest = max2i(largest, pt->start[p + 1] - pt->start[p]);
    int32_t *list = wci_alloc_array(2 * (size_t)largest, sizeof *list);
    int32_t *vertices = wci_alloc_array(6 * (size_t)largest, sizeof *vertices);
    wc_half_edge *halves = wci_alloc_array(6 * (size_t)largest, sizeof *halves);
    int ok = list && vertices && halves;
    for (int32_t p = 0; p < np && ok; ++p) {
        s->patch_disk[p] = (uint8_t)patches_disk(s, p, -1, list, halves, vertices);
        for (int32_t k = adj->start[p]; k < adj->start[p + 1]; ++k) {
            int32_t q = adj->items[k];
            if (q < p) continue;
            uint8_t disk = (uint8_t)patches_disk(s, p, q, list, halves, vertices);
            s->adjacent_disk[k] = disk;
            s->adjacent_disk[adj->start[q] + sorted_contains(adj->items + adj->start[q],
                                                              adj->start[q + 1] - adj->start[q], p)] = disk;
        }
    }
    wci_free(list);
    wci_free(vertices);
    wci_free(halves);
    return ok;
}

/* Copies the pieces into the state: each particle's and each patch's piece
 * and the per-piece settings. */
static int set_pieces(wc_self_state *s, const wc_self_pieces *pieces)
{
    int32_t m = pieces->count;
    s->piece_count = m;
    s->particle_piece = wci_alloc_array((size_t)s->particle_count, sizeof *s->particle_piece);
    s->patch_piece = wci_alloc_array((size_t)s->patch_count, sizeof *s->patch_piece);
    s->piece_self = wci_alloc_array((size_t)m, 1);
    s->piece_friction = wci_alloc_array((size_t)m, sizeof *s->piece_friction);
    s->piece_wet_friction = wci_alloc_array((size_t)m, sizeof *s->piece_wet_friction);
    if (!s->particle_piece || !s->patch_piece || !s->piece_self || !s->piece_friction ||
        !s->piece_wet_friction)
        return 0;
    for (int32_t k = 0; k < m; ++k)
        for (int32_t i = pieces->first[k]; i < pieces->first[k + 1]; ++i) s->particle_piece[i] = k;
    for (int32_t p = 0; p < s->patch_count; ++p) {
        int32_t t = s->patch_triangles.items[s->patch_triangles.start[p]];
        s->patch_piece[p] = s->particle_piece[s->triangles[3 * (size_t)t]];
    }
    memcpy(s->piece_self, pieces->self, (size_t)m);
    wci_self_state_set_friction(s, pieces->friction, pieces->wet_friction);
    return 1;
}

void wci_self_state_set_friction(wc_self_state *s, const double *friction, const double *wet_friction)
{
    memcpy(s->piece_friction, friction, (size_t)s->piece_count * sizeof *friction);
    memcpy(s->piece_wet_friction, wet_friction, (size_t)s->piece_count * sizeof *wet_friction);
}

void wci_self_state_invalidate(wc_self_state *s) { s->built = 0; }

const double *wci_self_state_rest(const wc_self_state *s) { return s->rest; }

const uint8_t *wci_self_state_moved(const wc_self_state *s, int32_t *count)
{
    *count = s->moved_count;
    return s->moved;
}

wc_self_state *wci_self_state_create(const wc_cloth *c) { return wci_self_state_create_pieces(c, NULL); }

wc_self_state *wci_self_state_create_pieces(const wc_cloth *c, const wc_self_pieces *pieces)
{
    WC_ASSERT(c->topology.triangles != NULL || c->topology.triangle_count == 0);
    WC_ASSERT(c->particle_count > 0);
    wc_self_state *s = wci_alloc_array(1, sizeof *s);
    if (!s) return NULL;
    size_t n = (size_t)c->particle_count, nt = (size_t)c->topology.triangle_count;
    s->particle_count = c->particle_count;
    s->triangle_count = c->topology.triangle_count;
    s->triangles = c->topology.triangles;
    memset(&s->patch_grid, 0, sizeof s->patch_grid);
    s->rest = wci_alloc_array(3 * n, sizeof *s->rest);
    int32_t *neighbours = wci_alloc_array(3 * nt, sizeof *neighbours);
    int ok = s->rest && neighbours && build_edges(s, c, neighbours);
    if (ok) {
        for (size_t i = 0; i < n; ++i) load(c->x, c->y, c->z, (int32_t)i, s->rest + 3 * i);
        ok = build_patches(s, neighbours) && build_contours(s, neighbours);
    }
    wci_free(neighbours);
    if (!ok) {
        wci_self_state_destroy(s);
        return NULL;
    }
    size_t np = (size_t)s->patch_count, adjacency = (size_t)s->patch_adjacent.start[np];
    s->rest_triangle_boxes = wci_alloc_array(6 * nt, sizeof *s->rest_triangle_boxes);
    s->rest_edge_boxes = wci_alloc_array(6 * (size_t)s->edge_count, sizeof *s->rest_edge_boxes);
    s->particle_boxes = wci_alloc_array(6 * n, sizeof *s->particle_boxes);
    s->triangle_boxes = wci_alloc_array(6 * nt, sizeof *s->triangle_boxes);
    s->edge_boxes = wci_alloc_array(6 * (size_t)s->edge_count, sizeof *s->edge_boxes);
    s->triangle_normals = wci_alloc_array(9 * nt, sizeof *s->triangle_normals);
    s->patch_boxes = wci_alloc_array(6 * np, sizeof *s->patch_boxes);
    s->patch_grown = wci_alloc_array(6 * np, sizeof *s->patch_grown);
    s->patch_axis = wci_alloc_array(3 * np, sizeof *s->patch_axis);
    s->patch_cos = wci_alloc_array(np, sizeof *s->patch_cos);
    s->patch_fit = wci_alloc_array(np, sizeof *s->patch_fit);
    s->patch_culled = wci_alloc_array(np, 1);
    s->patch_touched = wci_alloc_array(np, 1);
    s->adjacent_culled = wci_alloc_array(adjacency, 1);
    s->dirty = wci_alloc_array(n, 1);
    s->reverted = wci_alloc_array(n, 1);
    s->moved = wci_alloc_array(n, 1);
    size_t region_most = 3 * (size_t)s->boundary_most + 1;
    s->contour = wci_alloc_array(region_most, sizeof *s->contour);
    int slices_ok = 1;
    for (int k = 0; k < SLICES; ++k)
        slices_ok = slices_ok && (s->slices[k].contour = wci_alloc_array(region_most, sizeof *s->contour));
    if (!slices_ok || !s->contour || !s->particle_boxes || !s->triangle_boxes || !s->edge_boxes ||
        !s->triangle_normals ||
        !s->patch_boxes || !s->patch_grown || !s->patch_axis || !s->patch_cos || !s->patch_fit ||
        !s->patch_culled || !s->patch_touched || !s->adjacent_culled || !s->dirty || !s->reverted || !s->moved ||
        !s->rest_triangle_boxes || !s->rest_edge_boxes) {
        wci_self_state_destroy(s);
        return NULL;
    }
    for (size_t t = 0; t < nt; ++t) {
        double *box = s->rest_triangle_boxes + 6 * t;
        for (int j = 0; j < 3; ++j) {
            const double *r = s->rest + 3 * (size_t)s->triangles[3 * t + j];
            double point[6] = {r[0], r[1], r[2], r[0], r[1], r[2]};
            if (j == 0) memcpy(box, point, sizeof point);
            else union_box(box, point);
        }
    }
    for (size_t e = 0; e < (size_t)s->edge_count; ++e) {
        const double *a = s->rest + 3 * (size_t)s->edges[2 * e], *b = s->rest + 3 * (size_t)s->edges[2 * e + 1];
        double *box = s->rest_edge_boxes + 6 * e;
        for (int k = 0; k < 3; ++k) box[k] = min2(a[k], b[k]), box[k + 3] = max2(a[k], b[k]);
    }
    if (pieces && !set_pieces(s, pieces)) {
        wci_self_state_destroy(s);
        return NULL;
    }
    return s;
}

void wci_self_state_destroy(wc_self_state *s)
{
    if (!s) return;
    void *blocks[] = {s->edges, s->edge_owner, s->rest, s->rest_triangle_boxes,
                      s->rest_edge_boxes, s->triangle_patch,
                      s->particle_boxes, s->triangle_boxes, s->edge_boxes, s->triangle_normals,
                      s->patch_boxes, s->patch_grown, s->patch_axis, s->patch_cos, s->patch_fit,
                      s->patch_culled, s->adjacent_culled, s->patch_touched, s->open, s->joined, s->vf,
                      s->ee, s->vf_status, s->ee_status, s->dirty, s->reverted, s->moved, s->vf_h,
                      s->particle_piece, s->patch_piece, s->piece_self, s->piece_friction,
                      s->piece_wet_friction, s->boundary, s->boundary_start, s->patch_disk,
                      s->adjacent_disk, s->contour};
    for (size_t k = 0; k < sizeof blocks / sizeof blocks[0]; ++k) wci_free(blocks[k]);
    csr_free(&s->patch_triangles);
    csr_free(&s->patch_particles);
    csr_free(&s->patch_owned_particles);
    csr_free(&s->patch_owned_edges);
    csr_free(&s->patch_adjacent);
    wci_grid_destroy(&s->patch_grid);
    for (int k = 0; k < SLICES; ++k) {
        wci_free(s->slices[k].pairs);
        wci_free(s->slices[k].values);
        wci_free(s->slices[k].query);
        wci_free(s->slices[k].contour);
    }
    wci_free(s);
}

/* ------------------------------------------------------------------------ */
/* Broadphase                                                               */
/* ------------------------------------------------------------------------ */

/* A particle's box: its motion x -> nx, and as far again ahead (where the
 * next step takes it if its velocity holds), grown by the margin g. A box
 * round this step's motion alone is left by the next step's as soon as a
 * step moves the particle more than g (a falling cloth: every other step),
 * and each time the whole broadphase runs again; ahead, the candidates
 * hold while the velocity changes by less than g per step. The larger box
 * only adds candidates that are not in contact, so what the passes do is
 * unchanged: their contacts are the same pairs in the same order. */
static void particle_box(const wc_cloth *c, int32_t i, double g, double box[6])
{
    double a[3], b[3];
    load(c->x, c->y, c->z, i, a);
    load(c->nx, c->ny, c->nz, i, b);
    for (int k = 0; k < 3; ++k) {
        double ahead = b[k] + (b[k] - a[k]);
        box[k] = min2(a[k], ahead) - g;
        box[k + 3] = max2(a[k], ahead) + g;
    }
}

/* A triangle's normal over the step. With edge vectors linear in t, the
 * (unnormalised) normal is n(t) = (1-t) n0 + t n1 - t(1-t) N2, N2 the cross
 * product of the edges' changes; so |n(t) - lerp(n0, n1)| <= |N2| / 4. */
static void triangle_normal_motion(const wc_cloth *c, const int32_t *tri, double out[9])
{
    double a0[3], b0[3], c0[3], a1[3], b1[3], c1[3], e0[3], f0[3], e1[3], f1[3], de[3], df[3], n2[3];
    load(c->x, c->y, c->z, tri[0], a0), load(c->x, c->y, c->z, tri[1], b0), load(c->x, c->y, c->z, tri[2], c0);
    load(c->nx, c->ny, c->nz, tri[0], a1), load(c->nx, c->ny, c->nz, tri[1], b1), load(c->nx, c->ny, c->nz, tri[2], c1);
    for (int k = 0; k < 3; ++k) {
        e0[k] = b0[k] - a0[k], f0[k] = c0[k] - a0[k];
        e1[k] = b1[k] - a1[k], f1[k] = c1[k] - a1[k];
        de[k] = e1[k] - e0[k], df[k] = f1[k] - f0[k];
    }
    cross3(e0, f0, out);
    cross3(e1, f1, out + 3);
    cross3(de, df, n2);
    out[6] = sqrt(dot3(out, out));
    out[7] = sqrt(dot3(out + 3, out + 3));
    out[8] = 0.25 * sqrt(dot3(n2, n2));
}

/* Lower bound of cos(angle(n(t), axis)) over the step; <= 0 when the normal
 * may turn 90 degrees or more away from the axis (or vanish). */
static double triangle_cos(const double nm[9], const double axis[3])
{
    double lo = min2(dot3(nm, axis), dot3(nm + 3, axis)) - nm[8];
    double hi = max2(nm[6], nm[7]) + nm[8];
    return lo > 0.0 && hi > 0.0 ? lo / hi : -1.0;
}

/* Cone axis (normalised sum of the unit normals at both ends of the step)
 * and the cosine bound of a patch. */
static void patch_cone(wc_self_state *s, int32_t p)
{
    double *axis = s->patch_axis + 3 * (size_t)p;
    axis[0] = axis[1] = axis[2] = 0.0;
    const csr *tris = &s->patch_triangles;
    for (int32_t k = tris->start[p]; k < tris->start[p + 1]; ++k) {
        const double *nm = s->triangle_normals + 9 * (size_t)tris->items[k];
        for (int m = 0; m < 3; ++m) {
            if (nm[6] > 0.0) axis[m] += nm[m] / nm[6];
            if (nm[7] > 0.0) axis[m] += nm[3 + m] / nm[7];
        }
    }
    double cosine = -1.0;
    if (normalize3(axis)) {
        cosine = 1.0;
        for (int32_t k = tris->start[p]; k < tris->start[p + 1] && cosine > 0.0; ++k)
            cosine = min2(cosine, triangle_cos(s->triangle_normals + 9 * (size_t)tris->items[k], axis));
    }
    s->patch_cos[p] = cosine;
    /* cones_fit asks acos(cosine) + acos(c) < acos(CONE_COS) of the angle
     * c to a joint axis: acos falls, so that is c > cos(acos(CONE_COS) -
     * acos(cosine)), one comparison with this instead of two arc cosines
     * per patch and check (the angle difference lies in [0, 60 degrees]).
     * Kept here in closed form (fits_cone). */
    if (cosine > CONE_COS)
        s->patch_fit[p] = CONE_COS * cosine + CONE_SIN * sqrt((1.0 - cosine) * (1.0 + cosine));
}

/* Whether c > cos(acos(CONE_COS) - acos(cosine)) for patch p. Its closed
 * form cos a cos b + sin a sin b (patch_fit; 1 - cosine is exact for a
 * cosine in [0.5, 1], so the square root loses nothing to cancellation)
 * is within a few 1e-16 of it, as is libm's value; only a comparison
 * within FIT_TIE of the closed form pays for libm's arc cosine and cosine
 * (they were 2.3 % of a draped 20 x 20 cloth's step), and every answer is
 * libm's. */
static int fits_cone(const wc_self_state *s, int32_t p, double c)
{
    double fast = s->patch_fit[p];
    if (c > fast + FIT_TIE) return 1;
    if (c < fast - FIT_TIE) return 0;
    return c > cos(acos(CONE_COS) - acos(s->patch_cos[p]));
}

/* Whether the cones of `count` patches fit in one cone of half-angle
 * acos(CONE_COS) around d, the normalised sum of their axes: a normal is at
 * most its patch's half-angle plus the angle between that patch's axis and
 * d away from d. */
static int cones_fit(const wc_self_state *s, const int32_t *patches, int count, double d[3])
{
    d[0] = d[1] = d[2] = 0.0;
    for (int k = 0; k < count; ++k) {
        if (!(s->patch_cos[patches[k]] > CONE_COS)) return 0;
        for (int m = 0; m < 3; ++m) d[m] += s->patch_axis[3 * (size_t)patches[k] + m];
    }
    if (!normalize3(d)) return 0;
    for (int k = 0; k < count; ++k)
        if (!fits_cone(s, patches[k], dot3(s->patch_axis + 3 * (size_t)patches[k], d))) return 0;
    return 1;
}

/* Whether patches[0 .. count) (1 to 3, each adjacent to the next) can skip
 * their element tests over the current motion: their normals within
 * acos(CONE_COS) of one direction d, their triangles an oriented disk, and
 * the disk's boundary projected along d simple over the step (contour.h).
 * contour is scratch for three patches' boundaries. */
static int region_culls(const wc_self_state *s, const wc_cloth *c, const int32_t *patches, int count,
                        wc_contour_segment *contour)
{
    double d[3];
    if (count == 1) {
        if (!(s->patch_cos[patches[0]] > CONE_COS) || !s->patch_disk[patches[0]]) return 0;
        memcpy(d, s->patch_axis + 3 * (size_t)patches[0], sizeof d);
    } else {
        if (!cones_fit(s, patches, count, d)) return 0;
        const csr *adj = &s->patch_adjacent;
        for (int k = 0; k + 1 < count; ++k) {
            int32_t p = patches[k], q = patches[k + 1];
            int32_t at = sorted_contains(adj->items + adj->start[p], adj->start[p + 1] - adj->start[p], q);
            if (at < 0 || !s->adjacent_disk[adj->start[p] + at]) return 0;
        }
    }
    /* The region's boundary: its patches' boundaries less the edges they
     * share. */
    int32_t segments = 0;
    for (int k = 0; k < count; ++k)
        for (int32_t m = s->boundary_start[patches[k]]; m < s->boundary_start[patches[k] + 1]; ++m) {
            const int32_t *b = s->boundary + 3 * (size_t)m;
            int inner = 0;
            for (int j = 0; j < count; ++j) inner |= b[2] == patches[j];
            if (inner) continue;
            contour[segments].from = b[0], contour[segments].to = b[1];
            ++segments;
        }
    return wci_contour_simple(contour, segments, d, c->x, c->y, c->z, c->nx, c->ny, c->nz, s->mean_edge);
}

/* A common neighbour r of non-adjacent patches p and q through which the
 * three form one connected region that can be culled, or -1. */
static int32_t joining_patch(const wc_self_state *s, const wc_cloth *c, int32_t p, int32_t q,
                             wc_contour_segment *contour)
{
    const csr *adj = &s->patch_adjacent;
    int32_t i = adj->start[p], j = adj->start[q];
    while (i < adj->start[p + 1] && j < adj->start[q + 1]) {
        int32_t a = adj->items[i], b = adj->items[j];
        if (a < b) {
            ++i;
        } else if (b < a) {
            ++j;
        } else {
            int32_t three[3] = {p, a, q};
            if (region_culls(s, c, three, 3, contour)) return a;
            ++i, ++j;
        }
    }
    return -1;
}

/* Patch-level pairs of the patches in [first, end): for each P, every
 * Q >= P whose grown box meets P's box, as triples (P, Q, how): how = -1 for
 * a pair to open, -2 for neighbours culled together, r >= 0 for patches two
 * apart culled together with their common neighbour r. */
static void patch_pairs_slice(wc_self_state *s, const wc_cloth *c, pair_slice *sl, int32_t first,
                              int32_t end)
{
    for (int32_t p = first; p < end && !sl->failed; ++p) {
        s->patch_culled[p] = 0;
        int32_t found;
        for (;;) {
            found = wci_grid_query(&s->patch_grid, s->patch_boxes + 6 * (size_t)p, sl->query,
                                  sl->query_capacity);
            if (found <= sl->query_capacity) break;
            int64_t cap = sl->query_capacity;
            if (!grow_int32(&sl->query, &cap, found)) {
                sl->failed = 1;
                return;
            }
            sl->query_capacity = (int32_t)cap;
        }
        const int32_t *adj = s->patch_adjacent.items + s->patch_adjacent.start[p];
        int32_t adj_count = s->patch_adjacent.start[p + 1] - s->patch_adjacent.start[p];
        for (int32_t k = 0; k < found; ++k) {
            int32_t q = sl->query[k], how;
            if (q < p) continue;
            /* a piece without self-collision only meets other pieces */
            if (s->patch_piece && s->patch_piece[p] == s->patch_piece[q] &&
                !s->piece_self[s->patch_piece[p]])
                continue;
            if (q == p) {
                /* p is only in this slice: its flag is this thread's */
                s->patch_culled[p] = (uint8_t)region_culls(s, c, &p, 1, sl->contour);
                if (s->patch_culled[p]) continue;
                how = -1;
            } else if (sorted_contains(adj, adj_count, q) >= 0) {
                int32_t two[2] = {p, q};
                how = region_culls(s, c, two, 2, sl->contour) ? -2 : -1;
            } else {
                how = joining_patch(s, c, p, q, sl->contour);
                if (how < 0) how = -1;
            }
            if (!grow_int32(&sl->pairs, &sl->capacity, 3 * (sl->count + 1))) {
                sl->failed = 1;
                return;
            }
            int32_t *out = sl->pairs + 3 * sl->count++;
            out[0] = p, out[1] = q, out[2] = how;
        }
    }
}

/* Appends a pair to a slice; on out-of-memory marks the slice failed. */
static void slice_push(pair_slice *sl, int32_t a, int32_t b)
{
    if (sl->failed) return;
    if (!grow_int32(&sl->pairs, &sl->capacity, 2 * (sl->count + 1))) {
        sl->failed = 1;
        return;
    }
    sl->pairs[2 * sl->count] = a;
    sl->pairs[2 * sl->count + 1] = b;
    sl->count++;
}

/* Sets the value of the slice's last pair. */
static void slice_value(pair_slice *sl, double value)
{
    if (sl->failed) return;
    if (sl->count > sl->value_capacity) {
        int64_t cap = sl->value_capacity > 0 ? sl->value_capacity : 256;
        while (cap < sl->count) cap *= 2;
        double *p = wci_alloc_array((size_t)cap, sizeof *p);
        if (!p) {
            sl->failed = 1;
            return;
        }
        if (sl->value_capacity > 0) memcpy(p, sl->values, (size_t)sl->value_capacity * sizeof *p);
        wci_free(sl->values);
        sl->values = p;
        sl->value_capacity = cap;
    }
    sl->values[sl->count - 1] = value;
}

/* Scratch list of the slice (its query buffer, free once the patch pairs
 * are known), grown to hold `count` items; NULL on out-of-memory. */
static int32_t *slice_scratch(pair_slice *sl, int32_t count)
{
    if (count > sl->query_capacity) {
        int64_t cap = sl->query_capacity;
        if (!grow_int32(&sl->query, &cap, count)) {
            sl->failed = 1;
            return NULL;
        }
        sl->query_capacity = (int32_t)cap;
    }
    return sl->query;
}

typedef struct self_ctx {
    const double *x, *y, *z, *nx, *ny, *nz;
    const double *rest;
    /// Piece of each particle, or NULL for one cloth.
    const int32_t *piece;
    /// Thickness, CCD tolerance, squared rest distance below which a pair
    /// counts as neighbours (see pair_thickness).
    double h, tol, exclude2;
} self_ctx;

enum { NO_CONTACT = 0, PROXIMITY = 1, COLLISION = 2 };

/* The thickness a pair keeps: h, except for pairs that were within
 * REST_EXCLUSION * h in the rest shape (neighbours in the cloth itself, such
 * as across a quad's diagonal). Those keep half their rest distance, so the
 * repulsion never fights the cloth's own links yet still holds the two sides
 * of a tight crease apart; never less than a few CCD tolerances, so that a
 * pair held apart is not a collision for the continuous test. */
static double pair_thickness(const self_ctx *ctx, double rest2)
{
    if (!(rest2 < ctx->exclude2)) return ctx->h;
    double t = 0.5 * sqrt(rest2);
    if (t > ctx->h) t = ctx->h;
    if (t < 4.0 * ctx->tol) t = 4.0 * ctx->tol;
    return t;
}

/* Different pieces are different cloths: how far apart they were at rest
 * means nothing, so their pairs keep the full thickness. For both kinds of
 * pair ids[0] is on the first element and ids[3] on the second. */
static int across_pieces(const self_ctx *ctx, const int32_t ids[4])
{
    return ctx->piece && ctx->piece[ids[0]] != ctx->piece[ids[3]];
}

static double rest2_vf(const self_ctx *ctx, const int32_t ids[4])
{
    if (across_pieces(ctx, ids)) return INFINITY;
    double bary[3];
    const double *r = ctx->rest;
    return wci_point_triangle_closest(r + 3 * (size_t)ids[0], r + 3 * (size_t)ids[1],
                                     r + 3 * (size_t)ids[2], r + 3 * (size_t)ids[3], bary);
}

static double rest2_ee(const self_ctx *ctx, const int32_t ids[4])
{
    if (across_pieces(ctx, ids)) return INFINITY;
    double u, v;
    const double *r = ctx->rest;
    return wci_segment_segment_closest(r + 3 * (size_t)ids[0], r + 3 * (size_t)ids[1],
                                      r + 3 * (size_t)ids[2], r + 3 * (size_t)ids[3], &u, &v);
}

/* Vertices of patch p (owned) against triangles of patch q: pairs whose
 * boxes meet within the pair's thickness (see pair_thickness; the rest
 * boxes spare computing rest distances for pairs that were far apart). */
static void open_vf(const wc_self_state *s, const self_ctx *ctx, pair_slice *vf, int32_t p,
                    int32_t q)
{
    const csr *own = &s->patch_owned_particles, *tris = &s->patch_triangles;
    const double *pbox = s->patch_boxes + 6 * (size_t)p, *qbox = s->patch_boxes + 6 * (size_t)q;
    double h = ctx->h, reach = REST_EXCLUSION * h;
    /* q's triangles that reach p at all (triangle boxes include h) */
    int32_t *near = slice_scratch(vf, tris->start[q + 1] - tris->start[q]);
    if (!near) return;
    int32_t count = 0;
    for (int32_t b = tris->start[q]; b < tris->start[q + 1]; ++b)
        if (boxes_overlap_by(pbox, s->triangle_boxes + 6 * (size_t)tris->items[b], 0.0))
            near[count++] = tris->items[b];
    for (int32_t a = own->start[p]; a < own->start[p + 1] && count; ++a) {
        int32_t v = own->items[a];
        const double *vbox = s->particle_boxes + 6 * (size_t)v;
        if (!boxes_overlap_by(vbox, qbox, h)) continue;
        const double *vr = s->rest + 3 * (size_t)v;
        double vrest[6] = {vr[0], vr[1], vr[2], vr[0], vr[1], vr[2]};
        for (int32_t b = 0; b < count; ++b) {
            int32_t t = near[b];
            const int32_t *tri = s->triangles + 3 * (size_t)t;
            const double *tbox = s->triangle_boxes + 6 * (size_t)t;
            if (tri[0] == v || tri[1] == v || tri[2] == v || !boxes_overlap_by(vbox, tbox, 0.0))
                continue;
            /* The pair's own thickness only matters when the boxes meet
             * within h but not closer; otherwise it is left to the first
             * proximity test that needs it (-1). */
            double hp = -1.0;
            if (!boxes_overlap_by(vbox, tbox, -h)) {
                hp = h;
                if (boxes_overlap_by(vrest, s->rest_triangle_boxes + 6 * (size_t)t, reach)) {
                    int32_t ids[4] = {v, tri[0], tri[1], tri[2]};
                    hp = pair_thickness(ctx, rest2_vf(ctx, ids));
                    if (!boxes_overlap_by(vbox, tbox, hp - h)) continue;
                }
            }
            slice_push(vf, v, t);
            slice_value(vf, hp);
        }
    }
}

/* Edges of patch p (owned) against edges of patch q (for p == q, each pair
 * once) whose boxes meet: edge pairs only need the continuous test. */
static void open_ee(const wc_self_state *s, pair_slice *ee, int32_t p, int32_t q)
{
    const csr *own = &s->patch_owned_edges;
    const double *pbox = s->patch_boxes + 6 * (size_t)p, *qbox = s->patch_boxes + 6 * (size_t)q;
    int32_t *near = slice_scratch(ee, own->start[q + 1] - own->start[q]);
    if (!near) return;
    int32_t count = 0;
    for (int32_t b = own->start[q]; b < own->start[q + 1]; ++b)
        if (boxes_overlap_by(pbox, s->edge_boxes + 6 * (size_t)own->items[b], 0.0))
            near[count++] = own->items[b];
    int32_t from = 0;
    for (int32_t a = own->start[p]; a < own->start[p + 1]; ++a) {
        int32_t e = own->items[a];
        /* p == q: near[] is p's edge list itself; pair each with later ones */
        if (p == q) from = a - own->start[p] + 1;
        const double *ebox = s->edge_boxes + 6 * (size_t)e;
        if (!boxes_overlap_by(ebox, qbox, 0.0)) continue;
        const int32_t *ev = s->edges + 2 * (size_t)e;
        for (int32_t b = from; b < count; ++b) {
            int32_t f = near[b];
            const int32_t *fv = s->edges + 2 * (size_t)f;
            if (fv[0] == ev[0] || fv[0] == ev[1] || fv[1] == ev[0] || fv[1] == ev[1]) continue;
            if (boxes_overlap_by(ebox, s->edge_boxes + 6 * (size_t)f, 0.0)) slice_push(ee, e, f);
        }
    }
}

/* Concatenates slices (entries of `stride` ints) in order into one list,
 * with a zeroed status byte per entry when status is given. */
static int gather(const pair_slice *slices, int stride, int32_t **pairs, uint8_t **status,
                  int64_t *count, int64_t *capacity)
{
    int64_t total = 0;
    for (int k = 0; k < SLICES; ++k) {
        if (slices[k].failed) return 0;
        total += slices[k].count;
    }
    if (total > *capacity) {
        int64_t cap = *capacity > 0 ? *capacity : 1024;
        while (cap < total) cap *= 2;
        wci_free(*pairs);
        *pairs = wci_alloc_array((size_t)stride * (size_t)cap, sizeof **pairs);
        if (status) {
            wci_free(*status);
            *status = wci_alloc_array((size_t)cap, 1);
        }
        *capacity = (*pairs && (!status || *status)) ? cap : 0;
        if (!*capacity) return 0;
    }
    int64_t at = 0;
    for (int k = 0; k < SLICES; ++k) {
        if (slices[k].count)
            memcpy(*pairs + stride * at, slices[k].pairs,
                   (size_t)stride * (size_t)slices[k].count * sizeof **pairs);
        at += slices[k].count;
    }
    *count = total;
    if (status && total) memset(*status, 0, (size_t)total); /* *status is NULL until a pair is found */
    return 1;
}

/* Range k of SLICES equal parts of [0, count). */
static int32_t slice_begin(int64_t count, int k) { return (int32_t)(count * k / SLICES); }

/* Boxes, cones, culling and candidate pairs of the current motion x -> nx. */
static wc_status broadphase(wc_self_state *s, const wc_cloth *c, const self_ctx *ctx, double g,
                            int threads)
{
    double h = ctx->h;
    int32_t n = s->particle_count, nt = s->triangle_count, np = s->patch_count;
    (void)threads;
#pragma omp parallel for schedule(static) num_threads(threads) if (n >= WC_PARALLEL_MIN)
    for (int32_t i = 0; i < n; ++i) particle_box(c, i, g, s->particle_boxes + 6 * (size_t)i);
#pragma omp parallel for schedule(static) num_threads(threads) if (nt >= WC_PARALLEL_MIN)
    for (int32_t t = 0; t < nt; ++t) {
        const int32_t *tri = s->triangles + 3 * (size_t)t;
        if (!s->cones_current) triangle_normal_motion(c, tri, s->triangle_normals + 9 * (size_t)t);
        double *box = s->triangle_boxes + 6 * (size_t)t;
        memcpy(box, s->particle_boxes + 6 * (size_t)tri[0], 6 * sizeof *box);
        union_box(box, s->particle_boxes + 6 * (size_t)tri[1]);
        union_box(box, s->particle_boxes + 6 * (size_t)tri[2]);
        for (int k = 0; k < 3; ++k) box[k] -= h, box[k + 3] += h;
    }
    /* Per patch: box, cone, and the boxes of the edges it owns. */
#pragma omp parallel for schedule(static) num_threads(threads) if (nt >= WC_PARALLEL_MIN)
    for (int32_t p = 0; p < np; ++p) {
        double *box = s->patch_boxes + 6 * (size_t)p;
        const csr *pp = &s->patch_particles, *pe = &s->patch_owned_edges;
        memcpy(box, s->particle_boxes + 6 * (size_t)pp->items[pp->start[p]], 6 * sizeof *box);
        for (int32_t k = pp->start[p] + 1; k < pp->start[p + 1]; ++k)
            union_box(box, s->particle_boxes + 6 * (size_t)pp->items[k]);
        double *grown = s->patch_grown + 6 * (size_t)p;
        for (int k = 0; k < 3; ++k) grown[k] = box[k] - h, grown[k + 3] = box[k + 3] + h;
        if (!s->cones_current) patch_cone(s, p);
        for (int32_t k = pe->start[p]; k < pe->start[p + 1]; ++k) {
            int32_t e = pe->items[k];
            double *eb = s->edge_boxes + 6 * (size_t)e;
            memcpy(eb, s->particle_boxes + 6 * (size_t)s->edges[2 * (size_t)e], 6 * sizeof *eb);
            union_box(eb, s->particle_boxes + 6 * (size_t)s->edges[2 * (size_t)e + 1]);
        }
    }
    /* Patch grid: cells about one grown patch box across (serial sum, so the
     * same bits for any thread count; the query results do not depend on it
     * anyway). */
    double extent = 0.0;
    for (int32_t p = 0; p < np; ++p) {
        const double *b = s->patch_grown + 6 * (size_t)p;
        extent += max2(b[3] - b[0], max2(b[4] - b[1], b[5] - b[2]));
    }
    double cell = np ? extent / np : 1.0;
    if (!(cell > 0.0) || !isfinite(cell)) cell = 1.0;
    if (wci_grid_update(&s->patch_grid, s->patch_grown, np, cell)) return WC_ERROR_OUT_OF_MEMORY;

    for (int k = 0; k < SLICES; ++k) s->slices[k].count = 0, s->slices[k].failed = 0;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) if (nt >= WC_PARALLEL_MIN)
    for (int k = 0; k < SLICES; ++k)
        patch_pairs_slice(s, c, &s->slices[k], slice_begin(np, k), slice_begin(np, k + 1));
    if (!gather(s->slices, 3, &s->open, NULL, &s->open_count, &s->open_capacity))
        return WC_ERROR_OUT_OF_MEMORY;
    /* Culling decisions (serial: few): patches alone, neighbours (a flag per
     * adjacency entry, both ways), patches two apart (triples); the pairs to
     * open are compacted in place to (P, Q). */
    memset(s->adjacent_culled, 0, (size_t)s->patch_adjacent.start[np]);
    const csr *adj = &s->patch_adjacent;
    int64_t open = 0, joined = 0;
    for (int64_t k = 0; k < s->open_count; ++k) {
        /* read before the compaction below may overwrite: 2 * open <= 3 k */
        int32_t p = s->open[3 * k], q = s->open[3 * k + 1], how = s->open[3 * k + 2];
        if (how == -1) {
            s->open[2 * open] = p, s->open[2 * open + 1] = q, ++open;
        } else if (how == -2) {
            int32_t at = sorted_contains(adj->items + adj->start[p], adj->start[p + 1] - adj->start[p], q);
            int32_t back = sorted_contains(adj->items + adj->start[q], adj->start[q + 1] - adj->start[q], p);
            s->adjacent_culled[adj->start[p] + at] = 1;
            s->adjacent_culled[adj->start[q] + back] = 1;
        } else {
            if (!grow_int32(&s->joined, &s->joined_capacity, 3 * (joined + 1)))
                return WC_ERROR_OUT_OF_MEMORY;
            s->joined[3 * joined] = p, s->joined[3 * joined + 1] = q, s->joined[3 * joined + 2] = how;
            ++joined;
        }
    }
    s->open_count = open;
    s->joined_count = joined;

    /* Element pairs of the opened patch pairs: vertex-face both ways, then
     * edge-edge. */
    for (int k = 0; k < SLICES; ++k) s->slices[k].count = 0, s->slices[k].failed = 0;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) if (open >= 64)
    for (int k = 0; k < SLICES; ++k)
        for (int64_t m = slice_begin(open, k); m < slice_begin(open, k + 1); ++m) {
            int32_t p = s->open[2 * m], q = s->open[2 * m + 1];
            open_vf(s, ctx, &s->slices[k], p, q);
            if (p != q) open_vf(s, ctx, &s->slices[k], q, p);
        }
    if (!gather(s->slices, 2, &s->vf, &s->vf_status, &s->vf_count, &s->vf_capacity))
        return WC_ERROR_OUT_OF_MEMORY;
    if (s->vf_h_capacity < s->vf_capacity) {
        wci_free(s->vf_h);
        s->vf_h = wci_alloc_array((size_t)s->vf_capacity, sizeof *s->vf_h);
        s->vf_h_capacity = s->vf_h ? s->vf_capacity : 0;
        if (!s->vf_h) return WC_ERROR_OUT_OF_MEMORY;
    }
    for (int k = 0, at = 0; k < SLICES; at += (int)s->slices[k].count, ++k)
        if (s->slices[k].count)
            memcpy(s->vf_h + at, s->slices[k].values, (size_t)s->slices[k].count * sizeof *s->vf_h);
    for (int k = 0; k < SLICES; ++k) s->slices[k].count = 0, s->slices[k].failed = 0;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) if (open >= 64)
    for (int k = 0; k < SLICES; ++k)
        for (int64_t m = slice_begin(open, k); m < slice_begin(open, k + 1); ++m)
            open_ee(s, &s->slices[k], s->open[2 * m], s->open[2 * m + 1]);
    if (!gather(s->slices, 2, &s->ee, &s->ee_status, &s->ee_count, &s->ee_capacity))
        return WC_ERROR_OUT_OF_MEMORY;
    return WC_OK;
}

/* ------------------------------------------------------------------------ */
/* Narrow phase                                                             */
/* ------------------------------------------------------------------------ */

/* A contact between two points of the cloth: the first is sum w_k X_k over
 * w_k > 0, the second over w_k < 0; their relative position D = sum w_k X_k.
 * n is unit (or zero when no direction could be found), with D at the start
 * of the step on its positive side; d0 = D(start) . n; h is the pair's
 * thickness. */
typedef struct self_contact {
    int kind;
    int32_t p[4];
    double w[4];
    double n[3];
    double d0, h;
} self_contact;

static void relative(const double *x, const double *y, const double *z, const self_contact *k,
                     double out[3])
{
    out[0] = out[1] = out[2] = 0.0;
    for (int j = 0; j < 4; ++j) {
        out[0] += k->w[j] * x[k->p[j]];
        out[1] += k->w[j] * y[k->p[j]];
        out[2] += k->w[j] * z[k->p[j]];
    }
}

/* Orients n so that the start-of-step relative position is on its positive
 * side (the side each element was on), or, when the start gives no side,
 * so that the elements approach along it. */
static void orient(const self_ctx *ctx, self_contact *k)
{
    double d0[3];
    relative(ctx->x, ctx->y, ctx->z, k, d0);
    double s = dot3(d0, k->n);
    if (s == 0.0) {
        double d1[3];
        relative(ctx->nx, ctx->ny, ctx->nz, k, d1);
        s = -dot3(d1, k->n); /* approaching: D . n decreases */
    }
    if (s < 0.0)
        for (int m = 0; m < 3; ++m) k->n[m] = -k->n[m];
    k->d0 = fabs(dot3(d0, k->n));
}

/* Fallback normal: the relative position at time t (contact points), else at
 * the start. */
static void fallback_normal(const self_ctx *ctx, self_contact *k, double t)
{
    double d0[3], d1[3];
    relative(ctx->x, ctx->y, ctx->z, k, d0);
    relative(ctx->nx, ctx->ny, ctx->nz, k, d1);
    lerp3(d0, d1, t, k->n);
    if (normalize3(k->n)) return;
    memcpy(k->n, d0, sizeof d0);
    if (!normalize3(k->n)) k->n[0] = k->n[1] = k->n[2] = 0.0;
}

/* Largest |u_i - u_j| with i in the first group and j in the second: it
 * bounds how fast the distance between the two elements changes over the
 * step (points of an element move with convex combinations of its corners'
 * motions). */
static double max_relative_motion(double u[4][3], int first_count)
{
    double l2 = 0.0;
    for (int i = 0; i < first_count; ++i)
        for (int j = first_count; j < 4; ++j) {
            double d[3] = {u[i][0] - u[j][0], u[i][1] - u[j][1], u[i][2] - u[j][2]};
            double m = dot3(d, d);
            if (m > l2) l2 = m;
        }
    return sqrt(l2);
}

/* Loads the four particles' start and end positions and motions; returns 0
 * when the swept boxes of the two elements (the first `first` particles and
 * the rest) are more than h apart. */
static int load_pair(const self_ctx *ctx, const int32_t ids[4], int first, double margin,
                     double p0[4][3], double p1[4][3], double u[4][3])
{
    for (int j = 0; j < 4; ++j) {
        load(ctx->x, ctx->y, ctx->z, ids[j], p0[j]);
        load(ctx->nx, ctx->ny, ctx->nz, ids[j], p1[j]);
    }
    for (int m = 0; m < 3; ++m) {
        double alo = min2(p0[0][m], p1[0][m]), ahi = max2(p0[0][m], p1[0][m]);
        for (int j = 1; j < first; ++j)
            alo = min2(alo, min2(p0[j][m], p1[j][m])), ahi = max2(ahi, max2(p0[j][m], p1[j][m]));
        double blo = min2(p0[first][m], p1[first][m]), bhi = max2(p0[first][m], p1[first][m]);
        for (int j = first + 1; j < 4; ++j)
            blo = min2(blo, min2(p0[j][m], p1[j][m])), bhi = max2(bhi, max2(p0[j][m], p1[j][m]));
        if (ahi + margin < blo || alo - margin > bhi) return 0;
    }
    for (int j = 0; j < 4; ++j)
        for (int m = 0; m < 3; ++m) u[j][m] = p1[j][m] - p0[j][m];
    return 1;
}

/* Vertex v against triangle tri; *hp is the pair's thickness, or -1 until
 * first needed (then computed and kept: each pair is evaluated by one
 * iteration at a time, and the value does not depend on when). With
 * ccd_only, proximity is not looked at. */
static int eval_vf(const self_ctx *ctx, int32_t v, const int32_t *tri, double *hp, int ccd_only,
                   self_contact *k)
{
    double p0[4][3], p1[4][3], u[4][3];
    int32_t ids[4] = {v, tri[0], tri[1], tri[2]};
    if (!load_pair(ctx, ids, 1, ctx->h, p0, p1, u)) return NO_CONTACT;
    for (int j = 0; j < 4; ++j) k->p[j] = ids[j];
    double bary1[3];
    double d1 = sqrt(wci_point_triangle_closest(p1[0], p1[1], p1[2], p1[3], bary1));
    /* The distance changes at most at rate L, so over the step it stays above
     * d1 - L, and above (d0 + d1 - L) / 2: when that exceeds the tolerance
     * the cubic cannot find a collision. d0 only when d1 alone cannot tell. */
    double lip = max_relative_motion(u, 1);
    int ccd = d1 - lip <= ctx->tol;
    if (ccd) {
        double bary0[3];
        double d0 = sqrt(wci_point_triangle_closest(p0[0], p0[1], p0[2], p0[3], bary0));
        ccd = 0.5 * (d0 + d1 - lip) <= ctx->tol;
    }
    double t, bary[3];
    if (ccd && wci_ccd_point_triangle(p0[0], p1[0], p0[1], p1[1], p0[2], p1[2], p0[3], p1[3],
                                     ctx->tol, &t, bary)) {
        k->kind = COLLISION;
        if (*hp < 0.0) *hp = pair_thickness(ctx, rest2_vf(ctx, ids));
        k->h = *hp;
        k->w[0] = 1.0, k->w[1] = -bary[0], k->w[2] = -bary[1], k->w[3] = -bary[2];
        double a[3], b[3], c[3];
        lerp3(p0[1], p1[1], t, a), lerp3(p0[2], p1[2], t, b), lerp3(p0[3], p1[3], t, c);
        wci_triangle_normal(a, b, c, k->n);
        if (dot3(k->n, k->n) == 0.0) fallback_normal(ctx, k, t);
        orient(ctx, k);
        return COLLISION;
    }
    if (ccd_only || !(d1 < ctx->h)) return NO_CONTACT;
    if (*hp < 0.0) *hp = pair_thickness(ctx, rest2_vf(ctx, ids));
    if (!(d1 < *hp)) return NO_CONTACT;
    k->h = *hp;
    k->kind = PROXIMITY;
    k->w[0] = 1.0, k->w[1] = -bary1[0], k->w[2] = -bary1[1], k->w[3] = -bary1[2];
    for (int m = 0; m < 3; ++m)
        k->n[m] = p1[0][m] - (bary1[0] * p1[1][m] + bary1[1] * p1[2][m] + bary1[2] * p1[3][m]);
    /* At (nearly) zero distance the direction is noise: use the face normal. */
    if (!(d1 > 1e-9 * ctx->h) || !normalize3(k->n)) {
        wci_triangle_normal(p1[1], p1[2], p1[3], k->n);
        if (dot3(k->n, k->n) == 0.0) fallback_normal(ctx, k, 1.0);
    }
    orient(ctx, k);
    return PROXIMITY;
}

/* Edge (a, b) against edge (c, d): the continuous test only. */
static int eval_ee(const self_ctx *ctx, const int32_t *e, const int32_t *f, int ccd_only,
                   self_contact *k)
{
    double p0[4][3], p1[4][3], u[4][3];
    int32_t ids[4] = {e[0], e[1], f[0], f[1]};
    if (!load_pair(ctx, ids, 2, ctx->tol, p0, p1, u)) return NO_CONTACT;
    for (int j = 0; j < 4; ++j) k->p[j] = ids[j];
    double s1, t1;
    double d1 = sqrt(wci_segment_segment_closest(p1[0], p1[1], p1[2], p1[3], &s1, &t1));
    double lip = max_relative_motion(u, 2);
    int ccd = d1 - lip <= ctx->tol;
    if (ccd) {
        double s0, t0;
        double d0 = sqrt(wci_segment_segment_closest(p0[0], p0[1], p0[2], p0[3], &s0, &t0));
        ccd = 0.5 * (d0 + d1 - lip) <= ctx->tol;
    }
    double t, s, v;
    if (ccd && wci_ccd_edge_edge(p0[0], p1[0], p0[1], p1[1], p0[2], p1[2], p0[3], p1[3], ctx->tol,
                                &t, &s, &v)) {
        k->kind = COLLISION;
        k->h = pair_thickness(ctx, rest2_ee(ctx, ids));
        k->w[0] = 1.0 - s, k->w[1] = s, k->w[2] = -(1.0 - v), k->w[3] = -v;
        double a[3], b[3], c[3], d[3], ea[3], eb[3];
        lerp3(p0[0], p1[0], t, a), lerp3(p0[1], p1[1], t, b);
        lerp3(p0[2], p1[2], t, c), lerp3(p0[3], p1[3], t, d);
        for (int m = 0; m < 3; ++m) ea[m] = b[m] - a[m], eb[m] = d[m] - c[m];
        cross3(ea, eb, k->n);
        /* Nearly parallel edges have no reliable cross product. */
        if (dot3(k->n, k->n) <= 1e-12 * dot3(ea, ea) * dot3(eb, eb) || !normalize3(k->n))
            fallback_normal(ctx, k, t);
        orient(ctx, k);
        return COLLISION;
    }
    (void)ccd_only; /* edge pairs have no proximity: see the header */
    return NO_CONTACT;
}

static int vf_pair(wc_self_state *s, const self_ctx *ctx, int64_t i, int ccd_only,
                   self_contact *k)
{
    const int32_t *pr = s->vf + 2 * i;
    return eval_vf(ctx, pr[0], s->triangles + 3 * (size_t)pr[1], s->vf_h + i, ccd_only, k);
}

static int ee_pair(const wc_self_state *s, const self_ctx *ctx, int64_t i, int ccd_only,
                   self_contact *k)
{
    const int32_t *pr = s->ee + 2 * i;
    return eval_ee(ctx, s->edges + 2 * (size_t)pr[0], s->edges + 2 * (size_t)pr[1], ccd_only, k);
}

/* Re-evaluates, in parallel, every pair with a particle that moved since its
 * last evaluation; each iteration writes only its own status byte. */
static void evaluate(wc_self_state *s, const self_ctx *ctx, int ccd_only, int threads)
{
    const uint8_t *dirty = s->dirty;
    int64_t nvf = s->vf_count, nee = s->ee_count;
    (void)threads;
#pragma omp parallel for schedule(static) num_threads(threads) if (nvf >= WC_PARALLEL_MIN)
    for (int64_t i = 0; i < nvf; ++i) {
        const int32_t *pr = s->vf + 2 * i, *tri = s->triangles + 3 * (size_t)pr[1];
        if (!(dirty[pr[0]] | dirty[tri[0]] | dirty[tri[1]] | dirty[tri[2]])) continue;
        self_contact k;
        s->vf_status[i] = (uint8_t)vf_pair(s, ctx, i, ccd_only, &k);
    }
#pragma omp parallel for schedule(static) num_threads(threads) if (nee >= WC_PARALLEL_MIN)
    for (int64_t i = 0; i < nee; ++i) {
        const int32_t *pr = s->ee + 2 * i;
        const int32_t *e = s->edges + 2 * (size_t)pr[0], *f = s->edges + 2 * (size_t)pr[1];
        if (!(dirty[e[0]] | dirty[e[1]] | dirty[f[0]] | dirty[f[1]])) continue;
        self_contact k;
        s->ee_status[i] = (uint8_t)ee_pair(s, ctx, i, ccd_only, &k);
    }
    memset(s->dirty, 0, (size_t)s->particle_count);
}

/* ------------------------------------------------------------------------ */
/* Response                                                                 */
/* ------------------------------------------------------------------------ */

/* Coulomb and wet friction of a pair (mu, q): the cloth's; between two
 * pieces the geometric mean of theirs, as a cloth meets a collider. */
static void pair_friction(const wc_cloth *c, const wc_self_state *s, const self_contact *k,
                          double out[2])
{
    out[0] = c->material.friction, out[1] = c->material.wet_friction;
    if (!s->particle_piece) return;
    int32_t a = s->particle_piece[k->p[0]], b = s->particle_piece[k->p[3]];
    if (a == b) {
        out[0] = s->piece_friction[a], out[1] = s->piece_wet_friction[a];
    } else {
        out[0] = sqrt(s->piece_friction[a] * s->piece_friction[b]);
        out[1] = sqrt(s->piece_wet_friction[a] * s->piece_wet_friction[b]);
    }
}

/* A particle moved by a response or the fail-safe: its pairs are evaluated
 * again, and the collider stage looks at it again (wci_self_state_moved). */
static void note_moved(wc_self_state *s, int32_t i)
{
    s->dirty[i] = 1;
    if (!s->moved[i]) s->moved[i] = 1, ++s->moved_count;
}

/* Answers one contact against the current state through the one response
 * (response.h): an inelastic impulse that removes the approach along n, a
 * position correction to the pair's target separation, Coulomb and wet
 * friction. The target: h is the pair's thickness (pair_thickness); for a
 * collision during the step min(start separation, h), so a pair never ends
 * closer than it started unless it stays h apart, but at least a tenth of
 * h (elements that start touching are parted a little, or the continuous
 * test would find them again); a proximity's target is h. Returns whether
 * any particle moved. */
static int respond(wc_cloth *c, wc_self_state *s, const self_contact *k, const double friction[2],
                   double slack, int32_t *marked)
{
    wc_contact ct;
    memset(&ct, 0, sizeof ct);
    ct.source = WC_SOURCE_CLOTH;
    ct.impact = k->kind == COLLISION;
    ct.count = 4;
    for (int j = 0; j < 4; ++j) ct.particle[j] = k->p[j], ct.weight[j] = k->w[j];
    for (int m = 0; m < 3; ++m) ct.normal[m] = k->n[m];
    double x1[3];
    relative(c->nx, c->ny, c->nz, k, x1);
    ct.distance = dot3(x1, k->n);
    double h = k->h;
    ct.target = k->kind == COLLISION ? (k->d0 > h ? h : k->d0 < 0.1 * h ? 0.1 * h : k->d0) : h;
    ct.friction = friction[0], ct.wet_friction = friction[1];
    wc_particle_arrays p = wci_particle_arrays_of(c);
    wc_response_options options = {slack};
    uint8_t moved[4];
    if (!wci_response_apply(&p, &ct, &options, marked, moved)) return 0;
    for (int j = 0; j < 4; ++j)
        if (moved[j]) note_moved(s, k->p[j]);
    return 1;
}

/* Serial pass over the flagged pairs in candidate order: each is evaluated
 * again against the current state (earlier responses of the pass may have
 * answered it already) and answered. Returns whether anything moved. */
static int respond_all(wc_cloth *c, wc_self_state *s, const self_ctx *ctx, int pass,
                       int32_t *marked)
{
    double friction[2], slack = pass ? RESIDUAL * ctx->h : 0.0;
    int moved = 0;
    for (int64_t i = 0; i < s->vf_count; ++i) {
        if (!s->vf_status[i]) continue;
        self_contact k;
        s->vf_status[i] = (uint8_t)vf_pair(s, ctx, i, 0, &k);
        if (!s->vf_status[i]) continue;
        pair_friction(c, s, &k, friction);
        moved |= respond(c, s, &k, friction, slack, marked);
    }
    for (int64_t i = 0; i < s->ee_count; ++i) {
        if (!s->ee_status[i]) continue;
        self_contact k;
        s->ee_status[i] = (uint8_t)ee_pair(s, ctx, i, 0, &k);
        if (!s->ee_status[i]) continue;
        pair_friction(c, s, &k, friction);
        moved |= respond(c, s, &k, friction, slack, marked);
    }
    return moved;
}

/* Whether the candidates still hold every pair that can touch after some
 * particles moved (those marked dirty): each inside its box, and every
 * culling decision that involves a patch holding one of them still true
 * for the new motion. */
static int still_valid(wc_self_state *s, const wc_cloth *c, int threads)
{
    s->cones_current = 0;
    for (int32_t i = 0; i < s->particle_count; ++i) {
        if (!s->dirty[i]) continue;
        const double *b = s->particle_boxes + 6 * (size_t)i;
        if (c->nx[i] < b[0] || c->nx[i] > b[3] || c->ny[i] < b[1] || c->ny[i] > b[4] ||
            c->nz[i] < b[2] || c->nz[i] > b[5])
            return 0;
    }
    const csr *pp = &s->patch_particles, *adj = &s->patch_adjacent;
    int any = 0;
    (void)threads;
    /* Each patch writes only its own triangles' normals and its own cone. */
#pragma omp parallel for schedule(static) num_threads(threads) if (s->triangle_count >= WC_PARALLEL_MIN) \
    reduction(| : any)
    for (int32_t p = 0; p < s->patch_count; ++p) {
        uint8_t touched = 0;
        for (int32_t k = pp->start[p]; k < pp->start[p + 1] && !touched; ++k) touched = s->dirty[pp->items[k]];
        s->patch_touched[p] = touched;
        if (!touched) continue;
        any = 1;
        for (int32_t k = s->patch_triangles.start[p]; k < s->patch_triangles.start[p + 1]; ++k) {
            int32_t t = s->patch_triangles.items[k];
            triangle_normal_motion(c, s->triangles + 3 * (size_t)t, s->triangle_normals + 9 * (size_t)t);
        }
        patch_cone(s, p);
    }
    /* Untouched patches' particles have not moved since their cones were
     * made, so now every cone is current. */
    s->cones_current = 1;
    if (!any) return 1;
    for (int32_t p = 0; p < s->patch_count; ++p) {
        if (!s->patch_touched[p]) continue;
        if (s->patch_culled[p] && !region_culls(s, c, &p, 1, s->contour)) return 0;
        for (int32_t k = adj->start[p]; k < adj->start[p + 1]; ++k) {
            /* both entries of a pair are flagged: check it from one side,
             * from the other when that one was not touched */
            int32_t q = adj->items[k], two[2] = {p < q ? p : q, p < q ? q : p};
            if (q < p && s->patch_touched[q]) continue;
            if (s->adjacent_culled[k] && !region_culls(s, c, two, 2, s->contour)) return 0;
        }
    }
    for (int64_t k = 0; k < s->joined_count; ++k) {
        /* stored as (P, Q, R), culled as the chain P, R, Q (joining_patch) */
        const int32_t *j = s->joined + 3 * k;
        int32_t three[3] = {j[0], j[2], j[1]};
        if ((s->patch_touched[j[0]] || s->patch_touched[j[1]] || s->patch_touched[j[2]]) &&
            !region_culls(s, c, three, 3, s->contour))
            return 0;
    }
    return 1;
}

/* A new broadphase for the current motion; every pair is to be evaluated. */
static wc_status rebuild_candidates(wc_self_state *s, const wc_cloth *c, const self_ctx *ctx,
                                    double g, int threads)
{
    s->built = 0;
    if (broadphase(s, c, ctx, g, threads)) return WC_ERROR_OUT_OF_MEMORY;
    s->built = 1, s->built_h = ctx->h;
    memset(s->dirty, 1, (size_t)s->particle_count);
    return WC_OK;
}

/* Puts a particle back where the step started, at rest. */
static void revert(wc_cloth *c, wc_self_state *s, int32_t i)
{
    c->nx[i] = c->x[i], c->ny[i] = c->y[i], c->nz[i] = c->z[i];
    c->qx[i] = c->x[i], c->qy[i] = c->y[i], c->qz[i] = c->z[i];
    c->history_override[i] = 1;
    s->reverted[i] = 1;
    note_moved(s, i);
}

/* Reverts every free particle of every pair whose motion still collides,
 * then detects again, until nothing collides or nothing is left to revert
 * (only pinned or already reverted particles in the colliding pairs: a pin
 * driven into the cloth). The set reverted is the union of the impact zones
 * (the connected groups of colliding pairs); since every member goes back,
 * the zones need not be formed explicitly. Reverting keeps particles inside
 * their boxes but changes the motion of their triangles, so the culling is
 * checked again each round. */
static wc_status failsafe(wc_cloth *c, wc_self_state *s, self_ctx *ctx, double g, int threads,
                          int32_t *count)
{
    int32_t total = 0;
    memset(s->reverted, 0, (size_t)s->particle_count);
    for (;;) {
        int32_t newly = 0;
        for (int64_t i = 0; i < s->vf_count; ++i) {
            if (s->vf_status[i] != COLLISION) continue;
            const int32_t *pr = s->vf + 2 * i, *tri = s->triangles + 3 * (size_t)pr[1];
            int32_t ids[4] = {pr[0], tri[0], tri[1], tri[2]};
            for (int j = 0; j < 4; ++j)
                if (!s->reverted[ids[j]] && c->pin_slot[ids[j]] < 0) revert(c, s, ids[j]), ++newly;
        }
        for (int64_t i = 0; i < s->ee_count; ++i) {
            if (s->ee_status[i] != COLLISION) continue;
            const int32_t *pr = s->ee + 2 * i;
            const int32_t *e = s->edges + 2 * (size_t)pr[0], *f = s->edges + 2 * (size_t)pr[1];
            int32_t ids[4] = {e[0], e[1], f[0], f[1]};
            for (int j = 0; j < 4; ++j)
                if (!s->reverted[ids[j]] && c->pin_slot[ids[j]] < 0) revert(c, s, ids[j]), ++newly;
        }
        if (!newly) break;
        total += newly;
        if (!still_valid(s, c, threads) && rebuild_candidates(s, c, ctx, g, threads))
            return WC_ERROR_OUT_OF_MEMORY;
        evaluate(s, ctx, 1, threads);
    }
    *count = total;
    return WC_OK;
}

/* Wet cloth: the vertex-face pairs that may adhere (wetness.c) are those
 * within (1 + WC_WET_HOLD_BAND) h at the end of the step whose vertex is in
 * contact: the contact marks of the responses reach every particle of an
 * answered pair, vertex or face corner, so which of two touching layers'
 * pairs the response happened to answer first does not matter. Rest
 * neighbours (thinner pairs) are the cloth itself, not a second layer. */
static void note_adhesive(wc_cloth *c, wc_self_state *s, const self_ctx *ctx)
{
    double reach = (1.0 + WC_WET_HOLD_BAND) * ctx->h, bary[3];
    for (int64_t i = 0; i < s->vf_count; ++i) {
        const int32_t *pr = s->vf + 2 * i, *tri = s->triangles + 3 * (size_t)pr[1];
        if (c->contact[pr[0]] == WC_CONTACT_NONE) continue;
        double p[4][3];
        load(c->nx, c->ny, c->nz, pr[0], p[0]);
        for (int j = 0; j < 3; ++j) load(c->nx, c->ny, c->nz, tri[j], p[1 + j]);
        if (!(wci_point_triangle_closest(p[0], p[1], p[2], p[3], bary) < reach * reach)) continue;
        int32_t ids[4] = {pr[0], tri[0], tri[1], tri[2]};
        if (s->vf_h[i] < 0.0) s->vf_h[i] = pair_thickness(ctx, rest2_vf(ctx, ids));
        if (s->vf_h[i] == ctx->h) wci_wet_note_self_contact(c, pr[0], pr[1]);
    }
}

double wci_self_thickness(const wc_cloth *c)
{
    return max2(c->material.thickness, MIN_THICKNESS * c->self->mean_edge);
}

static self_ctx context_of(const wc_cloth *c)
{
    const wc_self_state *s = c->self;
    self_ctx ctx;
    ctx.h = wci_self_thickness(c);
    ctx.tol = CCD_TOLERANCE * ctx.h;
    ctx.exclude2 = (REST_EXCLUSION * ctx.h) * (REST_EXCLUSION * ctx.h);
    ctx.rest = s->rest;
    ctx.piece = s->particle_piece;
    /* nx/ny/nz are the cloth's current arrays (they swap at commit). */
    ctx.x = c->x, ctx.y = c->y, ctx.z = c->z, ctx.nx = c->nx, ctx.ny = c->ny, ctx.nz = c->nz;
    return ctx;
}

wc_status wci_self_verify(wc_cloth *c, const uint8_t *moved, int threads, wc_step_stats *stats)
{
    wc_self_state *s = c->self;
    if (!s || s->triangle_count == 0) return WC_OK;
    if (threads < 1) threads = 1;
    self_ctx ctx = context_of(c);
    double g = BOX_MARGIN * ctx.h;
    memcpy(s->dirty, moved, (size_t)s->particle_count);
    if (!(s->built && s->built_h == ctx.h) || !still_valid(s, c, threads)) {
        if (rebuild_candidates(s, c, &ctx, g, threads)) return WC_ERROR_OUT_OF_MEMORY;
    } else {
        /* a pair that still collides from wci_self_collide and that nothing
         * moved since has had its free particles put back already: only the
         * moved particles' pairs are the fail-safe's now */
        if (s->vf_count) memset(s->vf_status, 0, (size_t)s->vf_count);
        if (s->ee_count) memset(s->ee_status, 0, (size_t)s->ee_count);
    }
    evaluate(s, &ctx, 1, threads);
    int32_t reverted = 0;
    if (failsafe(c, s, &ctx, g, threads, &reverted)) return WC_ERROR_OUT_OF_MEMORY;
    if (stats) stats->failsafe_particles += reverted;
    return WC_OK;
}

wc_status wci_self_collide(wc_cloth *c, double dt, int threads, wc_step_stats *stats)
{
    (void)dt; /* everything works in displacements over the step */
    wc_self_state *s = c->self;
    if (!s || s->triangle_count == 0) return WC_OK;
    if (threads < 1) threads = 1;
    self_ctx ctx = context_of(c);
    double g = BOX_MARGIN * ctx.h;
    int32_t marked = 0, reverted = 0;
    /* Candidates from an earlier step hold as long as every particle's
     * motion stays inside its box and the culled patches keep their cones
     * (still_valid with every particle marked): cloth at rest or moving
     * slowly skips the broadphase. */
    s->cones_current = 0; /* the cloth has moved since the last step */
    if (s->moved_count) memset(s->moved, 0, (size_t)s->particle_count);
    s->moved_count = 0;
    int rebuild = !(s->built && s->built_h == ctx.h);
    if (!rebuild) {
        memset(s->dirty, 1, (size_t)s->particle_count);
        rebuild = !still_valid(s, c, threads);
        if (!rebuild) {
            if (s->vf_count) memset(s->vf_status, 0, (size_t)s->vf_count);
            if (s->ee_count) memset(s->ee_status, 0, (size_t)s->ee_count);
        }
    }
    for (int pass = 0;; ++pass) {
        if (rebuild && rebuild_candidates(s, c, &ctx, g, threads)) return WC_ERROR_OUT_OF_MEMORY;
        int last = pass >= SELF_PASSES;
        evaluate(s, &ctx, last, threads);
        if (last || !respond_all(c, s, &ctx, pass, &marked)) break;
        rebuild = !still_valid(s, c, threads);
    }
    if (failsafe(c, s, &ctx, g, threads, &reverted)) return WC_ERROR_OUT_OF_MEMORY;
    if (c->wet_forces) note_adhesive(c, s, &ctx);
    if (stats) {
        stats->cloth_contacts += marked;
        stats->failsafe_particles += reverted;
    }
    return WC_OK;
}
