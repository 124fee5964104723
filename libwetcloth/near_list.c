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
    elements_free(&l->spare);
    wc_free(l->left);
    wc_near_list_init(l);
}

static int inside(const double box[6], double x, double y, double z)
{
    return x >= box[0] && x <= box[3] && y >= box[1] && y <= box[4] && z >= box[2] && z <= box[5];
}

/* Whether particle i's motion this step (start and end) lies in box. */
static int motion_inside(const double box[6], const wc_cloth *c, int32_t i)
{
    return inside(box, c->x[i], c->y[i], c->z[i]) && inside(box, c->nx[i], c->ny[i], c->nz[i]);
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
        if (!motion_inside(box, c, i)) return 0;
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

/* Grows *array (items of `size` bytes, contents kept) to hold `need`
 * items; 0 on out-of-memory, with *array as it was. */
static int grow(void **array, int64_t *capacity, int64_t need, size_t size)
{
    if (need <= *capacity) return 1;
    int64_t grown = *capacity ? *capacity : 64;
    while (grown < need) grown *= 2;
    void *bigger = wc_alloc_array((size_t)grown, size);
    if (!bigger) return 0;
    if (*capacity) memcpy(bigger, *array, (size_t)*capacity * size);
    wc_free(*array);
    *array = bigger, *capacity = grown;
    return 1;
}

static int reserve(int32_t **array, int64_t *capacity, int64_t need)
{
    void *a = *array;
    int ok = grow(&a, capacity, need, sizeof **array);
    *array = a;
    return ok;
}

static int reserve_doubles(double **array, int64_t *capacity, int64_t need)
{
    void *a = *array;
    int ok = grow(&a, capacity, need, sizeof **array);
    *array = a;
    return ok;
}

/* Particle p of element e: elements of `per` particles each, or with
 * particles NULL the particles themselves. */
static int32_t particle_of(const int32_t *particles, int per, int32_t e, int p)
{
    return particles ? particles[(size_t)per * (size_t)e + (size_t)p] : e;
}

/* Query box of an element: its particles' boxes, grown by r. */
static void element_box(const wc_near_list *l, const int32_t *particles, int per, int32_t e,
                        double r, double box[6])
{
    for (int k = 0; k < 3; ++k) box[k] = INFINITY, box[k + 3] = -INFINITY;
    for (int p = 0; p < per; ++p) {
        const double *b = l->particle_boxes + 6 * (size_t)particle_of(particles, per, e, p);
        for (int k = 0; k < 3; ++k) {
            if (b[k] - r < box[k]) box[k] = b[k] - r;
            if (b[k + 3] + r > box[k + 3]) box[k + 3] = b[k + 3] + r;
        }
    }
}

static int any_left(const wc_near_list *l, const int32_t *particles, int per, int32_t e)
{
    for (int p = 0; p < per; ++p)
        if (l->left[particle_of(particles, per, e, p)]) return 1;
    return 0;
}

/* Element e's candidates into out->found from `used` on: old's, when none
 * of its particles left their boxes (its box is the same, so the grid would
 * give the same), else the grid's for its new box. Returns how many (0: it
 * is not listed), -1 on out-of-memory; *kept says which. */
static int32_t element_candidates(const wc_near_list *l, const wc_near_elements *old,
                                  wc_near_elements *out, int64_t used, const int32_t *particles,
                                  int per, int32_t e, const wc_grid *grid, const double bounds[6],
                                  double r, int32_t *kept)
{
    *kept = -1;
    if (!any_left(l, particles, per, e)) {
        int32_t k = old->slot_of ? old->slot_of[e] : -1;
        if (k < 0) return 0;
        int32_t n = old->start[k + 1] - old->start[k];
        if (!reserve(&out->found, &out->found_capacity, used + n)) return -1;
        memcpy(out->found + used, old->found + old->start[k], (size_t)n * sizeof *out->found);
        *kept = k;
        return n;
    }
    double box[6];
    element_box(l, particles, per, e, r, box);
    if (!wc_boxes_overlap(box, bounds)) return 0;
    int32_t room = (int32_t)(out->found_capacity - used);
    /* no buffer yet (NULL): query the count only; NULL + 0 is undefined */
    int32_t n = wc_grid_query(grid, box, out->found ? out->found + used : NULL, room);
    if (n > room) {
        if (!reserve(&out->found, &out->found_capacity, used + n)) return -1;
        wc_grid_query(grid, box, out->found + used, n);
    }
    return n;
}

/* The list of one kind of element (`per` particles each, `count` of them)
 * into out, from old: each element that meets something in the grid, with
 * what it meets, and its clearances: kept from old where its candidates
 * are, else unknown (the feature pass measures them at the first visit). */
static wc_status relist_elements(const wc_near_list *l, const wc_near_elements *old,
                                 wc_near_elements *out, const int32_t *particles, int per,
                                 int32_t count, const wc_grid *grid, const double bounds[6],
                                 double r)
{
    out->count = 0;
    if (!reserve(&out->start, &out->start_capacity, 1) ||
        !reserve(&out->slot_of, &out->slot_capacity, count))
        return WC_ERROR_OUT_OF_MEMORY;
    out->start[0] = 0;
    int64_t used = 0;
    for (int32_t e = 0; e < count; ++e) {
        out->slot_of[e] = -1;
        int32_t kept;
        int32_t n = element_candidates(l, old, out, used, particles, per, e, grid, bounds, r, &kept);
        if (n < 0) return WC_ERROR_OUT_OF_MEMORY;
        if (n == 0) continue;
        int32_t k = out->count;
        if (!reserve(&out->element, &out->element_capacity, k + 1) ||
            !reserve(&out->start, &out->start_capacity, k + 2) ||
            !reserve_doubles(&out->clearance, &out->clearance_capacity, used + n) ||
            !reserve_doubles(&out->path_at, &out->path_at_capacity, (int64_t)per * (k + 1)) ||
            !reserve_doubles(&out->least_clearance, &out->least_capacity, k + 1))
            return WC_ERROR_OUT_OF_MEMORY;
        double *clearance = out->clearance + used, *path_at = out->path_at + (size_t)per * (size_t)k;
        if (kept >= 0) {
            memcpy(clearance, old->clearance + old->start[kept], (size_t)n * sizeof *clearance);
            memcpy(path_at, old->path_at + (size_t)per * (size_t)kept, (size_t)per * sizeof *path_at);
            out->least_clearance[k] = old->least_clearance[kept];
        } else {
            for (int32_t j = 0; j < n; ++j) clearance[j] = -1.0;
            for (int p = 0; p < per; ++p) path_at[p] = 0.0;
            out->least_clearance[k] = -1.0;
        }
        used += n;
        out->slot_of[e] = k;
        out->element[k] = e;
        out->start[++out->count] = (int32_t)used;
    }
    return WC_OK;
}

/* Relists one kind of element into the spare and makes that the list. */
static wc_status relist(wc_near_list *l, wc_near_elements *list, const int32_t *particles, int per,
                        int32_t count, const wc_grid *grid, const double bounds[6], double r)
{
    wc_status s = relist_elements(l, list, &l->spare, particles, per, count, grid, bounds, r);
    if (s) return s;
    wc_near_elements fresh = l->spare;
    l->spare = *list;
    *list = fresh;
    return WC_OK;
}

wc_status wc_near_list_build(wc_near_list *l, const wc_cloth *c, const int32_t *edges,
                             int32_t edge_count, const wc_collider *col, double r_triangles,
                             double r_edges, double r_particles)
{
    int32_t n = c->particle_count;
    /* lists made for this collider and these distances keep what holds */
    int keep = made_for(l, col) && l->particle_count == n && l->r_triangles == r_triangles &&
               l->r_edges == r_edges && l->r_particles == r_particles;
    l->built = 0;
    if (l->particle_count != n) {
        wc_free(l->particle_boxes);
        wc_free(l->particle_slot);
        wc_free(l->left);
        l->particle_boxes = wc_alloc_array(6 * (size_t)n, sizeof *l->particle_boxes);
        l->particle_slot = wc_alloc_array((size_t)n, sizeof *l->particle_slot);
        l->left = wc_alloc_array((size_t)n, sizeof *l->left);
        l->particle_count = l->particle_boxes && l->particle_slot && l->left ? n : 0;
        if (!l->particle_count) return WC_ERROR_OUT_OF_MEMORY;
    }
    /* Each box reaches from the start of the step to as far again past its
     * end (where the next step takes the particle if its velocity holds),
     * grown by the margin: round this step's motion alone, a particle
     * moving more than the margin per step (the drape's falling cloth at 20
     * XPBD substeps per frame) left it at the next step, and every listed
     * element's clearances, unknown after a build, were measured again. */
    double margin = MARGIN_CELLS * col->vertex_grid.cell_size;
    for (int32_t i = 0; i < n; ++i) {
        double *box = l->particle_boxes + 6 * (size_t)i;
        l->left[i] = !keep || !motion_inside(box, c, i);
        if (!l->left[i]) continue;
        double start[3] = {c->x[i], c->y[i], c->z[i]}, end[3] = {c->nx[i], c->ny[i], c->nz[i]};
        for (int k = 0; k < 3; ++k) {
            double ahead = end[k] + (end[k] - start[k]);
            box[k] = (start[k] < ahead ? start[k] : ahead) - margin;
            box[k + 3] = (start[k] > ahead ? start[k] : ahead) + margin;
        }
    }
    wc_status s = relist(l, &l->triangles, c->topology.triangles, 3, c->topology.triangle_count,
                         &col->vertex_grid, col->bounds, r_triangles);
    if (!s) s = relist(l, &l->edges, edges, 2, edge_count, &col->edge_grid, col->bounds, r_edges);
    if (!s) s = relist(l, &l->particles, NULL, 1, n, &col->grid, col->bounds, r_particles);
    if (s) return s;
    memcpy(l->particle_slot, l->particles.slot_of, (size_t)n * sizeof *l->particle_slot);
    l->collider = col;
    l->grid_version = col->grid_version;
    l->r_triangles = r_triangles, l->r_edges = r_edges, l->r_particles = r_particles;
    l->built = 1;
    return WC_OK;
}
