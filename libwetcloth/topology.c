#include "topology.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "alloc.h"
#include "status.h"

/* One link candidate before duplicates are merged. `order` makes the sort a
 * total order, so merged sums are added in the same order on every run. */
typedef struct link_entry {
    int32_t a, b;
    int32_t order;
    double share;
} link_entry;

static int compare_entries(const void *pa, const void *pb)
{
    const link_entry *p = pa, *q = pb;
    if (p->a != q->a) return p->a < q->a ? -1 : 1;
    if (p->b != q->b) return p->b < q->b ? -1 : 1;
    return (p->order > q->order) - (p->order < q->order);
}

static void vertex(const double *xyz, int32_t i, double out[3])
{
    out[0] = xyz[3 * (size_t)i];
    out[1] = xyz[3 * (size_t)i + 1];
    out[2] = xyz[3 * (size_t)i + 2];
}

static double distance(const double *xyz, int32_t i, int32_t j)
{
    double p[3], q[3];
    vertex(xyz, i, p);
    vertex(xyz, j, q);
    return sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) +
                (p[2] - q[2]) * (p[2] - q[2]));
}

/* Area of triangle (i, j, k) and the square of its longest edge. */
static double triangle_area(const double *xyz, int32_t i, int32_t j, int32_t k, double *longest2)
{
    double p[3], q[3], r[3], u[3], v[3], n[3];
    vertex(xyz, i, p);
    vertex(xyz, j, q);
    vertex(xyz, k, r);
    for (int c = 0; c < 3; ++c) {
        u[c] = q[c] - p[c];
        v[c] = r[c] - p[c];
    }
    n[0] = u[1] * v[2] - u[2] * v[1];
    n[1] = u[2] * v[0] - u[0] * v[2];
    n[2] = u[0] * v[1] - u[1] * v[0];
    double e0 = distance(xyz, i, j), e1 = distance(xyz, j, k), e2 = distance(xyz, k, i);
    double m = fmax(e0, fmax(e1, e2));
    *longest2 = m * m;
    return 0.5 * sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
}

/* Checks one face and returns its corner count (3 or 4) and area. */
static wc_status check_face(const double *xyz, int32_t n, const int32_t *face, int32_t face_size,
                            int32_t index, int32_t *corners, double *area, wc_message *msg)
{
    int32_t m = face_size;
    if (face_size == 4 && face[3] == -1) m = 3;
    for (int32_t c = 0; c < m; ++c) {
        if (face[c] < 0 || face[c] >= n)
            return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                           "cloth face %d uses vertex %d, but the cloth has %d vertices (valid: 0..%d%s)",
                           (int)index, (int)face[c], (int)n, (int)n - 1,
                           face_size == 4 && c == 3 ? ", or -1 to make a triangle" : "");
        for (int32_t d = 0; d < c; ++d)
            if (face[d] == face[c])
                return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                               "cloth face %d uses vertex %d twice", (int)index, (int)face[c]);
    }
    /* A face is degenerate when its area is negligible next to its size; for
     * a quad each of its two triangles must be sound, since both carry mass
     * and links. */
    double l0, l1 = 0.0;
    double a0 = triangle_area(xyz, face[0], face[1], face[2], &l0);
    double a1 = m == 4 ? triangle_area(xyz, face[0], face[2], face[3], &l1) : 0.0;
    if (!(a0 > 1e-12 * l0) || (m == 4 && !(a1 > 1e-12 * l1)))
        return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                       "cloth face %d is degenerate: its vertices are collinear or coincide "
                       "(area %g m^2)", (int)index, a0 + a1);
    *corners = m;
    *area = a0 + a1;
    return WC_OK;
}

static void link_set_free(wc_link_set *s)
{
    wci_free(s->a);
    wci_free(s->b);
    wci_free(s->rest);
    wci_free(s->share);
    memset(s, 0, sizeof *s);
}

static int link_set_alloc(wc_link_set *s, int32_t count)
{
    s->count = count;
    s->a = wci_alloc_array((size_t)count, sizeof *s->a);
    s->b = wci_alloc_array((size_t)count, sizeof *s->b);
    s->rest = wci_alloc_array((size_t)count, sizeof *s->rest);
    s->share = wci_alloc_array((size_t)count, sizeof *s->share);
    if (s->a && s->b && s->rest && s->share) return 1;
    link_set_free(s);
    return 0;
}

/* Sorts entries and merges duplicates (summing shares) into a link set. */
static wc_status merge_entries(link_entry *entries, size_t count, const double *xyz,
                               wc_link_set *out)
{
    qsort(entries, count, sizeof *entries, compare_entries);
    size_t unique = 0;
    for (size_t i = 0; i < count; ++i)
        if (i == 0 || entries[i].a != entries[i - 1].a || entries[i].b != entries[i - 1].b)
            entries[unique++] = entries[i];
        else
            entries[unique - 1].share += entries[i].share;
    if (!link_set_alloc(out, (int32_t)unique)) return WC_ERROR_OUT_OF_MEMORY;
    for (size_t i = 0; i < unique; ++i) {
        out->a[i] = entries[i].a;
        out->b[i] = entries[i].b;
        out->rest[i] = distance(xyz, entries[i].a, entries[i].b);
        out->share[i] = entries[i].share;
    }
    return WC_OK;
}

static void add_entry(link_entry *e, size_t *count, int32_t i, int32_t j, double share)
{
    link_entry *x = &e[*count];
    x->a = i < j ? i : j;
    x->b = i < j ? j : i;
    x->order = (int32_t)*count;
    x->share = share;
    ++*count;
}

/* Stretch links: every face's edges, plus both diagonals of each quad. Each
 * face shares its area, times its calibration factor, equally among its links
 * (see wc_material for why 8/3 and 12/5). */
static wc_status build_stretch(wc_topology *t, const double *xyz, const int32_t *faces,
                               int32_t face_count, int32_t face_size, const int32_t *corners,
                               const double *face_area)
{
    link_entry *e = wci_alloc_array((size_t)face_count * 6, sizeof *e);
    if (!e) return WC_ERROR_OUT_OF_MEMORY;
    size_t count = 0;
    for (int32_t f = 0; f < face_count; ++f) {
        const int32_t *v = faces + (size_t)f * face_size;
        if (corners[f] == 3) {
            double s = (8.0 / 3.0) * face_area[f] / 3.0;
            add_entry(e, &count, v[0], v[1], s);
            add_entry(e, &count, v[1], v[2], s);
            add_entry(e, &count, v[2], v[0], s);
        } else {
            double s = (12.0 / 5.0) * face_area[f] / 6.0;
            for (int c = 0; c < 4; ++c) add_entry(e, &count, v[c], v[(c + 1) % 4], s);
            add_entry(e, &count, v[0], v[2], s);
            add_entry(e, &count, v[1], v[3], s);
        }
    }
    wc_status s = merge_entries(e, count, xyz, &t->stretch);
    wci_free(e);
    return s;
}

/* Neighbours of each particle along stretch links, as CSR. */
static wc_status neighbours(const wc_link_set *links, int32_t n, int32_t **start_out,
                            int32_t **list_out)
{
    int32_t *start = wci_alloc_array((size_t)n + 1, sizeof *start);
    int32_t *list = wci_alloc_array((size_t)links->count * 2, sizeof *list);
    int32_t *fill = wci_alloc_array((size_t)n, sizeof *fill);
    if (!start || !list || !fill) {
        wci_free(start);
        wci_free(list);
        wci_free(fill);
        return WC_ERROR_OUT_OF_MEMORY;
    }
    for (int32_t e = 0; e < links->count; ++e) {
        start[links->a[e] + 1]++;
        start[links->b[e] + 1]++;
    }
    for (int32_t i = 0; i < n; ++i) start[i + 1] += start[i];
    for (int32_t e = 0; e < links->count; ++e) {
        int32_t a = links->a[e], b = links->b[e];
        list[start[a] + fill[a]++] = b;
        list[start[b] + fill[b]++] = a;
    }
    wci_free(fill);
    *start_out = start;
    *list_out = list;
    return WC_OK;
}

/* Cosine of the rest angle a-b-c. */
static double angle_cos(const double *xyz, int32_t a, int32_t b, int32_t c)
{
    double p[3], q[3], r[3], dot = 0.0, la = 0.0, lc = 0.0;
    vertex(xyz, a, p);
    vertex(xyz, b, q);
    vertex(xyz, c, r);
    for (int k = 0; k < 3; ++k) {
        dot += (p[k] - q[k]) * (r[k] - q[k]);
        la += (p[k] - q[k]) * (p[k] - q[k]);
        lc += (r[k] - q[k]) * (r[k] - q[k]);
    }
    return dot / sqrt(la * lc);
}

/* The neighbour of b (list[begin..end)) that continues the direction
 * a -> b most straightly, if the angle a-b-c is at least 150 degrees; else -1.
 * Ties go to the lower position in the list (deterministic). */
static int32_t straightest(const double *xyz, const int32_t *list, int32_t begin, int32_t end,
                           int32_t a, int32_t b)
{
    int32_t best = -1;
    double best_cos = WC_BEND_COS_LIMIT;
    for (int32_t j = begin; j < end; ++j) {
        if (list[j] == a) continue;
        double c = angle_cos(xyz, a, b, list[j]);
        if (c <= best_cos && (best < 0 || c < best_cos)) best = list[j], best_cos = c;
    }
    return best;
}

/* Bend links: (a, c) when (a, b) and (b, c) are stretch links,
 * the rest angle a-b-c is at least 150 degrees, and each is the other's
 * straightest continuation through b. On any regular grid, square cells or
 * not, this is exactly the thesis' "skip one" set. The angle alone is not
 * enough: on a grid of 3:1 cells a knight's-move pair passes 150 degrees
 * (161.6), and at the border, where the straight continuation is missing,
 * it would be the best one left; asking the choice to be mutual rejects it,
 * since from its other end the straight continuation exists. */
static wc_status build_bend(wc_topology *t, const double *xyz)
{
    int32_t n = t->particle_count, *start, *list;
    wc_status s = neighbours(&t->stretch, n, &start, &list);
    if (s) return s;
    link_entry *e = wci_alloc_array((size_t)start[n], sizeof *e);
    size_t count = 0;
    if (!e) s = WC_ERROR_OUT_OF_MEMORY;
    for (int32_t b = 0; b < n && !s; ++b)
        for (int32_t i = start[b]; i < start[b + 1]; ++i) {
            int32_t a = list[i], c = straightest(xyz, list, start[b], start[b + 1], a, b);
            if (c > a && straightest(xyz, list, start[b], start[b + 1], c, b) == a)
                add_entry(e, &count, a, c, 0.0);
        }
    if (!s) s = merge_entries(e, count, xyz, &t->bend);
    wci_free(e);
    wci_free(start);
    wci_free(list);
    if (s) return s;
    /* Each particle's area is shared equally among its bend links. */
    int32_t *degree = wci_alloc_array((size_t)n, sizeof *degree);
    if (!degree) return WC_ERROR_OUT_OF_MEMORY;
    for (int32_t k = 0; k < t->bend.count; ++k) {
        degree[t->bend.a[k]]++;
        degree[t->bend.b[k]]++;
    }
    for (int32_t k = 0; k < t->bend.count; ++k)
        t->bend.share[k] = t->area[t->bend.a[k]] / degree[t->bend.a[k]] +
                           t->area[t->bend.b[k]] / degree[t->bend.b[k]];
    wci_free(degree);
    return WC_OK;
}

static void build_triangles(wc_topology *t, const int32_t *faces, int32_t face_count,
                            int32_t face_size, const int32_t *corners)
{
    int32_t k = 0;
    for (int32_t f = 0; f < face_count; ++f) {
        const int32_t *v = faces + (size_t)f * face_size;
        int32_t *out = t->triangles + 3 * (size_t)k;
        out[0] = v[0], out[1] = v[1], out[2] = v[2];
        ++k;
        if (corners[f] == 4) {
            out += 3;
            out[0] = v[0], out[1] = v[2], out[2] = v[3];
            ++k;
        }
    }
}

wc_status wci_topology_create(wc_topology *t, const double *xyz, int32_t n, const int32_t *faces,
                            int32_t face_count, int32_t face_size, wc_message *msg)
{
    memset(t, 0, sizeof *t);
    t->particle_count = n;
    long bad = wci_first_non_finite(xyz, 3L * n);
    if (bad >= 0)
        return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                       "cloth vertex %ld has a non-finite coordinate (%c = %g)", bad / 3,
                       "xyz"[bad % 3], xyz[bad]);

    int32_t *corners = wci_alloc_array((size_t)face_count, sizeof *corners);
    double *face_area = wci_alloc_array((size_t)face_count, sizeof *face_area);
    t->area = wci_alloc_array((size_t)n, sizeof *t->area);
    wc_status s = (corners && face_area && t->area) ? WC_OK : WC_ERROR_OUT_OF_MEMORY;
    int32_t triangles = 0;
    for (int32_t f = 0; f < face_count && !s; ++f) {
        const int32_t *v = faces + (size_t)f * face_size;
        s = check_face(xyz, n, v, face_size, f, &corners[f], &face_area[f], msg);
        if (s) break;
        triangles += corners[f] - 2;
        for (int32_t c = 0; c < corners[f]; ++c) t->area[v[c]] += face_area[f] / corners[f];
    }
    for (int32_t i = 0; i < n && !s; ++i)
        if (t->area[i] == 0.0)
            s = wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                        "cloth vertex %d belongs to no face (every vertex needs a face to have mass)",
                        (int)i);
    if (!s) s = build_stretch(t, xyz, faces, face_count, face_size, corners, face_area);
    if (!s) s = build_bend(t, xyz);
    if (!s) {
        t->triangle_count = triangles;
        t->triangles = wci_alloc_array((size_t)triangles * 3, sizeof *t->triangles);
        if (t->triangles) build_triangles(t, faces, face_count, face_size, corners);
        else s = WC_ERROR_OUT_OF_MEMORY;
    }
    wci_free(corners);
    wci_free(face_area);
    if (s == WC_ERROR_OUT_OF_MEMORY)
        wci_fail(msg, s, "out of memory while building the topology of a cloth of %d vertices",
                (int)n);
    if (s) wci_topology_destroy(t);
    return s;
}

void wci_topology_destroy(wc_topology *t)
{
    wci_free(t->area);
    link_set_free(&t->stretch);
    link_set_free(&t->bend);
    wci_free(t->triangles);
    memset(t, 0, sizeof *t);
}
