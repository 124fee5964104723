#include "candidates.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "alloc.h"
#include "narrowphase.h"
#include "parallel.h"
#include "primitives.h"

/* Margins, as fractions of the contact distance r: never less than LOW
 * (a resting cloth: its lists last as long as it rests), and no more than
 * HIGH r or FEATURES of the collider's mean edge length, whichever is larger, unless
 * the particle's motion in this step needs more. A margin lists the
 * features within r plus it, whose number grows with (margin / feature
 * size)^2: on a collider of 1 cm triangles a margin of 2 r = 5 cm listed
 * some 300 triangles per particle, while on the thesis' sphere (12 cm
 * edges) half an edge length lists a handful and spares a falling cloth a
 * rebase at nearly every large step (10,201 particles at 12 implicit steps
 * per frame, collisions per frame: 124 ms with HIGH r alone, 70-77 ms with
 * 0.1-0.5 edge lengths, 82 with a whole one, whose lists' queries sweep
 * more of the sphere). */
#define MARGIN_LOW 0.25
#define MARGIN_HIGH 0.5
/* ... or this fraction of the collider's mean edge length. */
#define MARGIN_FEATURES 0.5
/* A margin covers this many times the motion expected until the frame ends. */
#define MARGIN_AHEAD 1.5
/* The most a particle's local step can be, in step motions S: its frame's
 * step is the centre of a box of displacements no longer than S, so both
 * lie in the cube of half-side S, and a displacement is no farther from it
 * than that cube's diagonal, 2 sqrt(3) S. */
#define LOCAL_STEP_MOST 3.5
/* How much wider than it needs a particle's cube is counted, in r
 * (own_step_of). */
#define REACH_SLACK 0.25
/* A node of the collider's tree that meets a particle's cube and is no
 * larger than this fraction of its half-side is taken whole in the count
 * of its own step, rather than triangle by triangle: a few triangles just
 * outside the cube, whose displacements differ little from those inside
 * (own_step_of). On the bending tube, three alternated runs, dry: 147-162
 * ms per frame at 0.5, 168-189 taking no node whole, 148-174 at 1.0. */
#define WHOLE_BELOW 0.5
/* A collider whose displacements in a step all lie within this distance,
 * in r, of their common centre gives every particle that centre as its
 * frame's step, without a count per particle. */
#define ONE_PIECE_SPREAD 0.01
/* From this many particles the count of their own steps (a query of the
 * collider's tree each) runs on the step's threads. */
#define LOCAL_MOTION_PARALLEL_MIN 256


static void makers_free(wc_candidates *c);

static void lists_free(wc_pair_lists *l)
{
    wci_free(l->start), wci_free(l->count), wci_free(l->room), wci_free(l->path_at);
    wci_free(l->least), wci_free(l->debt), wci_free(l->snap), wci_free(l->item), wci_free(l->d);
    memset(l, 0, sizeof *l);
}

void wci_candidates_destroy(wc_candidates *c)
{
    wci_free(c->base), wci_free(c->margin), wci_free(c->base_path);
    wci_free(c->local_path), wci_free(c->local_step), wci_free(c->particle_mark);
    wci_free(c->frame), wci_free(c->frame_step), wci_free(c->own_step), wci_free(c->again);
    wci_free(c->own_reach);
    lists_free(&c->particles), lists_free(&c->triangles), lists_free(&c->edges);
    makers_free(c);
    wci_free(c->jobs);
    memset(c, 0, sizeof *c);
}

static int lists_init(wc_pair_lists *l, int32_t owners, int per)
{
    lists_free(l);
    size_t n = owners > 0 ? (size_t)owners : 1;
    l->owner_count = owners;
    l->per = per;
    l->start = wci_alloc_array(n, sizeof *l->start);
    l->count = wci_alloc_array(n, sizeof *l->count);
    l->room = wci_alloc_array(n, sizeof *l->room);
    l->path_at = wci_alloc_array(n, sizeof *l->path_at);
    l->least = wci_alloc_array(n, sizeof *l->least);
    l->debt = wci_alloc_array(n, sizeof *l->debt);
    l->snap = wci_alloc_array(3 * n * (size_t)(per > 0 ? per : 1), sizeof *l->snap);
    return l->start && l->count && l->room && l->path_at && l->least && l->debt && l->snap;
}

/* Moves every list to the front of a pool of `capacity`, in owner order,
 * dropping the garbage. */
static int lists_repack(wc_pair_lists *l, int64_t capacity)
{
    int32_t *item = wci_alloc_array((size_t)capacity, sizeof *item);
    double *d = wci_alloc_array((size_t)capacity, sizeof *d);
    if (!item || !d) {
        wci_free(item), wci_free(d);
        return 0;
    }
    int64_t at = 0;
    for (int32_t k = 0; k < l->owner_count; ++k) {
        if (l->count[k]) {
            memcpy(item + at, l->item + l->start[k], (size_t)l->count[k] * sizeof *item);
            memcpy(d + at, l->d + l->start[k], (size_t)l->count[k] * sizeof *d);
        }
        l->start[k] = (int32_t)at;
        l->room[k] = l->count[k];
        at += l->count[k];
    }
    wci_free(l->item), wci_free(l->d);
    l->item = item, l->d = d;
    l->used = at, l->capacity = capacity, l->garbage = 0;
    return 1;
}

/* Owner k's list becomes items/d0[0 .. n) (sorted by the caller), its
 * snapshot the collider's path and the owner's particles' bases (`snap`,
 * xyz per particle). */
static int lists_put(wc_pair_lists *l, int32_t k, const int32_t *items, const double *d0, int32_t n,
                     double path, const double *snap)
{
    l->path_at[k] = path;
    double least = INFINITY;
    for (int32_t j = 0; j < n; ++j)
        if (d0[j] < least) least = d0[j];
    l->least[k] = least;
    l->debt[k] = 0.0;
    memcpy(l->snap + 3 * (size_t)l->per * (size_t)k, snap, 3 * (size_t)l->per * sizeof *snap);
    if (n > l->room[k]) {
        l->garbage += l->room[k];
        l->room[k] = 0, l->count[k] = 0;
        int64_t room = n + n / 2 + 2;
        if (l->used + room > l->capacity) {
            int64_t live = l->used - l->garbage, need = live + room, cap = 2 * need;
            if (cap < 1024) cap = 1024;
            if (cap > INT32_MAX) cap = need;
            if (need > INT32_MAX || !lists_repack(l, cap)) return 0;
        }
        l->start[k] = (int32_t)l->used;
        l->room[k] = (int32_t)room;
        l->used += room;
    }
    if (n) {
        memcpy(l->item + l->start[k], items, (size_t)n * sizeof *items);
        memcpy(l->d + l->start[k], d0, (size_t)n * sizeof *d0);
    }
    l->count[k] = n;
    return 1;
}

static void vertex_of(const double *xyz, int32_t v, double out[3])
{
    out[0] = xyz[3 * (size_t)v], out[1] = xyz[3 * (size_t)v + 1], out[2] = xyz[3 * (size_t)v + 2];
}

double wci_candidates_particle_distance(const wc_collider *col, int32_t t, const double p[3])
{
    const int32_t *v = col->triangles + 3 * (size_t)t;
    double a[3], b[3], c[3], w[3];
    vertex_of(col->current, v[0], a), vertex_of(col->current, v[1], b), vertex_of(col->current, v[2], c);
    return sqrt(wci_point_triangle_closest(p, a, b, c, w));
}

/* Scratch for one owner's pairs: `n` ids and distances. */
typedef struct pair_entry {
    double d0;
    int32_t item;
} pair_entry;

/* Ascending by item, in runs of SORT_RUN by insertion, then merged pairwise
 * between e and tmp (n entries each). A list's items are distinct (each
 * feature is gathered once per owner), so the order is the same whatever
 * the sort; a typed merge costs about half of qsort's calls through a
 * comparison pointer, which lists rebuilt on a dense collider felt. */
#define SORT_RUN 16

static void insertion_sort(pair_entry *e, int32_t n)
{
    for (int32_t i = 1; i < n; ++i) {
        pair_entry v = e[i];
        int32_t j = i;
        for (; j > 0 && e[j - 1].item > v.item; --j) e[j] = e[j - 1];
        e[j] = v;
    }
}

static void merge_runs(const pair_entry *a, int32_t na, const pair_entry *b, int32_t nb, pair_entry *out)
{
    int32_t i = 0, j = 0, k = 0;
    while (i < na && j < nb) out[k++] = b[j].item < a[i].item ? b[j++] : a[i++];
    while (i < na) out[k++] = a[i++];
    while (j < nb) out[k++] = b[j++];
}

static void sort_by_item(pair_entry *e, pair_entry *tmp, int32_t n)
{
    for (int32_t at = 0; at < n; at += SORT_RUN)
        insertion_sort(e + at, n - at < SORT_RUN ? n - at : SORT_RUN);
    pair_entry *from = e, *to = tmp;
    for (int32_t width = SORT_RUN; width < n; width *= 2) {
        for (int32_t at = 0; at < n; at += 2 * width) {
            int32_t na = n - at < width ? n - at : width;
            int32_t nb = n - at - na < width ? n - at - na : width;
            merge_runs(from + at, na, from + at + na, nb, to + at);
        }
        pair_entry *swap = from;
        from = to, to = swap;
    }
    if (from != e) memcpy(e, from, (size_t)n * sizeof *e);
}

/* Making lists. A rebase makes the lists of its particles and of their
 * triangles and edges, each from the bases and the collider alone, so they
 * are made on the step's threads, each thread a contiguous run of them
 * with scratch of its own (a maker), into the maker's pool of pairs; then
 * they are put into the lists one after the other in the order of the run
 * (lists_put), which places them in the lists' pool as one thread would:
 * the same bits for any thread count. */

/* A list to make: what owns it (a particle, a cloth triangle or edge) and,
 * once made, which maker holds its pairs, where and how many. */
typedef enum list_kind { LIST_PARTICLE, LIST_TRIANGLE, LIST_EDGE } list_kind;

typedef struct wc_list_job {
    list_kind kind;
    int32_t owner;
    int32_t maker;
    int32_t count;
    int64_t at;
} wc_list_job;

/* One thread's scratch: what a query found, one owner's entries (and the
 * sort's room), and the pairs of the lists it made. */
typedef struct wc_list_maker {
    int32_t *found;
    int32_t found_capacity;
    struct pair_entry *entries;
    int64_t entry_capacity;
    int32_t *items;
    double *d0;
    int64_t used, capacity;
    int failed;
} wc_list_maker;

/* Below this many lists a rebase makes them on one thread: waking the
 * team costs more. */
#define LISTS_PARALLEL_MIN 64
/* Lists are made and put this many at a time, so that the makers' pools
 * hold a batch's pairs, not those of every list at once (the first making
 * on a dense collider lists millions of pairs). */
#define LISTS_BATCH 4096
/* Jobs a thread makes in a row (make_body): enough that threads seldom
 * write the same cache line of the jobs. */
#define LISTS_RUN 64

static void makers_free(wc_candidates *c)
{
    for (int32_t t = 0; t < c->maker_count; ++t) {
        wc_list_maker *m = &c->makers[t];
        wci_free(m->found), wci_free(m->entries), wci_free(m->items), wci_free(m->d0);
    }
    wci_free(c->makers);
    c->makers = NULL, c->maker_count = 0;
}

/* The items of bvh whose boxes meet `box`, into m->found (grown as
 * needed). -1 on out-of-memory. */
static int32_t query(wc_list_maker *m, const wc_bvh *bvh, const double box[6])
{
    int32_t n = wci_bvh_collect(bvh, box, m->found, m->found_capacity);
    if (n <= m->found_capacity) return n;
    int32_t *grown = wci_alloc_array((size_t)n, 2 * sizeof *grown);
    if (!grown) return -1;
    wci_free(m->found);
    m->found = grown, m->found_capacity = 2 * n;
    return wci_bvh_collect(bvh, box, m->found, m->found_capacity);
}

/* Room for n entries and as many again behind them (the sort's), the
 * first `keep` kept. */
static pair_entry *entries(wc_list_maker *m, int64_t n, int64_t keep)
{
    if (m->entries && 2 * n <= m->entry_capacity) return m->entries;
    int64_t want = 2 * (2 * n + 64);
    pair_entry *e = wci_alloc_array((size_t)want, sizeof *e);
    if (!e) return NULL;
    if (keep) memcpy(e, m->entries, (size_t)keep * sizeof *e);
    wci_free(m->entries);
    m->entries = e, m->entry_capacity = want;
    return e;
}

/* The owner's n kept pairs e, ascending by item (the order the tests take
 * them in), onto the maker's pool; job records where. 0 on out-of-memory. */
static int keep_sorted(wc_list_maker *m, wc_list_job *job, pair_entry *e, int32_t n)
{
    /* entries() leaves room for n more after the first n */
    sort_by_item(e, e + n, n);
    if (m->used + n > m->capacity) {
        int64_t cap = 2 * (m->used + n) + 1024;
        int32_t *items = wci_alloc_array((size_t)cap, sizeof *items);
        double *d0 = wci_alloc_array((size_t)cap, sizeof *d0);
        if (!items || !d0) {
            wci_free(items), wci_free(d0);
            return 0;
        }
        if (m->used) {
            memcpy(items, m->items, (size_t)m->used * sizeof *items);
            memcpy(d0, m->d0, (size_t)m->used * sizeof *d0);
        }
        wci_free(m->items), wci_free(m->d0);
        m->items = items, m->d0 = d0, m->capacity = cap;
    }
    for (int32_t k = 0; k < n; ++k) m->items[m->used + k] = e[k].item, m->d0[m->used + k] = e[k].d0;
    job->at = m->used, job->count = n;
    m->used += n;
    return 1;
}

/* Particle i's frame at the start of the step (end 0) or at its end (1). */
static void frame_of(const wc_candidates *c, int32_t i, int end, double out[3])
{
    if (!c->framed) {
        out[0] = out[1] = out[2] = 0.0;
        return;
    }
    for (int k = 0; k < 3; ++k)
        out[k] = c->frame[3 * (size_t)i + k] + (end ? c->frame_step[3 * (size_t)i + k] : 0.0);
}

/* Particle i's base where its frame has carried it by the start of the
 * step: where its lists are measured from. */
static void base_of(const wc_candidates *c, int32_t i, double out[3])
{
    frame_of(c, i, 0, out);
    for (int k = 0; k < 3; ++k) out[k] += c->base[3 * (size_t)i + k];
}

static double element_margin(const wc_candidates *c, const int32_t *idx, int count)
{
    double m = 0.0;
    for (int k = 0; k < count; ++k)
        if (c->margin[idx[k]] > m) m = c->margin[idx[k]];
    return m;
}

static void element_box(const wc_candidates *c, const int32_t *idx, int count, double grow, double box[6])
{
    for (int k = 0; k < 3; ++k) box[k] = INFINITY, box[k + 3] = -INFINITY;
    for (int j = 0; j < count; ++j) {
        double p[3];
        base_of(c, idx[j], p);
        for (int k = 0; k < 3; ++k) {
            if (p[k] - grow < box[k]) box[k] = p[k] - grow;
            if (p[k] + grow > box[k + 3]) box[k + 3] = p[k] + grow;
        }
    }
}

/* Particle i's pairs: collider triangles within r + margin of its base. */
static int particle_pairs(const wc_candidates *c, wc_list_maker *m, const wc_collider *col,
                          wc_list_job *job)
{
    int32_t i = job->owner;
    double p[3], reach = c->r + c->margin[i], box[6];
    base_of(c, i, p);
    for (int k = 0; k < 3; ++k) box[k] = p[k] - reach, box[k + 3] = p[k] + reach;
    int32_t n = query(m, &col->bvh, box);
    if (n < 0) return 0;
    pair_entry *e = entries(m, n, 0);
    if (!e) return 0;
    int32_t kept = 0;
    for (int32_t k = 0; k < n; ++k) {
        double d = wci_candidates_particle_distance(col, m->found[k], p);
        if (d <= reach) e[kept].d0 = d, e[kept].item = m->found[k], ++kept;
    }
    return keep_sorted(m, job, e, kept);
}

/* A feature list's reach for one class of features (smooth or sharp:
 * candidates.h), its owner's margin given, and how much less than its
 * distance a pair of that class is listed (*shift). */
static double class_reach(const wc_candidates *c, int smooth, double margin, double *shift)
{
    *shift = smooth ? 0.0 : c->sharp_shift;
    double r = smooth && c->smooth_features ? c->feature_r : c->feature_r + c->sharp_shift;
    return r + margin;
}

/* Cloth triangle t's pairs: collider vertices within the feature distance
 * plus M of it (its corners at their bases), from the collider's vertex
 * tree. */
static int triangle_pairs(const wc_candidates *c, wc_list_maker *m, const wc_cloth_elements *el,
                          const wc_collider *col, wc_list_job *job)
{
    const int32_t *idx = el->triangles + 3 * (size_t)job->owner;
    double margin = element_margin(c, idx, 3), a[3], b[3], d[3];
    base_of(c, idx[0], a), base_of(c, idx[1], b), base_of(c, idx[2], d);
    int32_t kept = 0;
    pair_entry *e = NULL;
    /* the sharp vertices, then the smooth ones (collider.h) */
    for (int smooth = 0; smooth < 2; ++smooth) {
        double shift, reach = class_reach(c, smooth, margin, &shift), box[6];
        element_box(c, idx, 3, reach, box);
        int32_t n = query(m, smooth ? &col->smooth_vertex_bvh : &col->vertex_bvh, box);
        if (n < 0 || !(e = entries(m, kept + n, kept))) return 0;
        const int32_t *vertex = col->used_vertices + (smooth ? col->smooth_vertices_from : 0);
        for (int32_t k = 0; k < n; ++k) {
            int32_t v = vertex[m->found[k]];
            double p[3], w[3];
            vertex_of(col->current, v, p);
            double dist = sqrt(wci_point_triangle_closest(p, a, b, d, w));
            if (dist <= reach) e[kept].d0 = dist - shift, e[kept].item = v, ++kept;
        }
    }
    return keep_sorted(m, job, e, kept);
}

/* A lower bound on the distance between segments p-q and a-b: from the
 * midpoint of p-q to a-b, less half the length of p-q. */
static double segment_lower_bound(const double p[3], const double q[3], const double a[3],
                                  const double b[3])
{
    double m[3], ab[3], am[3], half2 = 0.0;
    for (int k = 0; k < 3; ++k) {
        m[k] = 0.5 * (p[k] + q[k]);
        ab[k] = b[k] - a[k], am[k] = m[k] - a[k];
        half2 += 0.25 * (q[k] - p[k]) * (q[k] - p[k]);
    }
    double len2 = ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2];
    double t = len2 > 0.0 ? (am[0] * ab[0] + am[1] * ab[1] + am[2] * ab[2]) / len2 : 0.0;
    t = t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t;
    double d2 = 0.0;
    for (int k = 0; k < 3; ++k) {
        double g = am[k] - t * ab[k];
        d2 += g * g;
    }
    return sqrt(d2) - sqrt(half2);
}

/* Cloth edge e's pairs: collider edges within the feature distance plus M
 * of it, from the collider's edge tree. */
static int edge_pairs(const wc_candidates *c, wc_list_maker *m, const wc_cloth_elements *el,
                      const wc_collider *col, wc_list_job *job)
{
    const int32_t *idx = el->edges + 2 * (size_t)job->owner;
    double margin = element_margin(c, idx, 2), a[3], b[3];
    base_of(c, idx[0], a), base_of(c, idx[1], b);
    int32_t kept = 0;
    pair_entry *e = NULL;
    /* the sharp edges, then the smooth ones (collider.h) */
    for (int smooth = 0; smooth < 2; ++smooth) {
        double shift, reach = class_reach(c, smooth, margin, &shift), box[6];
        element_box(c, idx, 2, reach, box);
        int32_t n = query(m, smooth ? &col->smooth_edge_bvh : &col->edge_bvh, box);
        if (n < 0 || !(e = entries(m, kept + n, kept))) return 0;
        const int32_t *order = col->edge_order + (smooth ? col->smooth_edges_from : 0);
        for (int32_t k = 0; k < n; ++k) {
            int32_t f = order[m->found[k]];
            double p[3], q[3], u, v;
            vertex_of(col->current, col->edges[2 * (size_t)f], p);
            vertex_of(col->current, col->edges[2 * (size_t)f + 1], q);
            /* cheap bound first: no point of the collider edge is nearer to
             * the cloth edge than its midpoint's distance less half its
             * length */
            if (segment_lower_bound(p, q, a, b) > reach) continue;
            double dist = sqrt(wci_segment_segment_closest(p, q, a, b, &u, &v));
            if (dist <= reach) e[kept].d0 = dist - shift, e[kept].item = f, ++kept;
        }
    }
    return keep_sorted(m, job, e, kept);
}

/* What making the lists reads, for the team. */
typedef struct make_pass {
    wc_candidates *cand;
    const wc_cloth_elements *el;
    const wc_collider *col;
    /* the batch: jobs [first, first + count) */
    int32_t first, count;
    /* the batch's first job that no thread has claimed yet */
    int32_t next;
} make_pass;

/* The first of the next LISTS_RUN jobs of the batch, claimed by the
 * calling thread. A critical section, not `atomic capture`: the code keeps
 * to OpenMP 2.0, which MSVC's /openmp implements (docs/building.md); a
 * claim per 64 lists costs nothing measurable. Unnamed: a named one is a
 * lock symbol that the library would export. */
static int32_t claim_run(make_pass *pass)
{
    int32_t begin;
#pragma omp critical
    {
        begin = pass->next;
        pass->next = begin < pass->count ? begin + LISTS_RUN : begin;
    }
    return begin;
}

/* Each thread claims LISTS_RUN jobs at a time until the batch is done: the
 * jobs come kind by kind (particles, triangles, edges) and the kinds cost
 * differently, so one contiguous slice per thread would leave a thread
 * waiting. Which thread makes a list changes nothing but where its pairs
 * wait (job->maker): put_list puts them in job order. */
static void make_body(void *context, const wc_team *team)
{
    make_pass *pass = context;
    wc_candidates *c = pass->cand;
    /* a copy of its own: the makers lie side by side, and a thread writing
     * to its maker at every list takes the other's cache line from it. (On
     * the 10,201-particle drape, making lists on 2 threads took 1.25 times
     * less time than on 1 with equal slices and the makers written in
     * place, 1.7 times less with the claimed runs and the copies; 1.6
     * times with the runs dealt to the threads in turn.) */
    wc_list_maker own = c->makers[team->thread], *m = &own;
    m->used = 0;
    for (int32_t begin = claim_run(pass); begin < pass->count && !m->failed; begin = claim_run(pass)) {
        int32_t end = pass->count - begin < LISTS_RUN ? pass->count : begin + LISTS_RUN;
        for (int32_t j = begin; j < end && !m->failed; ++j) {
            wc_list_job *job = &c->jobs[pass->first + j];
            job->maker = team->thread;
            int ok = job->kind == LIST_PARTICLE ? particle_pairs(c, m, pass->col, job)
                     : job->kind == LIST_TRIANGLE ? triangle_pairs(c, m, pass->el, pass->col, job)
                                                  : edge_pairs(c, m, pass->el, pass->col, job);
            m->failed = !ok;
        }
    }
    c->makers[team->thread] = own;
}

/* Owner job->owner's list from its pairs: the snapshot is its particles'
 * bases and the local path the list counts from (a particle's at its
 * rebase, an element's at its first particle now). */
static int put_list(wc_candidates *c, const wc_cloth_elements *el, const wc_list_job *job)
{
    const wc_list_maker *m = &c->makers[job->maker];
    /* a maker whose lists were all empty has no pool */
    const int32_t *items = job->count ? m->items + job->at : NULL;
    const double *d0 = job->count ? m->d0 + job->at : NULL;
    double snap[9];
    if (job->kind == LIST_PARTICLE) {
        vertex_of(c->base, job->owner, snap);
        return lists_put(&c->particles, job->owner, items, d0, job->count,
                         c->base_path[job->owner], snap);
    }
    int per = job->kind == LIST_TRIANGLE ? 3 : 2;
    const int32_t *idx = per == 3 ? el->triangles + 3 * (size_t)job->owner
                                  : el->edges + 2 * (size_t)job->owner;
    for (int k = 0; k < per; ++k) vertex_of(c->base, idx[k], snap + 3 * k);
    return lists_put(per == 3 ? &c->triangles : &c->edges, job->owner, items, d0, job->count,
                     c->local_path[idx[0]], snap);
}

/* Room for n jobs and a maker per thread. 0 on out-of-memory. */
static int ready_jobs(wc_candidates *c, int64_t n, int threads)
{
    if (n > c->job_capacity) {
        int64_t want = n + n / 2 + 64;
        if (want > INT32_MAX) want = n;
        wc_list_job *jobs = wci_alloc_array((size_t)want, sizeof *jobs);
        if (!jobs) return 0;
        wci_free(c->jobs);
        c->jobs = jobs, c->job_capacity = (int32_t)want;
    }
    if (threads > c->maker_count) {
        wc_list_maker *makers = wci_alloc_array((size_t)threads, sizeof *makers);
        if (!makers) return 0;
        if (c->maker_count) memcpy(makers, c->makers, (size_t)c->maker_count * sizeof *makers);
        wci_free(c->makers);
        c->makers = makers, c->maker_count = threads;
    }
    return 1;
}

/* Makes the lists of c->jobs[0 .. count), then puts them in that order.
 * 0 on out-of-memory. */
static int make_lists(wc_candidates *c, const wc_cloth_elements *el, const wc_collider *col,
                      int32_t count, int threads)
{
    int team = count >= LISTS_PARALLEL_MIN ? threads : 1;
    for (int32_t first = 0; first < count; first += LISTS_BATCH) {
        make_pass pass = {c, el, col, first, count - first < LISTS_BATCH ? count - first : LISTS_BATCH, 0};
        /* every maker, not only those the runtime gives the team */
        for (int32_t t = 0; t < c->maker_count; ++t) c->makers[t].failed = 0;
        wci_parallel_team(team, make_body, &pass);
        for (int32_t t = 0; t < c->maker_count; ++t)
            if (c->makers[t].failed) return 0;
        for (int32_t j = first; j < first + pass.count; ++j)
            if (!put_list(c, el, &c->jobs[j])) return 0;
    }
    return 1;
}

static void add_job(wc_candidates *c, int32_t *count, list_kind kind, int32_t owner)
{
    c->jobs[*count].kind = kind, c->jobs[*count].owner = owner;
    ++*count;
}

/* New base (the start of the step, in its frame) and margin for particle
 * i. Its margin must cover this step at once, and is made to cover
 * MARGIN_AHEAD times the motion expected until the frame ends, within
 * [MARGIN_LOW r, MARGIN_HIGH r]; both counted relative to its frame (its
 * own motion less its frame's, plus the collider's local step). A particle
 * far from the collider gets no more: its triangles' and edges' lists take
 * the largest margin of their particles, and a margin as large as the gap
 * to the collider made their queries sweep much of it (measured: the soaked
 * 2 m cloth falling past the sphere spent most of its step making lists); a
 * rebase far from everything costs a query that stops at the tree's root.
 * A rebase widens the cubes of its neighbours (their reach takes its
 * margin), so their local steps may rise after it: `worst` makes the
 * margin cover the most a local step can be (LOCAL_STEP_MOST), for a
 * particle that such a rise already pushed out of its cover once. */
static void rebase_one(wc_candidates *c, const wc_collider *col, int32_t i,
                       const wc_particle_arrays *pa, int32_t steps_left, int worst)
{
    double f[3], e[3], p[3] = {pa->x[i], pa->y[i], pa->z[i]}, r = c->r;
    frame_of(c, i, 0, f), frame_of(c, i, 1, e);
    double d[3] = {pa->nx[i] - e[0] - p[0] + f[0], pa->ny[i] - e[1] - p[1] + f[1],
                   pa->nz[i] - e[2] - p[2] + f[2]};
    double own = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    double now = own + (worst ? LOCAL_STEP_MOST * col->step_motion : c->local_step[i]);
    double m = MARGIN_AHEAD * now * (1.0 + (steps_left > 0 ? steps_left : 0));
    if (m < MARGIN_LOW * r) m = MARGIN_LOW * r;
    double feature = MARGIN_FEATURES * col->feature_size;
    double high = MARGIN_HIGH * r > feature ? MARGIN_HIGH * r : feature;
    if (m > high) m = high;
    if (m < MARGIN_AHEAD * now) m = MARGIN_AHEAD * now;
    /* strictly above this step's own motion, even when it is zero */
    if (!(m > now)) m = now + MARGIN_LOW * r + 1e-12;
    for (int k = 0; k < 3; ++k) c->base[3 * (size_t)i + k] = p[k] - f[k];
    c->margin[i] = m;
    c->base_path[i] = c->local_path[i];
}

static int allocate(wc_candidates *c, const wc_cloth_elements *el)
{
    size_t n = el->particle_count > 0 ? (size_t)el->particle_count : 1;
    /* each made once; a failed call leaves the others for the retry */
    if (!c->base) c->base = wci_alloc_array(3 * n, sizeof *c->base);
    if (!c->margin) c->margin = wci_alloc_array(n, sizeof *c->margin);
    if (!c->base_path) c->base_path = wci_alloc_array(n, sizeof *c->base_path);
    if (!c->local_path) c->local_path = wci_alloc_array(n, sizeof *c->local_path);
    if (!c->local_step) c->local_step = wci_alloc_array(n, sizeof *c->local_step);
    if (!c->particle_mark) c->particle_mark = wci_alloc_array(n, 1);
    if (!c->frame) c->frame = wci_alloc_array(3 * n, sizeof *c->frame);
    if (!c->frame_step) c->frame_step = wci_alloc_array(3 * n, sizeof *c->frame_step);
    if (!c->own_step) c->own_step = wci_alloc_array(n, sizeof *c->own_step);
    if (!c->own_reach) c->own_reach = wci_alloc_array(n, sizeof *c->own_reach);
    if (!c->again) c->again = wci_alloc_array(2 * n, sizeof *c->again);
    return c->base && c->margin && c->base_path && c->local_path && c->local_step && c->particle_mark &&
           c->frame && c->frame_step && c->own_step && c->own_reach && c->again;
}

/* Whether the smooth features keep the smaller distance (candidates.h):
 * a cloth edge of length L across an edge where the surface turns by at
 * most a (WC_SMOOTH_FEATURE_ANGLE), its ends on the faces' planes at r,
 * passes the edge at r less at most (L / 2) tan(a / 2); within (1 -
 * WC_FEATURE_DISTANCE) r of r, the faces hold the cloth where a sharp
 * feature's test would, so that distance is all the smooth feature's test
 * gives up. On a cloth whose edges are too long for that, every feature
 * keeps the sharp distance. */
static void choose_feature_distances(wc_candidates *c, const wc_cloth_elements *el, double r)
{
    double longest2 = 0.0;
    for (int32_t e = 0; e < el->edge_count; ++e) {
        const double *a = c->base + 3 * (size_t)el->edges[2 * (size_t)e];
        const double *b = c->base + 3 * (size_t)el->edges[2 * (size_t)e + 1];
        double d2 = (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]);
        if (d2 > longest2) longest2 = d2;
    }
    double dip = 0.5 * sqrt(longest2) * tan(0.5 * WC_SMOOTH_FEATURE_ANGLE);
    c->smooth_features = !c->sharp_only && dip <= (1.0 - WC_FEATURE_DISTANCE) * r;
    double sharp = WC_FEATURE_DISTANCE * r;
    c->feature_r = c->smooth_features ? WC_SMOOTH_FEATURE_DISTANCE * r : sharp;
    /* the exact test counts a touch nearer than its distance times
     * sqrt(1 - WC_FEATURE_SLACK) */
    c->sharp_shift = (sharp - c->feature_r) * sqrt(1.0 - WC_FEATURE_SLACK);
}

wc_status wci_candidates_update(wc_candidates *c, const wc_cloth_elements *el, const wc_collider *col,
                              double r, const wc_particle_arrays *p, int32_t steps_left, int threads)
{
    int64_t jobs = (int64_t)el->particle_count + el->triangle_count + el->edge_count;
    if (!allocate(c, el) || !lists_init(&c->particles, el->particle_count, 1) ||
        !lists_init(&c->triangles, el->triangle_count, 3) || !lists_init(&c->edges, el->edge_count, 2) ||
        jobs > INT32_MAX || !ready_jobs(c, jobs, threads))
        return WC_ERROR_OUT_OF_MEMORY;
    c->r = r;
    for (int32_t i = 0; i < el->particle_count; ++i) {
        c->local_path[i] = 0.0, c->local_step[i] = 0.0;
        for (int k = 0; k < 3; ++k) c->frame[3 * (size_t)i + k] = 0.0, c->frame_step[3 * (size_t)i + k] = 0.0;
    }
    c->framed = 0;
    for (int32_t i = 0; i < el->particle_count; ++i) rebase_one(c, col, i, p, steps_left, 1);
    choose_feature_distances(c, el, r);
    int32_t count = 0;
    for (int32_t i = 0; i < el->particle_count; ++i) add_job(c, &count, LIST_PARTICLE, i);
    for (int32_t t = 0; t < el->triangle_count; ++t) add_job(c, &count, LIST_TRIANGLE, t);
    for (int32_t e = 0; e < el->edge_count; ++e) add_job(c, &count, LIST_EDGE, e);
    if (!make_lists(c, el, col, count, threads)) {
        c->r = 0.0; /* made again at the next use */
        return WC_ERROR_OUT_OF_MEMORY;
    }
    wci_candidates_local_motion(c, el, col, threads);
    return WC_OK;
}

static int32_t neighbour(const wc_cloth_elements *el, int32_t i, int32_t k);
static void recount_local_steps(wc_candidates *c, const wc_cloth_elements *el, const wc_collider *col,
                                const int32_t *particles, int32_t count, const wc_particle_arrays *p,
                                int32_t *uncovered);

/* One round of wci_candidates_rebase: the particles rebased, their lists and
 * those of their triangles and edges made again, and the local steps near
 * them recounted. Returns how many particles that recount pushed out of
 * their cover, listed at c->again + n (n the particle count). 0 or -1 on
 * out-of-memory. */
static int32_t rebase_round(wc_candidates *c, const wc_cloth_elements *el, const wc_collider *col,
                            const int32_t *particles, int32_t count, const wc_particle_arrays *p,
                            int32_t steps_left, uint8_t *mark, int threads, int worst)
{
    /* at most each particle and each of its triangles and edges once */
    int64_t most = count;
    for (int32_t k = 0; k < count; ++k) {
        int32_t i = particles[k];
        most += el->triangles_start[i + 1] - el->triangles_start[i];
        most += el->edges_start[i + 1] - el->edges_start[i];
    }
    if (most > INT32_MAX || !ready_jobs(c, most, threads)) return -1;
    for (int32_t k = 0; k < count; ++k) rebase_one(c, col, particles[k], p, steps_left, worst);
    int32_t jobs = 0;
    for (int32_t k = 0; k < count; ++k) add_job(c, &jobs, LIST_PARTICLE, particles[k]);
    /* each triangle and edge of a rebased particle once, in the order met */
    for (int kind = 0; kind < 2; ++kind) {
        const int32_t *start = kind ? el->edges_start : el->triangles_start;
        const int32_t *items = kind ? el->edges_of : el->triangles_of;
        for (int32_t k = 0; k < count; ++k)
            for (int32_t j = start[particles[k]]; j < start[particles[k] + 1]; ++j) {
                int32_t e = items[j];
                if (mark[e]) continue;
                mark[e] = 1;
                add_job(c, &jobs, kind ? LIST_EDGE : LIST_TRIANGLE, e);
            }
        for (int32_t k = 0; k < count; ++k)
            for (int32_t j = start[particles[k]]; j < start[particles[k] + 1]; ++j) mark[items[j]] = 0;
    }
    if (!make_lists(c, el, col, jobs, threads)) return -1;
    /* new bases and margins: their reaches and their neighbours' */
    int32_t uncovered = 0;
    recount_local_steps(c, el, col, particles, count, p, &uncovered);
    return uncovered;
}

wc_status wci_candidates_rebase(wc_candidates *c, const wc_cloth_elements *el, const wc_collider *col,
                               const int32_t *particles, int32_t count, const wc_particle_arrays *p,
                               int32_t steps_left, uint8_t *mark, int threads)
{
    /* A particle whose local step the recount raised past its cover is
     * rebased in a further round, with a margin that covers the most any
     * local step can be, so that no round rebases it again and the rounds
     * end (each particle at most twice). */
    int32_t n = el->particle_count, *work = c->again;
    for (int worst = 0; count > 0; worst = 1) {
        int32_t uncovered = rebase_round(c, el, col, particles, count, p, steps_left, mark, threads, worst);
        if (uncovered < 0) {
            c->r = 0.0;
            return WC_ERROR_OUT_OF_MEMORY;
        }
        memcpy(work, c->again + n, (size_t)uncovered * sizeof *work);
        for (int32_t k = 0; k < uncovered; ++k) c->particle_mark[work[k]] = 0;
        particles = work, count = uncovered;
    }
    return WC_OK;
}

/* The particle at the other end of particle i's k-th edge. */
static int32_t neighbour(const wc_cloth_elements *el, int32_t i, int32_t k)
{
    const int32_t *e = el->edges + 2 * (size_t)el->edges_of[k];
    return e[0] == i ? e[1] : e[0];
}

/* The half-side of particle i's cube (wci_candidates_local_motion): what a
 * collider triangle must be within to be near it. Besides the reach of its
 * elements at their bases, the bases themselves move with their frames
 * during the step, each by at most sqrt(3) S (LOCAL_STEP_MOST). */
static double local_reach(const wc_candidates *c, const wc_cloth_elements *el, const wc_collider *col,
                          int32_t i)
{
    double margin = c->margin[i], far2 = 0.0, b[3], q[3];
    base_of(c, i, b);
    for (int32_t k = el->edges_start[i]; k < el->edges_start[i + 1]; ++k) {
        int32_t j = neighbour(el, i, k);
        if (c->margin[j] > margin) margin = c->margin[j];
        base_of(c, j, q);
        double d[3] = {q[0] - b[0], q[1] - b[1], q[2] - b[2]};
        double d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        if (d2 > far2) far2 = d2;
    }
    return c->r + margin + sqrt(far2) + 2.0 * col->step_motion;
}

/* Particle i's own step: how far, at most, the collider's triangles near it
 * moved in this step relative to its frame's step. `choose` sets the
 * frame's step first, to the centre of the box of their displacements (a
 * collider carrying the cloth along then moves by about nothing relative
 * to it); otherwise the frame's step stays as chosen at the start of the
 * step, since snapshots taken since count from it. The cube is counted a
 * little wider than it needs (by REACH_SLACK r), so that a neighbour's
 * rebase, which widens it a little, seldom needs it counted again: a
 * wider cube holds more triangles and gives a bound as good. */
static int own_step_of(wc_candidates *c, const wc_cloth_elements *el, const wc_collider *col, int32_t i,
                       int choose)
{
    double *u = c->frame_step + 3 * (size_t)i;
    if (!(col->step_motion > 0.0) || c->whole_collider) {
        c->own_step[i] = col->step_motion;
        if (choose) u[0] = u[1] = u[2] = 0.0;
        return 0;
    }
    double reach = local_reach(c, el, col, i);
    if (!choose && reach <= c->own_reach[i]) return 0;
    reach += REACH_SLACK * c->r;
    c->own_reach[i] = reach;
    double b[3], box[6], shift[6];
    base_of(c, i, b);
    for (int k = 0; k < 3; ++k) box[k] = b[k] - reach, box[k + 3] = b[k] + reach;
    if (!wci_bvh_union_within(&col->bvh, col->triangle_shift, col->node_shift, box, WHOLE_BELOW * reach,
                              shift)) {
        if (choose) u[0] = u[1] = u[2] = 0.0;
        c->own_step[i] = 0.0;
        return 0;
    }
    if (choose)
        for (int k = 0; k < 3; ++k) u[k] = 0.5 * (shift[k] + shift[k + 3]);
    /* the farthest corner of the box from the frame's step */
    double far2 = 0.0;
    for (int k = 0; k < 3; ++k) {
        double lo = u[k] - shift[k], hi = shift[k + 3] - u[k], g = lo > hi ? lo : hi;
        far2 += g * g;
    }
    c->own_step[i] = sqrt(far2);
    return u[0] != 0.0 || u[1] != 0.0 || u[2] != 0.0;
}

/* What the count of every particle's own and local steps reads. */
typedef struct local_motion_pass {
    wc_candidates *cand;
    const wc_cloth_elements *el;
    const wc_collider *col;
} local_motion_pass;

/* Own steps of particles [begin, end), with their frames' steps chosen;
 * nonzero if any frame moves. */
static int own_steps_range(void *context, int64_t begin, int64_t end)
{
    const local_motion_pass *pass = context;
    int moved = 0;
    for (int64_t i = begin; i < end; ++i) moved |= own_step_of(pass->cand, pass->el, pass->col, (int32_t)i, 1);
    return moved;
}

/* Local steps of particles [begin, end): an element's pairs move relative
 * to its particles' frames by no more than the largest of their own steps
 * (candidates.h, relative motion), and every element of i has only i and
 * its neighbours. */
static int local_steps_range(void *context, int64_t begin, int64_t end)
{
    const local_motion_pass *pass = context;
    wc_candidates *c = pass->cand;
    const wc_cloth_elements *el = pass->el;
    for (int64_t i = begin; i < end; ++i) {
        double most = c->own_step[i];
        for (int32_t m = el->edges_start[i]; m < el->edges_start[i + 1]; ++m)
            if (c->own_step[neighbour(el, (int32_t)i, m)] > most) most = c->own_step[neighbour(el, (int32_t)i, m)];
        c->local_step[i] = most;
    }
    return 0;
}

/* A collider that moves as one piece (a prop, a vehicle, a character's
 * root motion) displaces its vertices by nearly the same vector: the box of
 * all its displacements, at the tree's root, is then small, and its centre
 * serves every particle as well as a count of its own. Returns 0 (and
 * leaves everything) for a collider that does not. */
static int frames_of_one_piece(wc_candidates *c, const wc_cloth_elements *el, const wc_collider *col)
{
    if (col->bvh.node_count == 0) return 0;
    const double *all = col->node_shift;
    double half2 = 0.0;
    for (int k = 0; k < 3; ++k) half2 += 0.25 * (all[k + 3] - all[k]) * (all[k + 3] - all[k]);
    if (!(sqrt(half2) <= ONE_PIECE_SPREAD * c->r)) return 0;
    for (int32_t i = 0; i < el->particle_count; ++i) {
        for (int k = 0; k < 3; ++k) c->frame_step[3 * (size_t)i + k] = 0.5 * (all[k] + all[k + 3]);
        c->own_step[i] = sqrt(half2);
        c->local_step[i] = c->own_step[i];
        /* it holds for any cube: no recount needs it again */
        c->own_reach[i] = INFINITY;
    }
    c->framed = 1;
    return 1;
}

void wci_candidates_local_motion(wc_candidates *c, const wc_cloth_elements *el, const wc_collider *col,
                                 int threads)
{
    if (!(col->step_motion > 0.0) || c->whole_collider) {
        /* every frame stands still this step, and every step is the same */
        for (int32_t i = 0; i < el->particle_count; ++i) {
            own_step_of(c, el, col, i, 1);
            c->local_step[i] = c->own_step[i];
        }
        return;
    }
    if (frames_of_one_piece(c, el, col)) return;
    /* a tree query per particle: worth a team from a few hundred */
    int team = el->particle_count >= LOCAL_MOTION_PARALLEL_MIN ? threads : 1;
    local_motion_pass pass = {c, el, col};
    if (wci_parallel_for(el->particle_count, team, own_steps_range, &pass)) c->framed = 1;
    wci_parallel_for(el->particle_count, team, local_steps_range, &pass);
}

/* Particle j's own step taken into its local step and its neighbours'
 * (raised, never lowered: within a step a local step only grows); a
 * particle whose cover that breaks is listed at c->again + n. */
static void raise_local_steps(wc_candidates *c, const wc_cloth_elements *el, int32_t j,
                              const wc_particle_arrays *p, int32_t *uncovered)
{
    int32_t n = el->particle_count;
    for (int32_t m = el->edges_start[j] - 1; m < el->edges_start[j + 1]; ++m) {
        int32_t k = m < el->edges_start[j] ? j : neighbour(el, j, m);
        if (!(c->own_step[j] > c->local_step[k])) continue;
        c->local_step[k] = c->own_step[j];
        if (c->particle_mark[k] & 2 || wc_candidates_covers(c, k, wci_candidates_displacement(c, p, k)))
            continue;
        c->particle_mark[k] |= 2;
        c->again[n + (*uncovered)++] = k;
    }
}

/* After a rebase of the particles listed: the own steps of each and of each
 * neighbour (their cubes take its base and margin) counted again, and the
 * local steps near them raised to match. */
static void recount_local_steps(wc_candidates *c, const wc_cloth_elements *el, const wc_collider *col,
                                const int32_t *particles, int32_t count, const wc_particle_arrays *p,
                                int32_t *uncovered)
{
    /* each listed particle and each neighbour once, in the order met (m =
     * the start less one stands for the particle itself) */
    for (int pass = 0; pass < 2; ++pass) {
        for (int32_t k = 0; k < count; ++k) {
            int32_t i = particles[k];
            for (int32_t m = el->edges_start[i] - 1; m < el->edges_start[i + 1]; ++m) {
                int32_t j = m < el->edges_start[i] ? i : neighbour(el, i, m);
                if (c->particle_mark[j] & 1) continue;
                c->particle_mark[j] |= 1;
                if (pass == 0) own_step_of(c, el, col, j, 0);
                else raise_local_steps(c, el, j, p, uncovered);
            }
        }
        for (int32_t k = 0; k < count; ++k) {
            int32_t i = particles[k];
            c->particle_mark[i] &= (uint8_t)~1u;
            for (int32_t m = el->edges_start[i]; m < el->edges_start[i + 1]; ++m)
                c->particle_mark[neighbour(el, i, m)] &= (uint8_t)~1u;
        }
    }
}

void wci_candidates_commit(wc_candidates *c, int32_t particle_count)
{
    if (!c->local_path) return;
    for (int32_t i = 0; i < particle_count; ++i) {
        c->local_path[i] += c->local_step[i], c->local_step[i] = 0.0;
        for (int k = 0; k < 3 && c->framed; ++k) {
            c->frame[3 * (size_t)i + k] += c->frame_step[3 * (size_t)i + k];
            c->frame_step[3 * (size_t)i + k] = 0.0;
        }
    }
}

/* Particle i's end less its frame's end: where it is in its frame. */
static void end_in_frame(const wc_candidates *c, const wc_particle_arrays *p, int32_t i, double out[3])
{
    frame_of(c, i, 1, out);
    out[0] = p->nx[i] - out[0], out[1] = p->ny[i] - out[1], out[2] = p->nz[i] - out[2];
}

double wci_candidates_ceiling(const wc_candidates *c, double r, const int32_t *idx, int count,
                              const wc_particle_arrays *p)
{
    double far2 = 0.0;
    for (int k = 0; k < count; ++k) {
        int32_t i = idx[k];
        const double *b = c->base + 3 * (size_t)i;
        double e[3];
        end_in_frame(c, p, i, e);
        double d[3] = {e[0] - b[0], e[1] - b[1], e[2] - b[2]};
        double d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        if (d2 > far2) far2 = d2;
    }
    return r + element_margin(c, idx, count) - sqrt(far2);
}

/* The larger squared distance of particle i in its frame at the start and
 * at the end of the step from a point of its frame: by convexity (the
 * particle and its frame both move linearly in the step), the most it is
 * from it over the step, squared (the callers take one root of the largest
 * of several: the filter of every element visit reads it). */
static double farthest2_over_step(const wc_candidates *c, const wc_particle_arrays *p, int32_t i,
                                  const double at[3])
{
    double f[3] = {0.0, 0.0, 0.0}, e[3] = {p->nx[i], p->ny[i], p->nz[i]};
    if (c->framed) frame_of(c, i, 0, f), end_in_frame(c, p, i, e);
    double s[3] = {p->x[i] - f[0] - at[0], p->y[i] - f[1] - at[1], p->z[i] - f[2] - at[2]};
    double t[3] = {e[0] - at[0], e[1] - at[1], e[2] - at[2]};
    double s2 = s[0] * s[0] + s[1] * s[1] + s[2] * s[2], e2 = t[0] * t[0] + t[1] * t[1] + t[2] * t[2];
    return s2 > e2 ? s2 : e2;
}

double wci_candidates_displacement(const wc_candidates *c, const wc_particle_arrays *p, int32_t i)
{
    return sqrt(farthest2_over_step(c, p, i, c->base + 3 * (size_t)i));
}

double wci_pair_lists_drift2(const wc_candidates *c, const wc_pair_lists *l, int32_t k,
                            const int32_t *particles, const wc_particle_arrays *p)
{
    const double *snap = l->snap + 3 * (size_t)l->per * (size_t)k;
    double most2 = 0.0;
    for (int j = 0; j < l->per; ++j) {
        double d2 = farthest2_over_step(c, p, particles[j], snap + 3 * j);
        if (d2 > most2) most2 = d2;
    }
    return most2;
}

double wci_pair_lists_drift(const wc_candidates *c, const wc_pair_lists *l, int32_t k,
                           const int32_t *particles, const wc_particle_arrays *p)
{
    return sqrt(wci_pair_lists_drift2(c, l, k, particles, p));
}

double wci_pair_lists_end_drift(const wc_candidates *c, const wc_pair_lists *l, int32_t k,
                               const int32_t *particles, const wc_particle_arrays *p)
{
    const double *snap = l->snap + 3 * (size_t)l->per * (size_t)k;
    double most2 = 0.0;
    for (int j = 0; j < l->per; ++j) {
        const double *at = snap + 3 * j;
        double e[3];
        end_in_frame(c, p, particles[j], e);
        double d[3] = {e[0] - at[0], e[1] - at[1], e[2] - at[2]};
        double d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        if (d2 > most2) most2 = d2;
    }
    return sqrt(most2);
}

void wci_pair_lists_renew(const wc_candidates *c, wc_pair_lists *l, int32_t k, const int32_t *particles,
                         const wc_particle_arrays *p, double collider_path, const int32_t *at,
                         const double *measured2, const double *less, int32_t n,
                         double least_unmeasured, double drift_end, double ceiling)
{
    double *d = l->d + l->start[k], debt = l->debt[k] + drift_end, least = least_unmeasured;
    l->debt[k] = debt;
    for (int32_t j = 0; j < n; ++j) {
        double measured = less ? sqrt(measured2[j]) - less[j] : sqrt(measured2[j]);
        d[at[j]] = (measured < ceiling ? measured : ceiling) + debt;
        if (d[at[j]] < least) least = d[at[j]];
    }
    l->least[k] = least;
    l->path_at[k] = collider_path;
    double *snap = l->snap + 3 * (size_t)l->per * (size_t)k;
    for (int j = 0; j < l->per; ++j) end_in_frame(c, p, particles[j], snap + 3 * j);
}
