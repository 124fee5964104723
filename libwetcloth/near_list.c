#include "near_list.h"

#include <math.h>
#include <string.h>

#include "alloc.h"
#include "grid.h"

/* The margin is a tenth of the collider grid's cell: a query box then
 * grows by a fifth of a cell, which adds few candidates, while a particle
 * moving 1 m/s at a typical 1e-4 s step keeps its lists for over a hundred
 * steps (the thesis sphere's cells are 0.15 m). A quarter of a cell ran no
 * faster on the thesis scene. */
#define MARGIN_CELLS 0.1

void wc_near_list_init(wc_near_list *l) { memset(l, 0, sizeof *l); }

static void elements_free(wc_near_elements *e)
{
    wc_free(e->element);
    wc_free(e->start);
    wc_free(e->found);
    wc_free(e->slot_of);
    wc_free(e->path_at);
    wc_free(e->clearance);
    wc_free(e->least_clearance);
    memset(e, 0, sizeof *e);
}

void wc_near_list_free(wc_near_list *l)
{
    wc_free(l->particle_boxes);
    wc_free(l->particle_slot);
    elements_free(&l->triangles);
    elements_free(&l->edges);
    elements_free(&l->particles);
    wc_near_list_init(l);
}

static int inside(const double box[6], double x, double y, double z)
{
    return x >= box[0] && x <= box[3] && y >= box[1] && y <= box[4] && z >= box[2] && z <= box[5];
}

/* Made for this collider, which has not changed since. */
static int made_for(const wc_near_list *l, const wc_collider *col)
{
    return l->built && l->collider == col && l->grid_version == col->grid_version && col->grid_static;
}

int wc_near_list_holds(const wc_near_list *l, const wc_cloth *c, const wc_collider *col,
                       double r_triangles, double r_edges, double r_particles, const int32_t *only,
                       int32_t only_count)
{
    if (!made_for(l, col) || l->r_triangles != r_triangles || l->r_edges != r_edges ||
        l->r_particles != r_particles || l->particle_count != c->particle_count)
        return 0;
    int32_t count = only ? only_count : c->particle_count;
    for (int32_t k = 0; k < count; ++k) {
        int32_t i = only ? only[k] : k;
        const double *box = l->particle_boxes + 6 * (size_t)i;
        if (!inside(box, c->x[i], c->y[i], c->z[i]) || !inside(box, c->nx[i], c->ny[i], c->nz[i]))
            return 0;
    }
    return 1;
}

int wc_near_list_particle(const wc_near_list *l, const wc_collider *col, double r_particles,
                          int32_t i, double sx, double sy, double sz, double ex, double ey,
                          double ez, const int32_t **found, int32_t *count)
{
    if (!made_for(l, col) || l->r_particles != r_particles || i >= l->particle_count) return 0;
    const double *box = l->particle_boxes + 6 * (size_t)i;
    if (!inside(box, sx, sy, sz) || !inside(box, ex, ey, ez)) return 0;
    int32_t k = l->particle_slot[i];
    if (k < 0) {
        *found = NULL, *count = 0;
    } else {
        *found = l->particles.found + l->particles.start[k];
        *count = l->particles.start[k + 1] - l->particles.start[k];
    }
    return 1;
}

/* Grows an int32 array to hold `need` items; 0 on out-of-memory. */
static int reserve(int32_t **array, int64_t *capacity, int64_t need)
{
    if (need <= *capacity) return 1;
    int64_t grown = *capacity ? *capacity : 64;
    while (grown < need) grown *= 2;
    int32_t *bigger = wc_alloc_array((size_t)grown, sizeof *bigger);
    if (!bigger) return 0;
    if (*capacity) memcpy(bigger, *array, (size_t)*capacity * sizeof *bigger);
    wc_free(*array);
    *array = bigger, *capacity = grown;
    return 1;
}

/* Grows a double array to hold `need` items, contents not kept; 0 on
 * out-of-memory. */
static int reserve_doubles(double **array, int64_t *capacity, int64_t need)
{
    if (need <= *capacity) return 1;
    int64_t grown = *capacity ? *capacity : 64;
    while (grown < need) grown *= 2;
    double *bigger = wc_alloc_array((size_t)grown, sizeof *bigger);
    if (!bigger) return 0;
    wc_free(*array);
    *array = bigger, *capacity = grown;
    return 1;
}

/* Room for the clearances of a freshly listed set, all unknown: the feature
 * pass measures each element at its first visit. */
static wc_status unknown_clearances(wc_near_elements *out, int per)
{
    int64_t found = out->start[out->count];
    if (!reserve_doubles(&out->path_at, &out->path_at_capacity, (int64_t)per * out->count + 1) ||
        !reserve_doubles(&out->clearance, &out->clearance_capacity, found + 1) ||
        !reserve_doubles(&out->least_clearance, &out->least_capacity, (int64_t)out->count + 1))
        return WC_ERROR_OUT_OF_MEMORY;
    memset(out->path_at, 0, (size_t)((int64_t)per * out->count) * sizeof *out->path_at);
    for (int64_t k = 0; k < found; ++k) out->clearance[k] = -1.0;
    for (int32_t k = 0; k < out->count; ++k) out->least_clearance[k] = -1.0;
    return WC_OK;
}

/* Query box of an element: its particles' boxes, grown by r. */
static void element_box(const wc_near_list *l, const int32_t *particles, int count, double r,
                        double box[6])
{
    for (int k = 0; k < 3; ++k) box[k] = INFINITY, box[k + 3] = -INFINITY;
    for (int p = 0; p < count; ++p) {
        const double *b = l->particle_boxes + 6 * (size_t)particles[p];
        for (int k = 0; k < 3; ++k) {
            if (b[k] - r < box[k]) box[k] = b[k] - r;
            if (b[k + 3] + r > box[k + 3]) box[k + 3] = b[k + 3] + r;
        }
    }
}

/* Lists the elements (`per` particles each, `count` of them) whose boxes
 * meet something in the grid, with what they meet. */
static wc_status list_elements(wc_near_list *l, wc_near_elements *out, const int32_t *particles,
                               int per, int32_t count, const wc_grid *grid,
                               const double bounds[6], double r)
{
    out->count = 0;
    if (!reserve(&out->start, &out->start_capacity, 1) ||
        !reserve(&out->slot_of, &out->slot_capacity, count))
        return WC_ERROR_OUT_OF_MEMORY;
    out->start[0] = 0;
    for (int32_t e = 0; e < count; ++e) out->slot_of[e] = -1;
    int64_t used = 0;
    for (int32_t e = 0; e < count; ++e) {
        double box[6];
        element_box(l, particles + (size_t)per * (size_t)e, per, r, box);
        if (!wc_boxes_overlap(box, bounds)) continue;
        int32_t room = (int32_t)(out->found_capacity - used);
        /* no buffer yet (NULL): query the count only; NULL + 0 is undefined */
        int32_t n = wc_grid_query(grid, box, out->found ? out->found + used : NULL, room);
        if (n == 0) continue;
        if (n > room) {
            if (!reserve(&out->found, &out->found_capacity, used + n)) return WC_ERROR_OUT_OF_MEMORY;
            wc_grid_query(grid, box, out->found + used, n);
        }
        if (!reserve(&out->element, &out->element_capacity, out->count + 1) ||
            !reserve(&out->start, &out->start_capacity, out->count + 2))
            return WC_ERROR_OUT_OF_MEMORY;
        used += n;
        out->slot_of[e] = out->count;
        out->element[out->count] = e;
        out->start[++out->count] = (int32_t)used;
    }
    return WC_OK;
}

wc_status wc_near_list_build(wc_near_list *l, const wc_cloth *c, const int32_t *edges,
                             int32_t edge_count, const wc_collider *col, double r_triangles,
                             double r_edges, double r_particles)
{
    l->built = 0;
    int32_t n = c->particle_count;
    if (l->particle_count != n) {
        wc_free(l->particle_boxes);
        wc_free(l->particle_slot);
        l->particle_boxes = wc_alloc_array(6 * (size_t)n, sizeof *l->particle_boxes);
        l->particle_slot = wc_alloc_array((size_t)n, sizeof *l->particle_slot);
        l->particle_count = l->particle_boxes && l->particle_slot ? n : 0;
        if (!l->particle_count) return WC_ERROR_OUT_OF_MEMORY;
    }
    /* Each box reaches from the start of the step to as far again past its
     * end (where the next step takes the particle if its velocity holds),
     * grown by the margin: round this step's motion alone, a particle
     * moving more than the margin per step (the drape's falling cloth at 20
     * XPBD substeps per frame) left it at the next step, and every listed
     * element's clearances, unknown after a build, were measured again. */
    double margin = MARGIN_CELLS * col->vertex_grid.cell_size;
    for (int32_t i = 0; i < c->particle_count; ++i) {
        double *box = l->particle_boxes + 6 * (size_t)i;
        double start[3] = {c->x[i], c->y[i], c->z[i]}, end[3] = {c->nx[i], c->ny[i], c->nz[i]};
        for (int k = 0; k < 3; ++k) {
            double ahead = end[k] + (end[k] - start[k]);
            box[k] = (start[k] < ahead ? start[k] : ahead) - margin;
            box[k + 3] = (start[k] > ahead ? start[k] : ahead) + margin;
        }
    }
    wc_status s = list_elements(l, &l->triangles, c->topology.triangles, 3,
                                c->topology.triangle_count, &col->vertex_grid, col->bounds, r_triangles);
    if (!s) s = unknown_clearances(&l->triangles, 3);
    if (!s) s = list_elements(l, &l->edges, edges, 2, edge_count, &col->edge_grid, col->bounds, r_edges);
    if (!s) s = unknown_clearances(&l->edges, 2);
    /* particle i is element i: the slot array is its own identity map */
    for (int32_t i = 0; i < n && !s; ++i) l->particle_slot[i] = i;
    if (!s) s = list_elements(l, &l->particles, l->particle_slot, 1, n, &col->grid, col->bounds, r_particles);
    if (!s) s = unknown_clearances(&l->particles, 1);
    if (s) return s;
    for (int32_t i = 0; i < n; ++i) l->particle_slot[i] = -1;
    for (int32_t k = 0; k < l->particles.count; ++k) l->particle_slot[l->particles.element[k]] = k;
    l->collider = col;
    l->grid_version = col->grid_version;
    l->r_triangles = r_triangles, l->r_edges = r_edges, l->r_particles = r_particles;
    l->built = 1;
    return WC_OK;
}
