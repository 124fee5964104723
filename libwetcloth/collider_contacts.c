#include "collider_contacts.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "alloc.h"
#include "candidates.h"
#include "narrowphase.h"
#include "parallel.h"
#include "response.h"
#include "support.h"
#include "vec3.h"

/* A contact distance of zero would leave a resting particle exactly in the
 * surface, where the side it came from is ambiguous; keep it at least this. */
#define MIN_CONTACT_DISTANCE 1e-6
/* Tests of one particle per round: enough for a particle wedged in a
 * concave corner of two or three surfaces; past it the fail-safe applies. */
#define PARTICLE_PASSES 4
/* Passes of the feature pass per round. */
#define FEATURE_PASSES 8
/* Rounds of the particle and feature passes. */
#define ROUNDS 3
/* The filter keeps a pair unless it is this much beyond the contact
 * distance (on top of r): far more than the rounding of the distances
 * behind it, far less than anything physical. */
#define FILTER_EPSILON(r) (1e-9 * (r) + 1e-12)
/* A cloth whose box is farther from every collider than APART_BECOMES
 * times the contact distance skips the stage; it stays apart while that is
 * more than APART_STAYS times it (see wci_collider_contacts_resolve). */
#define APART_BECOMES 2.0
#define APART_STAYS 1.001
/* A particle's direct query (when it has left its lists' cover mid-pass)
 * keeps this many triangles on the stack. */
#define DIRECT_STACK 256

struct wc_collider_contacts {
    wc_cloth_elements el;
    /// Per collider (by index): the candidates; made at first use. And its
    /// support reaches (support.h), measured while it stands still.
    wc_candidates *cand;
    wc_support *support;
    int32_t cand_count;
    /// Per particle, two each (collider, triangle; -1 for none): the
    /// triangle that held it (support.h) at the end of the last committed
    /// step, which its first test of that collider takes in this step
    /// (hint), and what holds it in this step (hint_next), which the commit
    /// makes the hint (hints_due: the stage ran in this step). Likewise a
    /// triangle that pushed the particle before its reaches were measured
    /// (want_next; want once committed), measured at the start of the next
    /// step. A failed step is taken again from the committed hints and
    /// wants, with the bits of a run that never failed.
    int32_t *hint, *hint_next, *want, *want_next;
    int hints_due;
    int use_filter, whole_collider, sharp_only, use_support;
    /// Between rounds: recheck (the particle pass must test the particle
    /// again) and shifted (the feature pass must visit its elements).
    uint8_t *recheck, *shifted;
    /// Moved since the start of the last recheck (see
    /// wci_collider_contacts_recheck).
    uint8_t *changed;
    /// Per particle: surface motion of the last face the particle pass
    /// answered for it, and of the collider feature that last pushed it
    /// (the fail-safes carry the particle along by them).
    double *carry;
    /// Feature pass: particles moved by the previous pass and by the one
    /// being run, as flags and lists.
    uint8_t *moved, *moving;
    int32_t *moved_list, *moving_list;
    int32_t moved_count, moving_count;
    /// Particles to rebase (list, and a flag so each is listed once).
    int32_t *rebase_list;
    uint8_t *rebase_flag;
    int32_t rebase_count;
    /// Per element scratch: a mark and a list.
    uint8_t *visit_mark;
    int32_t *visit_list;
    /// The feature pass' survivors of one element (positions in its list)
    /// and the distance measured for each (snapshots); room for kept_capacity.
    int32_t *kept;
    double *measured;
    /// What each measured distance is kept less in its list (a sharp
    /// feature's shift, candidates.h).
    double *measured_less;
    int32_t kept_capacity;
    /// Per particle: its motion over the step (start to end, as it is).
    double *motion;
    /// Exact tests of feature pairs, and of particles against faces, run so
    /// far.
    int64_t feature_tests, face_tests;
    /// Whether the last resolve found the cloth apart from every collider
    /// (cloth_apart) and ran no pass: the candidates are then forgotten,
    /// made again when it comes near. use_apart: the test switch; how many
    /// resolves were skipped so.
    int apart, use_apart;
    int64_t apart_steps;
};

/* ------------------------------------------------------------------------ */
/* Motion                                                                   */
/* ------------------------------------------------------------------------ */

/* How far particle i moves over the step, m. */
static double step_motion(const wc_particle_arrays *p, int32_t i)
{
    double u[3] = {p->nx[i] - p->x[i], p->ny[i] - p->y[i], p->nz[i] - p->z[i]};
    return sqrt(dot3(u, u));
}

/* Particle i's end of step has moved: its motion over the step noted, and
 * the change for wci_collider_contacts_recheck. Touches only particle i's
 * entries (safe in the parallel particle pass). */
static void track(wc_collider_contacts *s, const wc_particle_arrays *p, int32_t i)
{
    s->motion[i] = step_motion(p, i);
    s->changed[i] = 1;
}

/* ------------------------------------------------------------------------ */
/* The cloth's elements                                                     */
/* ------------------------------------------------------------------------ */

static int compare_edge(const void *pa, const void *pb)
{
    const int32_t *p = pa, *q = pb;
    for (int k = 0; k < 3; ++k)
        if (p[k] != q[k]) return p[k] < q[k] ? -1 : 1;
    return 0;
}

/* Inverts a list of elements (`per` particles each) into, per particle,
 * the elements it belongs to, ascending; 0 on out-of-memory. */
static int invert_elements(const int32_t *particles, int per, int32_t count, int32_t particle_count,
                           int32_t **start_out, int32_t **items_out)
{
    int32_t *start = wci_alloc_array((size_t)particle_count + 1, sizeof *start);
    int32_t *items = wci_alloc_array((size_t)per * (size_t)count + 1, sizeof *items);
    *start_out = start, *items_out = items;
    if (!start || !items) return 0;
    for (size_t k = 0; k < (size_t)per * (size_t)count; ++k) start[particles[k] + 1]++;
    for (int32_t i = 0; i < particle_count; ++i) start[i + 1] += start[i];
    for (int32_t e = 0; e < count; ++e)
        for (int p = 0; p < per; ++p) {
            int32_t i = particles[(size_t)per * (size_t)e + (size_t)p];
            items[start[i]++] = e; /* start[i] advances as i's slots fill; undone below */
        }
    for (int32_t i = particle_count; i > 0; --i) start[i] = start[i - 1];
    start[0] = 0;
    return 1;
}

/* The unique edges of the cloth's triangles, lower index first, sorted. */
static int build_edges(wc_cloth_elements *el)
{
    int32_t nt = el->triangle_count;
    int32_t *entries = wci_alloc_array(9 * (size_t)nt + 1, sizeof *entries);
    el->edges = wci_alloc_array(6 * (size_t)nt + 1, sizeof *el->edges);
    if (!entries || !el->edges) {
        wci_free(entries);
        return 0;
    }
    for (int32_t t = 0; t < nt; ++t)
        for (int k = 0; k < 3; ++k) {
            int32_t a = el->triangles[3 * t + k], b = el->triangles[3 * t + (k + 1) % 3];
            int32_t *e = entries + 3 * (3 * (size_t)t + k);
            e[0] = a < b ? a : b, e[1] = a < b ? b : a, e[2] = 3 * t + k;
        }
    qsort(entries, 3 * (size_t)nt, 3 * sizeof *entries, compare_edge);
    for (int32_t k = 0; k < 3 * nt; ++k) {
        const int32_t *e = entries + 3 * (size_t)k;
        if (k > 0 && e[0] == e[-3] && e[1] == e[-2]) continue;
        el->edges[2 * el->edge_count] = e[0];
        el->edges[2 * el->edge_count + 1] = e[1];
        ++el->edge_count;
    }
    wci_free(entries);
    return 1;
}

wc_collider_contacts *wci_collider_contacts_create(const wc_cloth *c)
{
    wc_collider_contacts *s = wci_alloc_array(1, sizeof *s);
    if (!s) return NULL;
    size_t n = (size_t)c->particle_count;
    s->use_filter = 1;
    s->use_apart = 1;
    s->use_support = 1;
    s->el.particle_count = c->particle_count;
    s->el.triangle_count = c->topology.triangle_count;
    s->el.triangles = c->topology.triangles;
    int ok = build_edges(&s->el) &&
             invert_elements(s->el.triangles, 3, s->el.triangle_count, c->particle_count,
                             &s->el.triangles_start, &s->el.triangles_of) &&
             invert_elements(s->el.edges, 2, s->el.edge_count, c->particle_count,
                             &s->el.edges_start, &s->el.edges_of);
    size_t most = (size_t)(s->el.triangle_count > s->el.edge_count ? s->el.triangle_count
                                                                   : s->el.edge_count) + 1;
    s->recheck = wci_alloc_array(n, 1);
    s->changed = wci_alloc_array(n, 1);
    s->shifted = wci_alloc_array(n, 1);
    s->carry = wci_alloc_array(3 * n, sizeof *s->carry);
    s->moved = wci_alloc_array(n, 1);
    s->moving = wci_alloc_array(n, 1);
    s->moved_list = wci_alloc_array(n, sizeof *s->moved_list);
    s->moving_list = wci_alloc_array(n, sizeof *s->moving_list);
    s->rebase_list = wci_alloc_array(n, sizeof *s->rebase_list);
    s->rebase_flag = wci_alloc_array(n, 1);
    s->visit_mark = wci_alloc_array(most, 1);
    s->visit_list = wci_alloc_array(most, sizeof *s->visit_list);
    s->motion = wci_alloc_array(n, sizeof *s->motion);
    s->hint = wci_alloc_array(2 * n, sizeof *s->hint);
    s->hint_next = wci_alloc_array(2 * n, sizeof *s->hint_next);
    s->want = wci_alloc_array(2 * n, sizeof *s->want);
    s->want_next = wci_alloc_array(2 * n, sizeof *s->want_next);
    if (!ok || !s->motion || !s->recheck || !s->changed || !s->shifted || !s->carry || !s->moved || !s->moving ||
        !s->moved_list || !s->moving_list || !s->rebase_list || !s->rebase_flag ||
        !s->visit_mark || !s->visit_list || !s->hint || !s->hint_next || !s->want || !s->want_next) {
        wci_collider_contacts_destroy(s);
        return NULL;
    }
    for (size_t k = 0; k < 2 * n; ++k) s->hint[k] = s->hint_next[k] = s->want[k] = s->want_next[k] = -1;
    return s;
}

void wci_collider_contacts_destroy(wc_collider_contacts *s)
{
    if (!s) return;
    for (int32_t k = 0; k < s->cand_count; ++k) {
        wci_candidates_destroy(&s->cand[k]);
        wci_support_destroy(&s->support[k]);
    }
    void *blocks[] = {s->cand, s->support, s->hint, s->hint_next, s->want, s->want_next,
                      s->el.edges, s->el.triangles_start, s->el.triangles_of,
                      s->el.edges_start, s->el.edges_of, s->recheck, s->changed, s->shifted, s->carry,
                      s->moved, s->moving, s->moved_list, s->moving_list, s->rebase_list,
                      s->rebase_flag, s->visit_mark, s->visit_list, s->kept, s->measured,
                      s->measured_less, s->motion};
    for (size_t k = 0; k < sizeof blocks / sizeof blocks[0]; ++k) wci_free(blocks[k]);
    wci_free(s);
}

void wci_collider_contacts_commit(wc_collider_contacts *s, int32_t particle_count)
{
    for (int32_t k = 0; k < s->cand_count; ++k) wci_candidates_commit(&s->cand[k], particle_count);
    if (s->hints_due) {
        memcpy(s->hint, s->hint_next, 2 * (size_t)particle_count * sizeof *s->hint);
        memcpy(s->want, s->want_next, 2 * (size_t)particle_count * sizeof *s->want);
    }
    s->hints_due = 0;
}

void wci_collider_contacts_use_filter(wc_collider_contacts *s, int use) { s->use_filter = use; }

void wci_collider_contacts_use_local_motion(wc_collider_contacts *s, int use) { s->whole_collider = !use; }

void wci_collider_contacts_use_smooth_features(wc_collider_contacts *s, int use)
{
    s->sharp_only = !use;
    /* the lists are made again, at the next step, with the distances chosen */
    for (int32_t k = 0; k < s->cand_count; ++k) s->cand[k].r = 0.0;
}

int wci_collider_contacts_smooth_features(const wc_collider_contacts *s, int32_t collider)
{
    return collider >= 0 && collider < s->cand_count && s->cand[collider].smooth_features;
}

void wci_collider_contacts_use_apart(wc_collider_contacts *s, int use) { s->use_apart = use; }

int64_t wci_collider_contacts_apart_steps(const wc_collider_contacts *s) { return s->apart_steps; }

int64_t wci_collider_contacts_feature_tests(const wc_collider_contacts *s) { return s->feature_tests; }

void wci_collider_contacts_use_support(wc_collider_contacts *s, int use) { s->use_support = use; }

int64_t wci_collider_contacts_face_tests(const wc_collider_contacts *s) { return s->face_tests; }

int32_t wci_collider_contacts_uncovered(const wc_collider_contacts *s, const wc_cloth *c)
{
    /* between steps a particle is where the last step ended: its start and
     * end are both that (the end arrays hold the step's leftovers) */
    wc_particle_arrays p = wci_particle_arrays_of((wc_cloth *)c);
    p.nx = (double *)p.x, p.ny = (double *)p.y, p.nz = (double *)p.z;
    int32_t n = 0;
    for (int32_t k = 0; k < s->cand_count; ++k) {
        const wc_candidates *cand = &s->cand[k];
        if (!(cand->r > 0.0)) continue; /* never made: no lists to cover */
        for (int32_t i = 0; i < c->particle_count; ++i)
            n += !wc_candidates_covers(cand, i, wci_candidates_displacement(cand, &p, i));
    }
    return n;
}

/* ------------------------------------------------------------------------ */
/* Candidates                                                               */
/* ------------------------------------------------------------------------ */

static double contact_distance(const wc_cloth *c, const wc_collider *col)
{
    double r = c->material.thickness + col->thickness;
    return r < MIN_CONTACT_DISTANCE ? MIN_CONTACT_DISTANCE : r;
}

static int grow_candidates(wc_collider_contacts *s, int32_t count)
{
    if (count <= s->cand_count) return 1;
    wc_candidates *grown = wci_alloc_array((size_t)count, sizeof *grown);
    wc_support *support = wci_alloc_array((size_t)count, sizeof *support);
    if (!grown || !support) {
        wci_free(grown), wci_free(support);
        return 0;
    }
    memset(grown, 0, (size_t)count * sizeof *grown);
    memset(support, 0, (size_t)count * sizeof *support);
    if (s->cand_count) {
        memcpy(grown, s->cand, (size_t)s->cand_count * sizeof *grown);
        memcpy(support, s->support, (size_t)s->cand_count * sizeof *support);
    }
    wci_free(s->cand), wci_free(s->support);
    s->cand = grown, s->support = support, s->cand_count = count;
    return 1;
}

static void note_rebase(wc_collider_contacts *s, int32_t i)
{
    if (s->rebase_flag[i]) return;
    s->rebase_flag[i] = 1;
    s->rebase_list[s->rebase_count++] = i;
}

/* Which particles to rebase against a collider, looked at on every thread:
 * with `only_shifted` those the particle pass moved (s->shifted) whose
 * motion has left their cover, else those due a rebase ahead of the step
 * (wc_candidates_rebase_due). Flags them in s->rebase_flag. */
typedef struct rebase_scan {
    wc_collider_contacts *s;
    const wc_candidates *cand;
    const wc_particle_arrays *p;
    int only_shifted;
} rebase_scan;

static int rebase_scan_range(void *context, int64_t begin, int64_t end)
{
    const rebase_scan *scan = context;
    wc_collider_contacts *s = scan->s;
    for (int64_t i = begin; i < end; ++i) {
        if (scan->only_shifted && !s->shifted[i]) continue;
        double d = wci_candidates_displacement(scan->cand, scan->p, (int32_t)i);
        s->rebase_flag[i] = scan->only_shifted ? !wc_candidates_covers(scan->cand, (int32_t)i, d)
                                               : wc_candidates_rebase_due(scan->cand, (int32_t)i, d);
    }
    return 0;
}

/* Notes, in ascending order, the particles that rebase_scan_range flags
 * (no particle is noted when it runs). */
static void note_scanned(wc_collider_contacts *s, const wc_candidates *cand,
                         const wc_particle_arrays *p, int32_t n, int only_shifted, int threads)
{
    rebase_scan scan = {s, cand, p, only_shifted};
    wci_parallel_for(n, wc_threads_for(n, threads), rebase_scan_range, &scan);
    for (int32_t i = 0; i < n; ++i)
        if (s->rebase_flag[i]) s->rebase_list[s->rebase_count++] = i;
}

/* Rebases the noted particles against collider k and clears the notes. */
static wc_status flush_rebase(wc_collider_contacts *s, const wc_collider *col, int32_t k,
                              const wc_particle_arrays *p, int32_t steps_left, int threads)
{
    wc_status st = WC_OK;
    if (s->rebase_count)
        st = wci_candidates_rebase(&s->cand[k], &s->el, col, s->rebase_list, s->rebase_count, p,
                                  steps_left, s->visit_mark, threads);
    for (int32_t j = 0; j < s->rebase_count; ++j) s->rebase_flag[s->rebase_list[j]] = 0;
    s->rebase_count = 0;
    return st;
}

/* Before the passes: the lists of every mesh collider made (first use, or
 * a new contact distance) or brought up to date for the particles whose
 * motion in this step leaves their cover. */
static wc_status refresh_candidates(wc_collider_contacts *s, const wc_cloth *c,
                                    wc_collider *const *colliders, int32_t count,
                                    const wc_particle_arrays *p, int32_t steps_left, int threads)
{
    if (!grow_candidates(s, count)) return WC_ERROR_OUT_OF_MEMORY;
    for (int32_t k = 0; k < count; ++k) {
        const wc_collider *col = colliders[k];
        if (!col->is_mesh) continue;
        wc_candidates *cand = &s->cand[k];
        cand->whole_collider = s->whole_collider;
        cand->sharp_only = s->sharp_only;
        double r = contact_distance(c, col);
        if (cand->r != r) {
            if (wci_candidates_update(cand, &s->el, col, r, p, steps_left, threads))
                return WC_ERROR_OUT_OF_MEMORY;
        } else {
            wci_candidates_local_motion(cand, &s->el, col, threads);
        }
        if (!col->moving && wci_support_prepare(&s->support[k], col, r)) return WC_ERROR_OUT_OF_MEMORY;
        note_scanned(s, cand, p, c->particle_count, 0, threads);
        if (flush_rebase(s, col, k, p, steps_left, threads)) return WC_ERROR_OUT_OF_MEMORY;
    }
    return WC_OK;
}

/* ------------------------------------------------------------------------ */
/* Particle pass                                                            */
/* ------------------------------------------------------------------------ */

/* What one particle's tests share. */
typedef struct particle_run {
    const wc_particle_arrays *p;
    int32_t i;
    double start[3];
    double mu_cloth, q;
    int touched;
    double last_motion[3];
    /// The collider (index, -1 for none) and its triangle that hold the
    /// particle at held_end (support.h), found in this round; and one whose
    /// reach was wanted for that but not yet measured (2 t + side).
    int32_t held_by, held_triangle, want_by, want_triangle;
    double held_end[3];
    /// Exact tests run.
    int64_t tests;
} particle_run;

static void end_now(const particle_run *run, double end[3])
{
    const wc_particle_arrays *p = run->p;
    end[0] = p->nx[run->i], end[1] = p->ny[run->i], end[2] = p->nz[run->i];
}

/* Answers a touch the narrowphase found; returns whether it moved the
 * particle. */
static int answer_particle(particle_run *run, wc_contact *k, const wc_collider *col)
{
    uint8_t moved[4];
    wc_response_options none = {0.0};
    k->friction = sqrt(run->mu_cloth * col->friction);
    k->wet_friction = run->q;
    if (!wci_response_apply(run->p, k, &none, NULL, moved)) return 0;
    run->touched = 1;
    for (int m = 0; m < 3; ++m) run->last_motion[m] = k->surface_motion[m];
    return 1;
}

/* Whether triangle t of collider k holds the particle where it is now
 * (support.h): then no triangle of that collider can touch it until it
 * moves again, and the hint for the next step is t. */
static int held(particle_run *run, const wc_support *support, const wc_collider *col, int32_t k, int32_t t)
{
    double end[3];
    end_now(run, end);
    int side = wci_support_side(col, t, run->start);
    if (!wci_support_measured(support, t, side)) {
        run->want_by = k, run->want_triangle = 2 * t + side;
        return 0;
    }
    if (!wci_support_holds(support, col, t, run->start, end)) return 0;
    run->held_by = k, run->held_triangle = t;
    memcpy(run->held_end, end, sizeof end);
    return 1;
}

/* Whether the particle is still where a collider held it. */
static int still_held(const particle_run *run, int32_t k)
{
    const wc_particle_arrays *p = run->p;
    int32_t i = run->i;
    return run->held_by == k && p->nx[i] == run->held_end[0] && p->ny[i] == run->held_end[1] &&
           p->nz[i] == run->held_end[2];
}

/* Triangle t against the particle's motion as it is now; *end_d2 gets a
 * lower bound on the square of their distance at the end of the step
 * (wci_narrow_particle_triangle). */
static int test_triangle(particle_run *run, const wc_collider *col, int32_t t, double r, double *end_d2)
{
    double end[3];
    wc_contact k;
    end_now(run, end);
    ++run->tests;
    if (!wci_narrow_particle_triangle(col, t, run->i, run->start, end, r, end_d2, &k)) return 0;
    return answer_particle(run, &k, col);
}

/* Which pairs get the exact test, and in which order. The answer must not
 * depend on the candidates' state (where and when particles were rebased,
 * how large their margins are): a failed step leaves that state changed,
 * and the retry must give the bits of a run that never failed. So an owner's
 * pairs are tested in ascending order of the collider item, exactly as if
 * every item of the collider were tested in turn against the state as it is
 * then: the lists and the filter only leave out items that cannot touch at
 * their turn. After a push the particle has moved, so the items after the
 * one that pushed are gathered again with the new bound. Against a static
 * mesh collider, the triangle that held the particle at the last committed
 * step goes first, and a triangle that holds it (support.h) ends its tests
 * of that collider: no other triangle can touch it then. Which triangle that
 * is depends only on the committed state and the step's own motion, never on
 * the candidates'. */

/* Gathers position j of a list into out if its bound d is within `bound`,
 * and otherwise lowers *least to d; returns the new count. */
static int32_t gather_one(int32_t j, double d, double bound, int32_t *out, int32_t n, double *least)
{
    int keep = !(d > bound);
    double other = keep ? INFINITY : d;
    out[n] = j;
    *least = other < *least ? other : *least;
    return n + keep;
}

/* The position of the first of the ascending items[0 .. count) above
 * `after` (count if none; 0 for after < 0). */
static int32_t first_after(const int32_t *items, int32_t count, int32_t after)
{
    int32_t lo = 0, hi = count;
    while (lo < hi) {
        int32_t mid = lo + (hi - lo) / 2;
        if (items[mid] <= after) lo = mid + 1;
        else hi = mid;
    }
    return lo;
}

/* Positions in owner k's list (ascending by item) of the items after
 * `after` whose bound d is within `bound` (all of them when `all`), into out,
 * which has room for the whole list; returns how many. *rest gets the least
 * d of the items after `after` that were not gathered (INFINITY if none):
 * what a renewal needs to know of the items it does not measure. */
static int32_t survivors(const wc_pair_lists *l, int32_t k, double bound, int all, int32_t after,
                         int32_t *out, double *rest)
{
    *rest = INFINITY;
    if (l->count[k] == 0) return 0; /* (the pool may not exist yet) */
    const int32_t *item = l->item + l->start[k];
    const double *d = l->d + l->start[k];
    int32_t n = 0, count = l->count[k], j = first_after(item, count, after);
    if (!all) {
        /* Only the bounds are read, from the first item after `after` on
         * (a gathering after a push starts there: the items are
         * ascending), without a branch (which items the filter keeps
         * changes from visit to visit, and mispredicted skips made this
         * scan a tenth of a dense collider's step), and into four running
         * minima (one would chain every item's compare to the last one's;
         * the least of a set is the same however grouped). */
        double least[4] = {INFINITY, INFINITY, INFINITY, INFINITY};
        for (; j + 4 <= count; j += 4) {
            n = gather_one(j, d[j], bound, out, n, &least[0]);
            n = gather_one(j + 1, d[j + 1], bound, out, n, &least[1]);
            n = gather_one(j + 2, d[j + 2], bound, out, n, &least[2]);
            n = gather_one(j + 3, d[j + 3], bound, out, n, &least[3]);
        }
        for (; j < count; ++j) n = gather_one(j, d[j], bound, out, n, &least[0]);
        double a = least[0] < least[1] ? least[0] : least[1], b = least[2] < least[3] ? least[2] : least[3];
        *rest = a < b ? a : b;
        return n;
    }
    for (; j < count; ++j) out[n++] = j;
    return n;
}

/* The collider triangles after `after` whose boxes meet the particle's
 * motion grown by r, from the tree, in turn; after a push the motion has
 * changed and the tree is asked again. For a particle outside its lists'
 * cover (or when the room for its survivors cannot be had). */
static int direct_triangles(particle_run *run, const wc_collider *col, double r, int32_t after)
{
    int moved = 0;
    for (;;) {
        double end[3], box[6];
        end_now(run, end);
        for (int k = 0; k < 3; ++k) {
            box[k] = (run->start[k] < end[k] ? run->start[k] : end[k]) - r;
            box[k + 3] = (run->start[k] < end[k] ? end[k] : run->start[k]) + r;
        }
        int32_t stack[DIRECT_STACK], *found = stack;
        int32_t n = wci_bvh_query(&col->bvh, box, stack, DIRECT_STACK);
        if (n > DIRECT_STACK) {
            found = wci_alloc_array((size_t)n, sizeof *found);
            if (!found) {
                /* no room for the list: every triangle in turn */
                double unused;
                for (int32_t t = after + 1; t < col->triangle_count; ++t)
                    moved |= test_triangle(run, col, t, r, &unused);
                return moved;
            }
            wci_bvh_query(&col->bvh, box, found, n);
        }
        int32_t pushed = -1;
        double unused;
        for (int32_t j = 0; j < n && pushed < 0; ++j)
            if (found[j] > after && test_triangle(run, col, found[j], r, &unused)) pushed = found[j];
        if (found != stack) wci_free(found);
        if (pushed < 0) return moved;
        moved = 1, after = pushed;
    }
}

/* What one visit of a particle's list measured, for the snapshot it
 * leaves: list positions, the squared distances found there (lower bounds,
 * at the particle's end when measured), and how far its end had been moved
 * by pushes before each measurement. */
typedef struct particle_measures {
    int32_t at[DIRECT_STACK];
    double d2[DIRECT_STACK], moved_before[DIRECT_STACK];
    int32_t n;
    /// How far pushes have moved the particle's end in this visit, summed.
    double moved;
    /// The least bound of the items not gathered, over the gatherings.
    double rest;
    /// Whether every test was recorded (there was room).
    int complete;
} particle_measures;

/* After a visit of particle i's list: its snapshot renewed at the particle's
 * end (candidates.h, snapshots). A measurement taken before a push keeps as
 * bound its distance less how far the pushes after it moved the end (the
 * distance is 1-Lipschitz in the particle's place), so a visit that pushed
 * renews too: a particle resting on a collider is pushed back at nearly
 * every step, and its list measured from its base would keep every
 * triangle within r plus its drift from the base a survivor (dozens on a
 * dense collider). The same bits: the filter only leaves out what cannot
 * touch. */
static void renew_particle(const wc_candidates *cand, const wc_particle_arrays *p, int32_t i,
                           particle_measures *m)
{
    wc_pair_lists *l = (wc_pair_lists *)&cand->particles;
    for (int32_t j = 0; j < m->n; ++j) {
        double owed = m->moved - m->moved_before[j];
        if (owed > 0.0) {
            double b = sqrt(m->d2[j]) - owed;
            m->d2[j] = b > 0.0 ? b * b : 0.0;
        }
    }
    double now = wc_candidates_path_now(cand, i), step = cand->local_step[i];
    double end_drift = wci_pair_lists_end_drift(cand, l, i, &i, p) + (now - l->path_at[i]);
    /* the collider counted from before this step, which may yet be refused
     * and taken again (as in visit_element) */
    wci_pair_lists_renew(cand, l, i, &i, p, now - 2.0 * step, m->at, m->d2, NULL, m->n, m->rest, end_drift,
                        wci_candidates_ceiling(cand, cand->r, &i, 1, p));
}

/* One mesh collider against the particle: first the triangle that held it
 * at the last committed step, then the items of its list that the filter
 * keeps (candidates.h), in turn, with the bound measured from the list's
 * snapshot, until a triangle holds it (support.h); a visit that measured
 * the whole list renews the snapshot. */
static int mesh_particle(particle_run *run, const wc_collider_contacts *s, int32_t k,
                         const wc_collider *col, double r)
{
    const wc_particle_arrays *p = run->p;
    const wc_candidates *cand = &s->cand[k];
    const wc_pair_lists *l = &cand->particles;
    int32_t i = run->i, after = -1, stack[DIRECT_STACK], *kept = stack, room = DIRECT_STACK;
    if (still_held(run, k)) return 0;
    const wc_support *support =
        s->use_support && wci_support_ready(&s->support[k], col, r) ? &s->support[k] : NULL;
    int moved = 0, use_filter = s->use_filter;
    const int32_t *hint = s->hint + 2 * (size_t)i;
    if (support && hint[0] == k && hint[1] < col->triangle_count) {
        /* the triangle that held the particle at the last step first: on a
         * convex collider it holds it again, and nothing else is tested */
        double unused;
        moved = test_triangle(run, col, hint[1], r, &unused);
        if (held(run, support, col, k, hint[1])) return moved;
    }
    double drift = wc_candidates_path_now(cand, i) - l->path_at[i];
    particle_measures m;
    m.n = 0, m.moved = 0.0, m.rest = INFINITY, m.complete = use_filter;
    for (;;) {
        double d = wci_candidates_displacement(cand, p, i);
        if (!wc_candidates_covers(cand, i, d)) {
            m.complete = 0;
            moved |= direct_triangles(run, col, r, after);
            break;
        }
        if (l->count[i] > room) {
            /* A longer list than the stack holds: a UV sphere's pole
             * gathers hundreds of slivers within r of a particle. Room for
             * the whole list is still far cheaper than asking the tree for
             * the motion's box, which finds more of them, unsorted (the
             * 30,624-triangle sphere's pole: 530-870 triangles a query). */
            int32_t *grown = wci_alloc_array((size_t)l->count[i], sizeof *grown);
            if (!grown) {
                m.complete = 0;
                moved |= direct_triangles(run, col, r, after);
                break;
            }
            if (kept != stack) wci_free(kept);
            kept = grown, room = l->count[i];
        }
        double near2 = wci_pair_lists_drift2(cand, l, i, &i, p);
        /* nothing in the list can touch (the hanging part of a draped
         * cloth): no scan, and the old snapshot kept, whose bound is the
         * displacement from it rather than the path since; least > reach
         * compared on squares, as in visit_element */
        double still = r + drift + l->debt[i] + FILTER_EPSILON(r); /* the reach less near */
        double clear = l->least[i] - still;
        if (use_filter && after < 0 && clear > 0.0 && clear * clear > near2) {
            m.complete = 0;
            break;
        }
        double reach = still + sqrt(near2), rest;
        int32_t n = survivors(l, i, reach, !use_filter, after, kept, &rest);
        if (rest < m.rest) m.rest = rest;
        if (n == 0) break;
        const int32_t *item = l->item + l->start[i];
        int32_t pushed = -1;
        double before[3] = {p->nx[i], p->ny[i], p->nz[i]};
        for (int32_t j = 0; j < n && pushed < 0; ++j) {
            double d2;
            if (test_triangle(run, col, item[kept[j]], r, &d2)) {
                /* not measured: it keeps its bound, and counts among the
                 * least of what the renewal does not measure */
                pushed = item[kept[j]];
                if (l->d[l->start[i] + kept[j]] < m.rest) m.rest = l->d[l->start[i] + kept[j]];
            } else if (m.n < DIRECT_STACK) {
                m.at[m.n] = kept[j], m.d2[m.n] = d2, m.moved_before[m.n] = m.moved;
                ++m.n;
            } else {
                m.complete = 0;
            }
        }
        if (pushed < 0) break;
        moved = 1, after = pushed;
        if (support && held(run, support, col, k, pushed)) {
            m.complete = 0; /* the items after it were not measured */
            break;
        }
        double shift[3] = {p->nx[i] - before[0], p->ny[i] - before[1], p->nz[i] - before[2]};
        m.moved += sqrt(shift[0] * shift[0] + shift[1] * shift[1] + shift[2] * shift[2]);
    }
    if (kept != stack) wci_free(kept);
    if (m.complete) renew_particle(cand, p, i, &m);
    return moved;
}

/* Particle i against every collider, up to PARTICLE_PASSES times; returns
 * 1 if it was still being moved after the last (fail-safe), and sets
 * *touched. */
static int particle_passes(wc_collider_contacts *s, const wc_cloth *c, wc_collider *const *colliders,
                           int32_t count, particle_run *run)
{
    const wc_particle_arrays *p = run->p;
    int moved = 1;
    for (int pass = 0; pass < PARTICLE_PASSES && moved; ++pass) {
        moved = 0;
        for (int32_t k = 0; k < count; ++k) {
            const wc_collider *col = colliders[k];
            double r = contact_distance(c, col);
            if (col->is_mesh) {
                moved |= mesh_particle(run, s, k, col, r);
            } else {
                double end[3];
                wc_contact ct;
                end_now(run, end);
                if (wci_narrow_particle_convex(col, run->i, run->start, end, r, &ct))
                    moved |= answer_particle(run, &ct, col);
            }
        }
    }
    (void)p;
    return moved;
}

/* What held the particle in this step, and what it wanted measured, for
 * the commit to keep (touches only particle run->i's entries). */
static void note_hints(wc_collider_contacts *s, const particle_run *run)
{
    int32_t *hint = s->hint_next + 2 * (size_t)run->i, *want = s->want_next + 2 * (size_t)run->i;
    if (run->held_by >= 0) hint[0] = run->held_by, hint[1] = run->held_triangle;
    if (run->want_by >= 0) want[0] = run->want_by, want[1] = run->want_triangle;
}

static int32_t particle_pass(wc_collider_contacts *s, wc_cloth *c, const wc_particle_arrays *p,
                             wc_collider *const *colliders, int32_t count, int threads, int all)
{
    int32_t n = c->particle_count, failsafe = 0;
    int64_t tests = 0;
    (void)threads;
#pragma omp parallel for schedule(dynamic, 256) num_threads(threads) if (n >= WC_PARALLEL_MIN) \
    reduction(+ : failsafe, tests)
    for (int32_t i = 0; i < n; ++i) {
        if (c->pin_slot[i] >= 0 || !(all || s->recheck[i])) continue;
        s->recheck[i] = 0;
        particle_run run;
        run.p = p, run.i = i;
        run.start[0] = c->x[i], run.start[1] = c->y[i], run.start[2] = c->z[i];
        run.mu_cloth = c->material.friction, run.q = c->material.wet_friction;
        run.touched = 0, run.held_by = -1, run.want_by = -1, run.tests = 0;
        run.last_motion[0] = run.last_motion[1] = run.last_motion[2] = 0.0;
        int stuck = particle_passes(s, c, colliders, count, &run);
        tests += run.tests;
        note_hints(s, &run);
        if (!run.touched) continue;
        if (stuck) {
            /* Still pushed around after every pass: wedged between
             * surfaces. Keep the place relative to the surface it last
             * touched that it had at the start of the step, free of
             * intersection: move with that surface (at rest if static). */
            c->nx[i] = c->x[i] + run.last_motion[0];
            c->ny[i] = c->y[i] + run.last_motion[1];
            c->nz[i] = c->z[i] + run.last_motion[2];
            c->qx[i] = c->x[i], c->qy[i] = c->y[i], c->qz[i] = c->z[i];
            c->history_override[i] = 1;
            ++failsafe;
            s->recheck[i] = 1;
        }
        for (int m = 0; m < 3; ++m) s->carry[3 * (size_t)i + m] = run.last_motion[m];
        s->shifted[i] = 1;
        track(s, p, i);
    }
    s->face_tests += tests;
    return failsafe;
}

/* ------------------------------------------------------------------------ */
/* Feature pass                                                             */
/* ------------------------------------------------------------------------ */

/* Collider vertices against cloth triangles (count 3) or collider edges
 * against cloth edges (count 2). */
typedef struct element_kind {
    int count;
    const int32_t *particles;
    const wc_pair_lists *lists;
    const int32_t *start, *of; /* per particle: its elements (CSR) */
} element_kind;

/* Largest displacement over the step of the collider feature's vertices. */
static double feature_motion(const wc_collider *col, const element_kind *kind, int32_t f)
{
    if (!col->moving) return 0.0;
    const int32_t *v = kind->count == 3 ? &f : col->edges + 2 * (size_t)f;
    int n = kind->count == 3 ? 1 : 2;
    double most2 = 0.0;
    for (int k = 0; k < n; ++k) {
        const double *a = col->current + 3 * (size_t)v[k], *b = col->next + 3 * (size_t)v[k];
        double d[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        if (dot3(d, d) > most2) most2 = dot3(d, d);
    }
    return sqrt(most2);
}

/* Notes what a push moved: for the next pass, for the particle pass, what
 * the fail-safe would carry it along by, and its motion; a particle pushed
 * out of its cover against any collider is rebased there at once, so every
 * list stays whole. */
static wc_status note_pushed(wc_collider_contacts *s, const wc_particle_arrays *p,
                             wc_collider *const *colliders, int32_t count, const wc_contact *k,
                             const uint8_t moved[4], int32_t steps_left)
{
    for (int j = 0; j < k->count; ++j) {
        if (!moved[j]) continue;
        int32_t i = k->particle[j];
        if (!s->moving[i]) s->moving[i] = 1, s->moving_list[s->moving_count++] = i;
        s->recheck[i] = 1;
        for (int m = 0; m < 3; ++m) s->carry[3 * (size_t)i + m] = k->surface_motion[m];
        track(s, p, i);
    }
    for (int32_t c = 0; c < count; ++c) {
        const wc_collider *col = colliders[c];
        if (!col->is_mesh) continue;
        for (int j = 0; j < k->count; ++j)
            if (moved[j] && !wc_candidates_covers(&s->cand[c], k->particle[j],
                                                  wci_candidates_displacement(&s->cand[c], p, k->particle[j])))
                note_rebase(s, k->particle[j]);
        if (flush_rebase(s, col, c, p, steps_left, 1)) return WC_ERROR_OUT_OF_MEMORY;
    }
    return WC_OK;
}

/* Whether a feature pair can touch, by the exact test's own threshold: a
 * proximity counts only nearer than r sqrt(1 - slack), a crossing only at
 * distance 0 (tolerance 1e-9 r). */
static double feature_reach(double r) { return r * sqrt(1.0 - WC_FEATURE_SLACK); }

/* Room for the survivors and measurements of a list of n items. */
static int feature_scratch(wc_collider_contacts *s, int32_t n)
{
    if (n <= s->kept_capacity) return 1;
    int32_t cap = 2 * n + 16;
    int32_t *kept = wci_alloc_array((size_t)cap, sizeof *kept);
    double *measured = wci_alloc_array((size_t)cap, sizeof *measured);
    double *less = wci_alloc_array((size_t)cap, sizeof *less);
    if (!kept || !measured || !less) {
        wci_free(kept), wci_free(measured), wci_free(less);
        return 0;
    }
    wci_free(s->kept), wci_free(s->measured), wci_free(s->measured_less);
    s->kept = kept, s->measured = measured, s->measured_less = less;
    s->kept_capacity = cap;
    return 1;
}

/* How far element e and the collider near it can have come from its
 * snapshot: the collider's motion near the element counts at its first
 * particle (candidates.h, local motion). */
static double element_drift(const wc_candidates *cand, const wc_pair_lists *l, int32_t e,
                            const int32_t *idx, const wc_particle_arrays *p)
{
    return wci_pair_lists_drift(cand, l, e, idx, p) + (wc_candidates_path_now(cand, idx[0]) - l->path_at[e]);
}

/* Element e against the collider features its list keeps through the
 * filter, in ascending order of the feature (see survivors), gathered again
 * after each push. A visit that pushed nothing renews the element's
 * snapshot (candidates.h). Returns 1 if it pushed anything, -1 on
 * out-of-memory. */
static int visit_element(wc_collider_contacts *s, wc_cloth *c, const wc_particle_arrays *p,
                         wc_collider *const *colliders, int32_t count, int32_t k,
                         const element_kind *kind, int32_t e, double r, int32_t steps_left)
{
    const wc_collider *col = colliders[k];
    const int32_t *idx = kind->particles + (size_t)kind->count * (size_t)e;
    const wc_pair_lists *l = kind->lists;
    const wc_candidates *cand = &s->cand[k];
    /* the lists' distances are a smooth feature's (a sharp one's d is kept
     * sharp_shift less: candidates.h), so one reach filters both */
    double reach = feature_reach(cand->feature_r) + FILTER_EPSILON(cand->feature_r);
    /* nothing in the list can touch: the cheap way out of most visits,
     * least - debt - path - drift > reach compared on squares (the filter's
     * epsilon is far above the rounding by which the two forms differ) */
    double path = wc_candidates_path_now(cand, idx[0]) - l->path_at[e];
    double most2 = wci_pair_lists_drift2(cand, l, e, idx, p);
    double clear = l->least[e] - l->debt[e] - path - reach;
    if (!s->use_filter ? l->count[e] == 0 : clear > 0.0 && clear * clear > most2) return 0;
    double drift = sqrt(most2) + path; /* element_drift, from what is at hand */
    double mu = sqrt(c->material.friction * col->friction), rest = INFINITY;
    int32_t after = -1, n = 0;
    int pushed = 0;
    for (;;) {
        /* a push may have rebased the list and grown it */
        if (!feature_scratch(s, l->count[e])) return -1;
        double motion = 0.0;
        for (int j = 0; j < kind->count; ++j)
            if (s->motion[idx[j]] > motion) motion = s->motion[idx[j]];
        n = survivors(l, e, reach + drift + l->debt[e], !s->use_filter, after, s->kept, &rest);
        int32_t hit = -1;
        for (int32_t j = 0; j < n && hit < 0; ++j) {
            int32_t f = l->item[l->start[e] + s->kept[j]];
            double fm = feature_motion(col, kind, f);
            double rf = wc_candidates_feature_distance(cand, col, kind->count == 3, f, r);
            int ccd = wci_narrow_needs_ccd(motion > fm ? motion : fm, rf);
            double d2;
            wc_contact ct;
            int touch = kind->count == 3 ? wci_narrow_vertex_triangle(p, idx, col, f, ccd, rf, &d2, &ct)
                                         : wci_narrow_edge_edge(p, idx, col, f, ccd, rf, &d2, &ct);
            /* squared: the renewal takes the root, off this loop's path */
            s->measured[j] = d2;
            s->measured_less[j] = rf > cand->feature_r ? cand->sharp_shift : 0.0;
            ++s->feature_tests;
            if (!touch) continue;
            ct.friction = mu, ct.wet_friction = c->material.wet_friction;
            uint8_t moved[4];
            wc_response_options none = {0.0};
            if (!wci_response_apply(p, &ct, &none, NULL, moved)) continue;
            if (note_pushed(s, p, colliders, count, &ct, moved, steps_left)) return -1;
            hit = f;
        }
        if (hit < 0) break;
        pushed = 1, after = hit;
        /* the push moved the element (and perhaps rebased its list) */
        drift = element_drift(cand, l, e, idx, p);
    }
    if (!pushed) {
        /* One gathering, every survivor measured at the ends as they are:
         * a fresh snapshot. (After a push the list may have been made again,
         * and what was measured before the push is of no use.) */
        double now = wc_candidates_path_now(cand, idx[0]), step = cand->local_step[idx[0]];
        double end_drift = wci_pair_lists_end_drift(cand, l, e, idx, p) + (now - l->path_at[e]);
        /* The snapshot's collider is where this step takes it, and the step
         * may yet be refused (a failed or tearing step) and taken again:
         * counted from the committed path less this step's motion, the
         * drift covers the collider from there as well as from where it
         * really goes. */
        wci_pair_lists_renew(cand, (wc_pair_lists *)l, e, idx, p, now - 2.0 * step, s->kept, s->measured,
                            cand->sharp_shift > 0.0 ? s->measured_less : NULL, n, rest, end_drift,
                            wci_candidates_ceiling(cand, cand->feature_r, idx, kind->count, p));
    }
    return pushed;
}

/* Into s->visit_list, ascending, the elements of a kind with a particle
 * the last pass moved; returns how many. */
static int32_t moved_elements(wc_collider_contacts *s, const element_kind *kind)
{
    int32_t lo = INT32_MAX, hi = -1;
    for (int32_t m = 0; m < s->moved_count; ++m) {
        int32_t i = s->moved_list[m];
        for (int32_t j = kind->start[i]; j < kind->start[i + 1]; ++j) {
            int32_t e = kind->of[j];
            s->visit_mark[e] = 1;
            if (e < lo) lo = e;
            if (e > hi) hi = e;
        }
    }
    int32_t n = 0;
    for (int32_t e = lo; e <= hi; ++e)
        if (s->visit_mark[e]) s->visit_mark[e] = 0, s->visit_list[n++] = e;
    return n;
}

/* One kind of element against collider k: all elements with candidates in
 * a first pass, else those with a particle the last pass moved, ascending.
 * Returns 1 if anything moved, -1 on out-of-memory. */
static int element_pass(wc_collider_contacts *s, wc_cloth *c, const wc_particle_arrays *p,
                        wc_collider *const *colliders, int32_t collider_count, int32_t k,
                        const element_kind *kind, int only_moved, double r, int32_t steps_left)
{
    int32_t count = only_moved ? moved_elements(s, kind) : kind->lists->owner_count;
    int moved = 0;
    for (int32_t m = 0; m < count; ++m) {
        int32_t e = only_moved ? s->visit_list[m] : m;
        if (kind->lists->count[e] == 0) continue;
        int result = visit_element(s, c, p, colliders, collider_count, k, kind, e, r, steps_left);
        if (result < 0) return -1;
        moved |= result;
    }
    return moved;
}

static void clear_marks(uint8_t *flags, const int32_t *list, int32_t *count)
{
    for (int32_t k = 0; k < *count; ++k) flags[list[k]] = 0;
    *count = 0;
}

/* The feature pass: passes over every mesh collider until nothing moves
 * (FEATURE_PASSES at most), then the fail-safe for what the last one still
 * moved. Returns 1 if anything moved, -1 on out-of-memory. */
static int feature_pass(wc_collider_contacts *s, wc_cloth *c, const wc_particle_arrays *p,
                        wc_collider *const *colliders, int32_t count, int all, int32_t steps_left,
                        int32_t *failsafe)
{
    /* the first pass looks at what the particle pass moved as if a pass of
     * its own had moved it */
    clear_marks(s->moved, s->moved_list, &s->moved_count);
    clear_marks(s->moving, s->moving_list, &s->moving_count);
    for (int32_t i = 0; i < c->particle_count && !all; ++i)
        if (s->shifted[i]) s->moved[i] = 1, s->moved_list[s->moved_count++] = i;
    memset(s->shifted, 0, (size_t)c->particle_count);
    int moved = 1, any = 0;
    for (int pass = 0; pass < FEATURE_PASSES && moved; ++pass) {
        int only_moved = pass > 0 || !all;
        clear_marks(s->moving, s->moving_list, &s->moving_count);
        moved = 0;
        for (int32_t k = 0; k < count; ++k) {
            const wc_collider *col = colliders[k];
            if (!col->is_mesh) continue;
            double r = contact_distance(c, col);
            const wc_candidates *cand = &s->cand[k];
            element_kind triangles = {3, s->el.triangles, &cand->triangles, s->el.triangles_start,
                                      s->el.triangles_of};
            element_kind edges = {2, s->el.edges, &cand->edges, s->el.edges_start, s->el.edges_of};
            int a = element_pass(s, c, p, colliders, count, k, &triangles, only_moved, r, steps_left);
            if (a < 0) return -1;
            int b = element_pass(s, c, p, colliders, count, k, &edges, only_moved, r, steps_left);
            if (b < 0) return -1;
            moved |= a | b;
        }
        uint8_t *swap = s->moved;
        s->moved = s->moving, s->moving = swap;
        int32_t *swap_list = s->moved_list, swap_count = s->moved_count;
        s->moved_list = s->moving_list, s->moved_count = s->moving_count;
        s->moving_list = swap_list, s->moving_count = swap_count;
        any |= moved;
    }
    if (!moved) return any;
    /* Fail-safe: what the last pass still had to move keeps its position
     * relative to the collider feature that last pushed it, as at the start
     * of the step (free of intersection): it moves with the feature and
     * takes its velocity (for a static collider: stays where it was, at
     * rest). */
    for (int32_t m = 0; m < s->moved_count; ++m) {
        int32_t i = s->moved_list[m];
        const double *carry = s->carry + 3 * (size_t)i;
        c->nx[i] = c->x[i] + carry[0], c->qx[i] = c->x[i];
        c->ny[i] = c->y[i] + carry[1], c->qy[i] = c->y[i];
        c->nz[i] = c->z[i] + carry[2], c->qz[i] = c->z[i];
        c->history_override[i] = 1;
        s->shifted[i] = 1;
        track(s, p, i);
        ++*failsafe;
    }
    return any;
}

/* ------------------------------------------------------------------------ */
/* The stage                                                                */
/* ------------------------------------------------------------------------ */

/* Particle and feature passes in turn until the feature pass moves nothing
 * (ROUNDS at most). The first particle pass takes every particle (all) or
 * those marked for recheck; `also` (or NULL) adds particles to the first
 * feature pass's moved set, as if the particle pass had moved them. */
static wc_status pass_rounds(wc_collider_contacts *s, wc_cloth *c, const wc_particle_arrays *p,
                             wc_collider *const *colliders, int32_t count, int32_t steps_left,
                             int threads, int all, const uint8_t *also, int32_t *failsafe)
{
    memset(s->shifted, 0, (size_t)c->particle_count);
    for (int round = 0; round < ROUNDS; ++round) {
        *failsafe += particle_pass(s, c, p, colliders, count, threads, all && round == 0);
        if (also && round == 0)
            for (int32_t i = 0; i < c->particle_count; ++i) s->shifted[i] |= also[i];
        /* particles that left their cover during the pass are rebased for
         * the feature pass and the next step */
        for (int32_t k = 0; k < count; ++k) {
            if (!colliders[k]->is_mesh) continue;
            note_scanned(s, &s->cand[k], p, c->particle_count, 1, threads);
            if (flush_rebase(s, colliders[k], k, p, steps_left, threads)) return WC_ERROR_OUT_OF_MEMORY;
        }
        int moved = feature_pass(s, c, p, colliders, count, all && round == 0, steps_left, failsafe);
        if (moved < 0) return WC_ERROR_OUT_OF_MEMORY;
        if (!moved) break;
    }
    return WC_OK;
}

/* Whether the boxes are farther apart than r along some axis. */
static int boxes_apart(const double a[6], const double b[6], double r)
{
    for (int k = 0; k < 3; ++k)
        if (a[k] - b[k + 3] > r || b[k] - a[k + 3] > r) return 1;
    return 0;
}

/* Whether the box of every particle's start and end (as it is now) is
 * farther from every collider's bounds (over the step) than `slack` times
 * the contact distance: then no particle's path, and no triangle or edge of
 * the cloth at any time of the step (a convex combination of particles),
 * comes within the contact distance of any collider feature, and nothing
 * can touch. A falling cloth or one far from every collider then costs
 * the stage one pass over its particles. A non-finite position is never
 * apart. */
static int cloth_apart(const wc_cloth *c, const wc_particle_arrays *p, wc_collider *const *colliders,
                       int32_t count, double slack)
{
    double box[6] = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
    for (int32_t i = 0; i < c->particle_count; ++i) {
        double q[6] = {p->x[i], p->y[i], p->z[i], p->nx[i], p->ny[i], p->nz[i]};
        for (int j = 0; j < 6; ++j) {
            if (!isfinite(q[j])) return 0;
            if (q[j] < box[j % 3]) box[j % 3] = q[j];
            if (q[j] > box[j % 3 + 3]) box[j % 3 + 3] = q[j];
        }
    }
    for (int32_t k = 0; k < count; ++k)
        if (!boxes_apart(box, colliders[k]->bounds, slack * contact_distance(c, colliders[k]))) return 0;
    return 1;
}

/* The reaches the last committed step wanted (support.h), measured before
 * the passes: a step taken again finds them as its first try did. */
static void measure_wanted(wc_collider_contacts *s, const wc_cloth *c, wc_collider *const *colliders,
                           int32_t count)
{
    for (int32_t i = 0; i < c->particle_count; ++i) {
        int32_t k = s->want[2 * (size_t)i], t = s->want[2 * (size_t)i + 1] / 2;
        int side = s->want[2 * (size_t)i + 1] % 2;
        if (k < 0 || k >= count) continue;
        const wc_collider *col = colliders[k];
        wc_support *support = &s->support[k];
        if (!col->is_mesh || t >= col->triangle_count) continue;
        if (wci_support_ready(support, col, contact_distance(c, col)) && !wci_support_measured(support, t, side))
            wci_support_measure(support, col, t, side);
    }
}

/* What motions_range reads. */
typedef struct motions_pass {
    wc_collider_contacts *s;
    const wc_particle_arrays *p;
} motions_pass;

/* Every particle's motion over the step, at the stage's start: no change
 * is noted (whole_stage clears the notes; every particle is looked at). */
static int motions_range(void *context, int64_t begin, int64_t end)
{
    const motions_pass *pass = context;
    for (int64_t i = begin; i < end; ++i) pass->s->motion[i] = step_motion(pass->p, (int32_t)i);
    return 0;
}

/* The stage over every particle: their motions noted, the lists made or
 * brought up to date, the passes. */
static wc_status whole_stage(wc_collider_contacts *s, wc_cloth *c, const wc_particle_arrays *p,
                             wc_collider *const *colliders, int32_t count, int32_t steps_left,
                             int threads, wc_step_stats *stats)
{
    motions_pass motions = {s, p};
    wci_parallel_for(c->particle_count, wc_threads_for(c->particle_count, threads), motions_range,
                     &motions);
    memset(s->changed, 0, (size_t)c->particle_count);
    if (refresh_candidates(s, c, colliders, count, p, steps_left, threads)) return WC_ERROR_OUT_OF_MEMORY;
    measure_wanted(s, c, colliders, count);
    int32_t failsafe = 0;
    wc_status status = pass_rounds(s, c, p, colliders, count, steps_left, threads, 1, NULL, &failsafe);
    stats->failsafe_particles += failsafe;
    return status;
}

wc_status wci_collider_contacts_resolve(wc_cloth *c, wc_collider_contacts *s,
                                       wc_collider *const *colliders, int32_t count,
                                       int32_t steps_left, int threads, wc_step_stats *stats)
{
    if (count <= 0) return WC_OK;
    wc_particle_arrays p = wci_particle_arrays_of(c);
    /* Apart by more than twice the contact distance to become apart, by more
     * than it to stay so: a cloth moving about that distance from a
     * collider does not make its lists again at every step. (A little over
     * 1 covers the rounding of the box's differences.) */
    for (int32_t j = 0; j < 2 * c->particle_count; ++j) s->hint_next[j] = s->want_next[j] = -1;
    s->hints_due = 1;
    s->apart = s->use_apart && cloth_apart(c, &p, colliders, count, s->apart ? APART_STAYS : APART_BECOMES);
    if (!s->apart) return whole_stage(s, c, &p, colliders, count, steps_left, threads, stats);
    /* lists that no step keeps up to date: made again when it comes near */
    for (int32_t k = 0; k < s->cand_count; ++k) s->cand[k].r = 0.0;
    ++s->apart_steps;
    return WC_OK;
}

/* *changed: the state's flags if any is set, else NULL. */
static void changed_flags(const wc_collider_contacts *s, int32_t n, const uint8_t **changed)
{
    *changed = NULL;
    for (int32_t i = 0; i < n && !*changed; ++i)
        if (s->changed[i]) *changed = s->changed;
}

wc_status wci_collider_contacts_recheck(wc_cloth *c, wc_collider_contacts *s,
                                       wc_collider *const *colliders, int32_t count,
                                       const uint8_t *moved, int32_t steps_left, int threads,
                                       wc_step_stats *stats, const uint8_t **changed)
{
    *changed = NULL;
    if (count <= 0) return WC_OK;
    wc_particle_arrays p = wci_particle_arrays_of(c);
    if (s->apart) {
        /* resolve ran no pass; if what moved the particles brought the
         * cloth near a collider, the whole stage runs now */
        if (cloth_apart(c, &p, colliders, count, APART_STAYS)) return WC_OK;
        s->apart = 0;
        wc_status status = whole_stage(s, c, &p, colliders, count, steps_left, threads, stats);
        changed_flags(s, c->particle_count, changed);
        return status;
    }
    int any = 0;
    for (int32_t i = 0; i < c->particle_count; ++i)
        if (moved[i]) track(s, &p, i), s->recheck[i] = 1, any = 1;
    if (!any) return WC_OK;
    memset(s->changed, 0, (size_t)c->particle_count);
    int32_t failsafe = 0;
    wc_status status = pass_rounds(s, c, &p, colliders, count, steps_left, threads, 0, moved, &failsafe);
    stats->failsafe_particles += failsafe;
    changed_flags(s, c->particle_count, changed);
    return status;
}
