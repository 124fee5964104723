/* Collider storage and the public entry points that add and move colliders.
 * Every entry point validates all of its input before changing anything. */
#include "collider.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "alloc.h"
#include "convex.h"
#include "primitives.h"
#include "status.h"
#include "world.h"

#define MAX_VERTICES (1 << 26)
#define MAX_TRIANGLES (1 << 27)

wc_mesh_collider_def wc_mesh_collider_def_default(void)
{
    wc_mesh_collider_def d;
    memset(&d, 0, sizeof d);
    d.friction = 0.5;
    return d;
}

wc_convex_collider_def wc_convex_collider_def_default(void)
{
    wc_convex_collider_def d;
    memset(&d, 0, sizeof d);
    d.shape = WC_SHAPE_SPHERE;
    d.rotation[0] = 1.0;
    d.radius = 0.5;
    d.half_height = 0.5;
    d.half_extents[0] = d.half_extents[1] = d.half_extents[2] = 0.5;
    d.friction = 0.5;
    return d;
}

void wci_collider_destroy(wc_collider *c)
{
    if (!c) return;
    wci_free(c->triangles);
    wci_free(c->edges);
    wci_free(c->current);
    wci_free(c->target);
    wci_free(c->next);
    wci_free(c->boxes);
    wci_free(c->edge_boxes);
    wci_free(c->vertex_boxes);
    wci_free(c->used_vertices);
    wci_free(c->vertex_smooth), wci_free(c->edge_smooth);
    wci_free(c->class_edges), wci_free(c->edge_order);
    wci_free(c->normals);
    wci_free(c->triangle_shift);
    wci_free(c->node_shift);
    wci_bvh_destroy(&c->bvh);
    wci_bvh_destroy(&c->edge_bvh);
    wci_bvh_destroy(&c->vertex_bvh);
    wci_bvh_destroy(&c->smooth_edge_bvh);
    wci_bvh_destroy(&c->smooth_vertex_bvh);
    wci_convex_shape_destroy(&c->convex);
    wci_free(c);
}

static int compare_pairs(const void *pa, const void *pb)
{
    const int32_t *p = pa, *q = pb;
    for (int k = 0; k < 2; ++k)
        if (p[k] != q[k]) return p[k] < q[k] ? -1 : 1;
    return 0;
}

/* The vertices the triangles use, ascending (marked in used_vertices'
 * own room first: it has one entry per vertex). */
static void used_vertices(wc_collider *c)
{
    int32_t *mark = c->used_vertices, n = 0;
    memset(mark, 0, (size_t)c->vertex_count * sizeof *mark);
    for (size_t j = 0; j < 3 * (size_t)c->triangle_count; ++j) mark[c->triangles[j]] = 1;
    for (int32_t v = 0; v < c->vertex_count; ++v)
        if (mark[v]) mark[n++] = v;
    c->used_vertex_count = n;
}

/* The unique edges of a mesh collider's triangles, sorted. Entries (a, b),
 * a < b, are sorted so equal edges become neighbours. */
static int build_edges(wc_collider *c)
{
    size_t n = 3 * (size_t)c->triangle_count;
    int32_t *entries = wci_alloc_array(2 * n, sizeof *entries);
    c->edges = wci_alloc_array(2 * n, sizeof *c->edges);
    if (!entries || !c->edges) {
        wci_free(entries);
        return 0;
    }
    for (size_t t = 0; t < (size_t)c->triangle_count; ++t)
        for (int k = 0; k < 3; ++k) {
            int32_t a = c->triangles[3 * t + k], b = c->triangles[3 * t + (k + 1) % 3];
            int32_t *e = entries + 2 * (3 * t + k);
            e[0] = a < b ? a : b, e[1] = a < b ? b : a;
        }
    qsort(entries, n, 2 * sizeof *entries, compare_pairs);
    int32_t unique = 0;
    for (size_t k = 0; k < n; ++k) {
        const int32_t *e = entries + 2 * k;
        if (e[0] == e[1]) continue; /* a degenerate triangle's collapsed edge */
        if (!unique || e[0] != c->edges[2 * unique - 2] || e[1] != c->edges[2 * unique - 1]) {
            c->edges[2 * unique] = e[0];
            c->edges[2 * unique + 1] = e[1];
            ++unique;
        }
    }
    c->edge_count = unique;
    wci_free(entries);
    return 1;
}

/* Edge (a, b), a < b, in the sorted unique edges: its index, -1 if none. */
static int32_t find_edge(const wc_collider *c, int32_t a, int32_t b)
{
    int32_t lo = 0, hi = c->edge_count - 1;
    while (lo <= hi) {
        int32_t mid = lo + (hi - lo) / 2;
        const int32_t *e = c->edges + 2 * (size_t)mid;
        if (e[0] == a && e[1] == b) return mid;
        if (e[0] < a || (e[0] == a && e[1] < b)) lo = mid + 1;
        else hi = mid - 1;
    }
    return -1;
}

/* Which vertices and edges are smooth (collider.h), from the positions in
 * `current`. An edge is smooth when exactly two faces meet there and their
 * normals differ by at most WC_SMOOTH_FEATURE_ANGLE; a vertex when its faces'
 * normals all lie within half of it of their mean and no sharp edge ends at
 * it. A rim (an edge of one face), a seam of three faces and anything
 * touching a degenerate triangle are sharp. `normals` (one per triangle)
 * and `mean` (xyz per vertex) are scratch. */
static void classify_features(wc_collider *c, double *normals, double *mean)
{
    double cos_edge = cos(WC_SMOOTH_FEATURE_ANGLE), cos_vertex = cos(0.5 * WC_SMOOTH_FEATURE_ANGLE);
    int32_t *first_face = c->class_edges; /* scratch until the order is made */
    for (int32_t e = 0; e < c->edge_count; ++e) c->edge_smooth[e] = 0, first_face[e] = -1;
    memset(mean, 0, 3 * (size_t)c->vertex_count * sizeof *mean);
    for (int32_t v = 0; v < c->vertex_count; ++v) c->vertex_smooth[v] = 1;
    for (int32_t t = 0; t < c->triangle_count; ++t) {
        const int32_t *v = c->triangles + 3 * (size_t)t;
        double *n = normals + 3 * (size_t)t;
        wci_triangle_normal(c->current + 3 * (size_t)v[0], c->current + 3 * (size_t)v[1],
                            c->current + 3 * (size_t)v[2], n);
        int degenerate = n[0] == 0.0 && n[1] == 0.0 && n[2] == 0.0;
        for (int k = 0; k < 3; ++k) {
            for (int m = 0; m < 3; ++m) mean[3 * (size_t)v[k] + m] += n[m];
            if (degenerate) c->vertex_smooth[v[k]] = 0;
            int32_t a = v[k], b = v[(k + 1) % 3];
            int32_t e = find_edge(c, a < b ? a : b, a < b ? b : a);
            if (e < 0) continue; /* a collapsed edge */
            /* edge_smooth counts the faces met so far (2 at most, 3 = a seam) */
            if (first_face[e] < 0) {
                first_face[e] = degenerate ? -2 : t;
                c->edge_smooth[e] = 1;
                continue;
            }
            const double *f = first_face[e] >= 0 ? normals + 3 * (size_t)first_face[e] : NULL;
            int turns = degenerate || !f || n[0] * f[0] + n[1] * f[1] + n[2] * f[2] < cos_edge;
            c->edge_smooth[e] = (uint8_t)(c->edge_smooth[e] == 1 && !turns ? 2 : 3);
        }
    }
    for (int32_t v = 0; v < c->vertex_count; ++v) {
        double *m = mean + 3 * (size_t)v, len = sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
        if (len > 0.0) m[0] /= len, m[1] /= len, m[2] /= len;
        else c->vertex_smooth[v] = 0;
    }
    for (int32_t t = 0; t < c->triangle_count; ++t) {
        const int32_t *v = c->triangles + 3 * (size_t)t;
        const double *n = normals + 3 * (size_t)t;
        for (int k = 0; k < 3; ++k) {
            const double *m = mean + 3 * (size_t)v[k];
            if (n[0] * m[0] + n[1] * m[1] + n[2] * m[2] < cos_vertex) c->vertex_smooth[v[k]] = 0;
        }
    }
    for (int32_t e = 0; e < c->edge_count; ++e) {
        c->edge_smooth[e] = c->edge_smooth[e] == 2;
        if (!c->edge_smooth[e])
            c->vertex_smooth[c->edges[2 * (size_t)e]] = c->vertex_smooth[c->edges[2 * (size_t)e + 1]] = 0;
    }
}

/* The used vertices and the edges in class order (collider.h): sharp, then
 * smooth, each ascending. */
static void order_by_class(wc_collider *c)
{
    int32_t *used = c->used_vertices, n = 0;
    int32_t *scratch = c->edge_order; /* free until the edges are ordered */
    for (int pass = 0; pass < 2; ++pass) {
        if (pass == 1) c->smooth_vertices_from = n;
        for (int32_t k = 0; k < c->used_vertex_count; ++k)
            if (c->vertex_smooth[used[k]] == pass) scratch[n++] = used[k];
    }
    memcpy(used, scratch, (size_t)n * sizeof *used);
    n = 0;
    for (int pass = 0; pass < 2; ++pass) {
        if (pass == 1) c->smooth_edges_from = n;
        for (int32_t e = 0; e < c->edge_count; ++e)
            if (c->edge_smooth[e] == pass) c->edge_order[n++] = e;
    }
    for (int32_t k = 0; k < c->edge_count; ++k) {
        c->class_edges[2 * (size_t)k] = c->edges[2 * (size_t)c->edge_order[k]];
        c->class_edges[2 * (size_t)k + 1] = c->edges[2 * (size_t)c->edge_order[k] + 1];
    }
}

static wc_status append_collider(wc_world *w, wc_collider *c, int32_t *out)
{
    if (w->collider_count == w->collider_capacity) {
        int32_t capacity = w->collider_capacity ? 2 * w->collider_capacity : 4;
        wc_collider **grown = wci_alloc_array((size_t)capacity, sizeof *grown);
        if (!grown) {
            wci_collider_destroy(c);
            return wci_fail(&w->error, WC_ERROR_OUT_OF_MEMORY, "out of memory adding a collider");
        }
        if (w->collider_count)
            memcpy(grown, w->colliders, (size_t)w->collider_count * sizeof *grown);
        wci_free(w->colliders);
        w->colliders = grown;
        w->collider_capacity = capacity;
    }
    w->colliders[w->collider_count] = c;
    *out = w->collider_count++;
    return WC_OK;
}

static wc_status check_surface(wc_message *msg, const char *def, double thickness, double friction)
{
    if (!(isfinite(thickness) && thickness >= 0.0 && thickness <= 1.0))
        return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT, "%s.thickness must be in [0, 1] m but is %g",
                       def, thickness);
    if (!(isfinite(friction) && friction >= 0.0 && friction <= 10.0))
        return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT, "%s.friction must be in [0, 10] but is %g",
                       def, friction);
    return WC_OK;
}

static wc_status validate_mesh(const wc_mesh_collider_def *d, wc_message *msg)
{
    if (d->vertex_count < 3 || d->vertex_count > MAX_VERTICES)
        return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                       "mesh_collider_def.vertex_count must be in [3, %d] but is %d", MAX_VERTICES,
                       (int)d->vertex_count);
    if (d->triangle_count < 1 || d->triangle_count > MAX_TRIANGLES)
        return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                       "mesh_collider_def.triangle_count must be in [1, %d] but is %d",
                       MAX_TRIANGLES, (int)d->triangle_count);
    if (!d->vertices || !d->triangles)
        return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT, "mesh_collider_def.%s is NULL",
                       d->vertices ? "triangles" : "vertices");
    long bad = wci_first_non_finite(d->vertices, 3L * d->vertex_count);
    if (bad >= 0)
        return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                       "mesh_collider_def.vertices: vertex %ld has a non-finite %c (%g)", bad / 3,
                       "xyz"[bad % 3], d->vertices[bad]);
    for (int64_t k = 0; k < 3 * (int64_t)d->triangle_count; ++k)
        if (d->triangles[k] < 0 || d->triangles[k] >= d->vertex_count)
            return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                           "collider triangle %lld uses vertex %d, but the collider has %d vertices",
                           (long long)(k / 3), (int)d->triangles[k], (int)d->vertex_count);
    return check_surface(msg, "mesh_collider_def", d->thickness, d->friction);
}

wc_status wc_world_add_mesh_collider(wc_world *w, const wc_mesh_collider_def *d, int32_t *out)
{
    if (!w) return WC_ERROR_INVALID_ARGUMENT;
    if (!d || !out)
        return wci_fail(&w->error, WC_ERROR_INVALID_ARGUMENT, "wc_world_add_mesh_collider: %s is NULL",
                       d ? "out_collider" : "def");
    wc_status s = validate_mesh(d, &w->error);
    if (s) return s;
    wc_collider *c = wci_alloc_array(1, sizeof *c);
    size_t nv = 3 * (size_t)d->vertex_count, nt = (size_t)d->triangle_count;
    if (c) {
        c->is_mesh = 1;
        c->thickness = d->thickness;
        c->friction = d->friction;
        c->vertex_count = d->vertex_count;
        c->triangle_count = d->triangle_count;
        memset(&c->bvh, 0, sizeof c->bvh);
        memset(&c->edge_bvh, 0, sizeof c->edge_bvh);
        memset(&c->vertex_bvh, 0, sizeof c->vertex_bvh);
        memset(&c->smooth_edge_bvh, 0, sizeof c->smooth_edge_bvh);
        memset(&c->smooth_vertex_bvh, 0, sizeof c->smooth_vertex_bvh);
        c->triangles = wci_alloc_array(3 * nt, sizeof *c->triangles);
        c->current = wci_alloc_array(nv, sizeof *c->current);
        c->target = wci_alloc_array(nv, sizeof *c->target);
        c->next = wci_alloc_array(nv, sizeof *c->next);
        c->boxes = wci_alloc_array(6 * nt, sizeof *c->boxes);
        c->vertex_boxes = wci_alloc_array(2 * nv, sizeof *c->vertex_boxes);
        c->used_vertices = wci_alloc_array(nv / 3, sizeof *c->used_vertices);
        c->normals = wci_alloc_array(3 * nt, sizeof *c->normals);
    }
    if (!c || !c->triangles || !c->current || !c->target || !c->next || !c->boxes ||
        !c->vertex_boxes || !c->used_vertices || !c->normals) {
        wci_collider_destroy(c);
        return wci_fail(&w->error, WC_ERROR_OUT_OF_MEMORY, "out of memory adding a mesh collider");
    }
    memcpy(c->triangles, d->triangles, 3 * nt * sizeof *c->triangles);
    used_vertices(c);
    if (!build_edges(c) ||
        !(c->edge_boxes = wci_alloc_array(6 * (size_t)(c->edge_count ? c->edge_count : 1),
                                           sizeof *c->edge_boxes))) {
        wci_collider_destroy(c);
        return wci_fail(&w->error, WC_ERROR_OUT_OF_MEMORY, "out of memory adding a mesh collider");
    }
    memcpy(c->current, d->vertices, nv * sizeof *c->current);
    memcpy(c->target, d->vertices, nv * sizeof *c->target);
    memcpy(c->next, d->vertices, nv * sizeof *c->next);
    size_t ne = (size_t)(c->edge_count ? c->edge_count : 1);
    c->vertex_smooth = wci_alloc_array(nv / 3 ? nv / 3 : 1, 1);
    c->edge_smooth = wci_alloc_array(ne, 1);
    /* edge_order must hold the used vertices too (order_by_class's scratch) */
    c->edge_order = wci_alloc_array(ne > nv / 3 ? ne : nv / 3 ? nv / 3 : 1, sizeof *c->edge_order);
    c->class_edges = wci_alloc_array(2 * ne, sizeof *c->class_edges);
    double *mean = wci_alloc_array(nv ? nv : 1, sizeof *mean);
    if (!c->vertex_smooth || !c->edge_smooth || !c->edge_order || !c->class_edges || !mean) {
        wci_free(mean);
        wci_collider_destroy(c);
        return wci_fail(&w->error, WC_ERROR_OUT_OF_MEMORY, "out of memory adding a mesh collider");
    }
    /* the normals are made again at the first step */
    classify_features(c, c->normals, mean);
    wci_free(mean);
    order_by_class(c);
    return append_collider(w, c, out);
}

wc_status wc_world_add_convex_collider(wc_world *w, const wc_convex_collider_def *d, int32_t *out)
{
    if (!w) return WC_ERROR_INVALID_ARGUMENT;
    if (!d || !out)
        return wci_fail(&w->error, WC_ERROR_INVALID_ARGUMENT,
                       "wc_world_add_convex_collider: %s is NULL", d ? "out_collider" : "def");
    wc_collider *c = wci_alloc_array(1, sizeof *c);
    if (!c) return wci_fail(&w->error, WC_ERROR_OUT_OF_MEMORY, "out of memory adding a collider");
    memset(&c->bvh, 0, sizeof c->bvh);
    memset(&c->edge_bvh, 0, sizeof c->edge_bvh);
    memset(&c->vertex_bvh, 0, sizeof c->vertex_bvh);
    memset(&c->smooth_edge_bvh, 0, sizeof c->smooth_edge_bvh);
    memset(&c->smooth_vertex_bvh, 0, sizeof c->smooth_vertex_bvh);
    wc_status s = wci_convex_shape_create(&c->convex, &c->pose_current, d, &w->error);
    if (s) {
        wci_collider_destroy(c);
        return s;
    }
    c->thickness = d->thickness;
    c->friction = d->friction;
    c->pose_target = c->pose_next = c->pose_current;
    return append_collider(w, c, out);
}

static wc_collider *find_collider(wc_world *w, int32_t collider, const char *caller)
{
    if (collider >= 0 && collider < w->collider_count) return w->colliders[collider];
    wci_fail(&w->error, WC_ERROR_NOT_FOUND, "%s: collider %d does not exist (the world has %d)",
            caller, (int)collider, (int)w->collider_count);
    return NULL;
}

wc_status wc_collider_set_vertices(wc_world *w, int32_t collider, const double *xyz, int32_t count)
{
    if (!w) return WC_ERROR_INVALID_ARGUMENT;
    wc_collider *c = find_collider(w, collider, "wc_collider_set_vertices");
    if (!c) return WC_ERROR_NOT_FOUND;
    if (!c->is_mesh)
        return wci_fail(&w->error, WC_ERROR_INVALID_ARGUMENT,
                       "wc_collider_set_vertices: collider %d is convex; use wc_collider_set_transform",
                       (int)collider);
    if (!xyz || count != c->vertex_count)
        return wci_fail(&w->error, WC_ERROR_INVALID_ARGUMENT,
                       "wc_collider_set_vertices: %s for collider %d (it has %d vertices, count is %d)",
                       xyz ? "count mismatch" : "xyz is NULL", (int)collider, (int)c->vertex_count,
                       (int)count);
    long bad = wci_first_non_finite(xyz, 3L * count);
    if (bad >= 0)
        return wci_fail(&w->error, WC_ERROR_INVALID_ARGUMENT,
                       "wc_collider_set_vertices: vertex %ld has a non-finite %c (%g)", bad / 3,
                       "xyz"[bad % 3], xyz[bad]);
    memcpy(c->target, xyz, 3 * (size_t)count * sizeof *xyz);
    c->moving = memcmp(c->target, c->current, 3 * (size_t)count * sizeof *xyz) != 0;
    /* the boxes must cover the new advance's motion */
    c->indexed = 0;
    c->normals_current = 0;
    return WC_OK;
}

wc_status wc_collider_set_transform(wc_world *w, int32_t collider, const double position[3],
                                    const double rotation[4])
{
    if (!w) return WC_ERROR_INVALID_ARGUMENT;
    wc_collider *c = find_collider(w, collider, "wc_collider_set_transform");
    if (!c) return WC_ERROR_NOT_FOUND;
    if (c->is_mesh)
        return wci_fail(&w->error, WC_ERROR_INVALID_ARGUMENT,
                       "wc_collider_set_transform: collider %d is a mesh; use wc_collider_set_vertices",
                       (int)collider);
    if (!position || !rotation)
        return wci_fail(&w->error, WC_ERROR_INVALID_ARGUMENT, "wc_collider_set_transform: %s is NULL",
                       position ? "rotation" : "position");
    double norm = 0.0;
    for (int k = 0; k < 4; ++k) norm += rotation[k] * rotation[k];
    norm = sqrt(norm);
    for (int k = 0; k < 3; ++k)
        if (!isfinite(position[k]))
            return wci_fail(&w->error, WC_ERROR_INVALID_ARGUMENT,
                           "wc_collider_set_transform: position[%d] must be finite but is %g", k,
                           position[k]);
    if (!(isfinite(norm) && norm > 1e-12))
        return wci_fail(&w->error, WC_ERROR_INVALID_ARGUMENT,
                       "wc_collider_set_transform: rotation must be a finite non-zero quaternion "
                       "(w, x, y, z) but has norm %g", norm);
    for (int k = 0; k < 3; ++k) c->pose_target.position[k] = position[k];
    for (int k = 0; k < 4; ++k) c->pose_target.rotation[k] = rotation[k] / norm;
    c->moving = memcmp(&c->pose_target, &c->pose_current, sizeof c->pose_target) != 0;
    return WC_OK;
}

int32_t wc_world_collider_count(const wc_world *w) { return w ? w->collider_count : 0; }

/* ------------------------------------------------------------------------ */
/* Colliders over a step                                                    */
/* ------------------------------------------------------------------------ */

static void grow_box(double box[6], const double *p)
{
    for (int k = 0; k < 3; ++k) {
        if (p[k] < box[k]) box[k] = p[k];
        if (p[k] > box[k + 3]) box[k + 3] = p[k];
    }
}

/* Boxes over the running advance of `count` items of `per` vertices each
 * (their corners now and at the target). */
static void advance_boxes(const wc_collider *c, const int32_t *items, int per, int32_t count,
                          double *boxes)
{
    for (int32_t t = 0; t < count; ++t) {
        double *box = boxes + 6 * (size_t)t;
        for (int k = 0; k < 3; ++k) box[k] = INFINITY, box[k + 3] = -INFINITY;
        for (int k = 0; k < per; ++k) {
            size_t v = 3 * (size_t)items[(size_t)per * (size_t)t + k];
            grow_box(box, c->current + v);
            grow_box(box, c->target + v);
        }
    }
}

/* A tree over `count` boxes: built the first time, refit after. */
static wc_status index_boxes(wc_bvh *bvh, const double *boxes, int32_t count)
{
    if (bvh->node_count == 0) return wci_bvh_create(bvh, boxes, count);
    wci_bvh_refit(bvh);
    return WC_OK;
}

/* Every triangle's, edge's and vertex's box over the running advance, and
 * the trees over them: built the first time, refit after, so a deforming
 * collider pays one pass over its triangles per advance. */
static wc_status index_mesh(wc_collider *c)
{
    advance_boxes(c, c->triangles, 3, c->triangle_count, c->boxes);
    advance_boxes(c, c->class_edges, 2, c->edge_count, c->edge_boxes);
    advance_boxes(c, c->used_vertices, 1, c->used_vertex_count, c->vertex_boxes);
    int first = c->bvh.node_count == 0;
    if (index_boxes(&c->bvh, c->boxes, c->triangle_count)) return WC_ERROR_OUT_OF_MEMORY;
    if (first) {
        double total = 0.0;
        for (int32_t e = 0; e < c->edge_count; ++e) {
            const double *a = c->current + 3 * (size_t)c->edges[2 * (size_t)e];
            const double *b = c->current + 3 * (size_t)c->edges[2 * (size_t)e + 1];
            double d[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
            total += sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        }
        c->feature_size = c->edge_count ? total / c->edge_count : 0.0;
    }
    /* (a tree that could not be made is made at the next call) */
    int32_t ns = c->smooth_edges_from, vs = c->smooth_vertices_from;
    if (index_boxes(&c->edge_bvh, c->edge_boxes, ns) ||
        index_boxes(&c->smooth_edge_bvh, c->edge_boxes + 6 * (size_t)ns, c->edge_count - ns) ||
        index_boxes(&c->vertex_bvh, c->vertex_boxes, vs) ||
        index_boxes(&c->smooth_vertex_bvh, c->vertex_boxes + 6 * (size_t)vs, c->used_vertex_count - vs))
        return WC_ERROR_OUT_OF_MEMORY;
    memcpy(c->bounds, c->bvh.nodes[0].box, sizeof c->bounds);
    c->indexed = 1;
    return WC_OK;
}

static void static_normals(wc_collider *c)
{
    for (int32_t t = 0; t < c->triangle_count; ++t) {
        const int32_t *v = c->triangles + 3 * (size_t)t;
        wci_triangle_normal(c->current + 3 * (size_t)v[0], c->current + 3 * (size_t)v[1],
                           c->current + 3 * (size_t)v[2], c->normals + 3 * (size_t)t);
    }
    c->normals_current = 1;
}

/* This step's displacements: the box of its corners' per triangle and the
 * union of those per node of the tree (the tree's boxes span the advance,
 * so they hold the step's), and the largest displacement of any vertex:
 * the step motion. */
static wc_status step_motions(wc_collider *c)
{
    if (!c->triangle_shift) c->triangle_shift = wci_alloc_array(6 * ((size_t)c->triangle_count + 1), sizeof(double));
    if (!c->node_shift) c->node_shift = wci_alloc_array(6 * (2 * (size_t)c->triangle_count + 1), sizeof(double));
    if (!c->triangle_shift || !c->node_shift) return WC_ERROR_OUT_OF_MEMORY;
    double most2 = 0.0;
    for (int32_t v = 0; v < c->vertex_count; ++v) {
        const double *a = c->current + 3 * (size_t)v, *b = c->next + 3 * (size_t)v;
        double d[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        double d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        if (d2 > most2) most2 = d2;
    }
    for (int32_t t = 0; t < c->triangle_count; ++t) {
        const int32_t *v = c->triangles + 3 * (size_t)t;
        double *box = c->triangle_shift + 6 * (size_t)t;
        for (int k = 0; k < 3; ++k) box[k] = INFINITY, box[k + 3] = -INFINITY;
        for (int j = 0; j < 3; ++j)
            for (int k = 0; k < 3; ++k) {
                double d = c->next[3 * (size_t)v[j] + k] - c->current[3 * (size_t)v[j] + k];
                if (d < box[k]) box[k] = d;
                if (d > box[k + 3]) box[k + 3] = d;
            }
    }
    wci_bvh_fold_boxes(&c->bvh, c->triangle_shift, c->node_shift);
    c->step_motion = sqrt(most2);
    return WC_OK;
}

static wc_status mesh_begin_step(wc_collider *c, double share)
{
    size_t nv = 3 * (size_t)c->vertex_count;
    c->step_motion = 0.0;
    if (c->moving) {
        if (share >= 1.0) memcpy(c->next, c->target, nv * sizeof *c->next); /* exactly there */
        else
            for (size_t k = 0; k < nv; ++k) c->next[k] = wc_lerp(c->current[k], c->target[k], share);
    }
    if (!c->indexed && index_mesh(c)) return WC_ERROR_OUT_OF_MEMORY;
    if (c->moving && step_motions(c)) return WC_ERROR_OUT_OF_MEMORY;
    if (!c->moving && !c->normals_current) static_normals(c);
    return WC_OK;
}

static void convex_begin_step(wc_collider *c, double share)
{
    if (c->moving && share >= 1.0) c->pose_next = c->pose_target;
    else if (c->moving) wci_pose_lerp(&c->pose_current, &c->pose_target, share, &c->pose_next);
    else c->pose_next = c->pose_current;
    const double *p0 = c->pose_current.position, *p1 = c->pose_next.position;
    double r = c->convex.bound_radius;
    for (int k = 0; k < 3; ++k) {
        c->bounds[k] = fmin(p0[k], p1[k]) - r;
        c->bounds[k + 3] = fmax(p0[k], p1[k]) + r;
    }
}

wc_status wci_collider_begin_step(wc_collider *c, double share)
{
    if (c->is_mesh) return mesh_begin_step(c, share);
    convex_begin_step(c, share);
    return WC_OK;
}

void wci_collider_end_step(wc_collider *c)
{
    if (!c->moving) return;
    if (c->is_mesh) {
        size_t bytes = 3 * (size_t)c->vertex_count * sizeof *c->current;
        memcpy(c->current, c->next, bytes);
        c->path += c->step_motion;
        c->step_motion = 0.0;
        c->moving = memcmp(c->current, c->target, bytes) != 0;
        /* at rest now: tight boxes again, and normals for good */
        if (!c->moving) c->indexed = 0, c->normals_current = 0, ++c->shape;
    } else {
        c->pose_current = c->pose_next;
        c->moving = memcmp(&c->pose_current, &c->pose_target, sizeof c->pose_current) != 0;
    }
}
