/* Candidate pairs of one cloth against one mesh collider, found seldom and
 * filtered every step (docs/model.md, Collisions).
 *
 * Three lists, each by owner: per cloth particle the collider triangles
 * near it (the particle pass), per cloth triangle the collider vertices near
 * it and per cloth edge the collider edges near it (the feature pass). A
 * list is made from a reference configuration: its particles at their base
 * positions (where they were when they were last rebased) and the collider
 * as it was then; each pair keeps its exact distance d0 there, and a pair
 * is listed when d0 <= r + M (r the contact distance, M the largest margin
 * of the owner's particles; for the triangles' and edges' lists r is the
 * feature distance, WC_FEATURE_DISTANCE times the particles' in
 * narrowphase.h, or WC_SMOOTH_FEATURE_DISTANCE times it for a smooth
 * feature where `smooth_features` says so, and so it is in what follows). A particle's margin comes from its motion when
 * it is rebased, so a resting cloth keeps its lists for as long as it rests
 * and a falling one rebases about once per margin travelled.
 *
 * The filter and why nothing can tunnel past it. The distance between a
 * point and a triangle (or two segments, or a vertex and a triangle) changes
 * by no more than the largest displacement of any of their vertices: every
 * point of a triangle is a convex combination of its corners, so moving
 * each corner by at most D moves every point of it by at most D, and a
 * distance is 1-Lipschitz in each point. Let D_p be the largest distance of
 * the owner's particles from their base positions at the start and at the
 * end of the step, and D_c how far the collider's features near the owner
 * can have moved since the list was made (its local path, below). Motion
 * within a step is linear and the norm convex,
 * so at every time of the step the particles are within D_p of their bases.
 * Then at every time of the step
 *     distance >= d0 - D_p - D_c.
 * So a listed pair with d0 - D_p - D_c > r cannot come within r during the
 * step, hence cannot touch or cross: it is skipped for a few loads and a
 * compare. (The exact test of a feature pair counts a touch only nearer
 * than r sqrt(1 - slack), narrowphase.h, and that is its threshold.) An
 * unlisted pair had d0 > r + M, and while every particle keeps
 * D_p + D_c < its margin (checked every step, and after every response that
 * moves it), it stays beyond r for the same reason. A particle that breaks
 * that is rebased: new base, new margin, and its lists and those of its
 * triangles and edges are made again before they are used. The survivors
 * get the exact test: continuous where the pair can cross (narrowphase.c).
 *
 * Local motion. A deforming collider moves more in some places than in
 * others (a character's arm swings while the cloth rests on its back), so
 * D_c counts only the collider near the owner. At each step, particle i's
 * local step is the largest displacement of the collider triangles whose
 * boxes meet the cube of half-side T_i = r + (the largest margin of i and
 * its neighbours) + (its farthest neighbour's distance) around its base;
 * its local path sums them over the committed steps, and D_c for a list is
 * the difference of the local paths of its owner (of its first particle,
 * for a triangle or an edge) between now and when the list was made or
 * renewed. Why that suffices: call a triangle near at a step when its box
 * meets the cube. A triangle that is not near is farther than r + M from
 * the particle's base, and from every point of the particle's triangles
 * and edges at their bases (the cube reaches their farthest corner plus
 * their margins), so while the particle keeps D_p + D_c < M nothing of it
 * can touch the owner during that step. By induction over the steps, the
 * distance of any feature from the owner at its base is then at least
 * min(d0, r + M) less the local motion summed over the steps at which its
 * triangle was near, which is at most D_c: the argument above holds with
 * the local path in place of the collider's. A snapshot (below) credits
 * a measured pair with at most r + M - D (D the farthest of the owner's
 * particles from their bases at the snapshot), the distance that a
 * feature not near at a later step is known to keep from the snapshot, so
 * that a bound carried over renewals stays a bound. The cube is found by
 * a branch and bound over the collider's tree (broadphase.h); a still
 * collider costs nothing. A rebase changes bases and margins, so it makes
 * the local steps of the rebased particles and their neighbours again.
 *
 * Relative motion. A collider that carries the cloth along (a character
 * walking, a tube bending under a cloth that rides it) moves it as far as it
 * moves itself, and a bound that adds the two used a particle's margin in a
 * few steps. So each particle has a frame: a translation that follows the
 * collider near it, its step chosen at the start of each step as the
 * centre of the box of the displacements of the collider's triangles near
 * the particle. Everything above is measured in the particles' frames: a
 * base or a snapshot is a position less the frame's at that time, D_p is
 * how far the particle moved in its frame, and a particle's own step is the
 * farthest any near triangle's corner moved from its frame's step (0 for a
 * collider that only translates). Why that holds: a frame's translation
 * moves a point and its base alike, so distances in a frame are distances;
 * for a pair of an element with particles p_k (own frames U_k) and a
 * feature with vertices q_j, the point p = sum w_k p_k and the feature's
 * point q = sum v_j q_j change by sum_k w_k (dp_k - dU_k) + sum_k w_k dU_k -
 * sum_j v_j dq_j, whose norm is at most max_k |dp_k - dU_k| + max_k max_j
 * |dq_j - dU_k|: the particles' motion in their frames plus the largest of
 * their own steps. A particle's local step is therefore the largest own
 * step of it and its neighbours (an element has only those), and the rest
 * of the argument is unchanged, with each cube grown by how far the frames
 * of its particles can move in the step. A frame's step, once chosen, stays
 * for the step: a rebase recounts its neighbours' own steps against it, and
 * a local step that rises past a particle's cover rebases that particle too.
 */
#ifndef WC_CANDIDATES_H
#define WC_CANDIDATES_H

#include <stdint.h>

#include "broadphase.h"
#include "collider.h"
#include "narrowphase.h"
#include "response.h"
#include "wetcloth.h"

/// Pairs by owner: owner k's items are item[start[k] .. start[k] + count[k]),
/// ascending, each with a lower bound d[] - debt[k] on its distance in the
/// owner's snapshot. A list made again writes in place when it fits, else at
/// the end of the pool.
///
/// Snapshots. A list is made with every pair's exact distance at its
/// particles' bases (and the collider as it was then). The passes measure
/// the distance of the pairs they test anyway, so after a visit they renew
/// the owner's snapshot to the particles' present ends: tested pairs get
/// the distance just measured, the others their old bound less how far the
/// owner has moved since. That subtraction is the owner's debt, one number:
/// a renewal adds to it and writes only the pairs it measured (their
/// distance plus the debt), so its cost follows the few pairs near contact,
/// not the list (every item rewritten was 5 % of a dense collider's step).
/// A feature list is renewed after a visit that pushed nothing; a
/// particle's after every visit that tested its whole list, a measurement
/// taken before a push counting its distance less how far the pushes after
/// it moved the particle (a resting particle is pushed back at nearly every
/// step). How far an owner has moved since its snapshot is
/// the largest distance of its particles, at the start and at the end of
/// the step, from where they were at the snapshot (kept per particle of
/// the owner, `per` of them, xyz): the argument above
/// with the snapshot for the base. A displacement, not the length of the
/// path travelled: a particle resting on a collider sags under gravity and
/// is pushed back at every step, so its path grows by twice the sag per
/// step while it stays where it was. Resting pairs at the contact distance
/// are then skipped until the cloth has moved by the contact's slack (1 %
/// of r) from their snapshot, instead of being tested at every step once
/// the sag exceeds the slack.
typedef struct wc_pair_lists {
    int32_t owner_count;
    int per;
    int32_t *start, *count, *room;
    /// Per owner: the collider's path at its snapshot, the least d of its
    /// items, what is owed on every d (the bound is d - debt; 0 when the
    /// list is made) and where its `per` particles were (xyz each).
    double *path_at, *least, *debt, *snap;
    int32_t *item;
    double *d;
    int64_t used, capacity, garbage;
} wc_pair_lists;

/// One cloth against one mesh collider.
typedef struct wc_candidates {
    /// Contact distances the lists were made for: a particle's against
    /// faces, and a cloth triangle's or edge's against collider features
    /// (WC_FEATURE_DISTANCE r, or the smooth distance: smooth_features);
    /// 0 until made.
    double r, feature_r;
    /// Whether these lists keep the collider's smooth features (collider.h)
    /// at the smooth feature distance (narrowphase.h): when the cloth's
    /// longest edge, where the lists were all made, lying across a smooth
    /// edge on faces it rests on at r, comes no nearer to it than the
    /// feature distance of a sharp one (wci_candidates_update). Then
    /// feature_r is the smooth distance, and a sharp feature's d is kept
    /// `sharp_shift` less than its distance (the difference of the two
    /// distances at which the exact test counts a touch), so that one
    /// filter serves both; otherwise every feature is sharp and the shift 0.
    int smooth_features;
    double sharp_shift;
    /// A test's switch: every feature sharp.
    int sharp_only;
    /// Per particle: base position (xyz), margin, and its local path at its
    /// last rebase.
    double *base, *margin, *base_path;
    /// Per particle: its local path (summed over the committed steps, the
    /// largest displacement of the collider's triangles near it in each)
    /// and that displacement in the step being computed (see the local
    /// motion above).
    double *local_path, *local_step;
    /// Scratch per particle (zero between calls).
    uint8_t *particle_mark;
    /// Per particle: its frame, the translations summed over the committed
    /// steps, and this step's (xyz each; see relative motion above), and its
    /// own step (the local step before its neighbours' are taken in).
    double *frame, *frame_step, *own_step;
    /// Per particle: the half-side of the cube its own step was counted in.
    double *own_reach;
    /// Whether any frame has moved: until one does (a collider that stands
    /// still), every frame is 0 and is not read.
    int framed;
    /// Scratch: the particles a rebase's recount pushed out of their cover
    /// (twice the particle count).
    int32_t *again;
    /// A test's switch: every particle's local motion is the collider's
    /// largest (its step motion), as if the whole collider were near, and
    /// its frame stands still.
    int whole_collider;
    wc_pair_lists particles, triangles, edges;
    /// The lists being made (candidates.c, making lists): one maker of
    /// scratch per thread, and per list its owner and where its pairs are.
    struct wc_list_maker *makers;
    int32_t maker_count;
    struct wc_list_job *jobs;
    int32_t job_capacity;
} wc_candidates;

/// The cloth's side of the lists: its triangles and edges, and per particle
/// the triangles and edges it belongs to (CSR).
typedef struct wc_cloth_elements {
    int32_t particle_count, triangle_count, edge_count;
    const int32_t *triangles;
    int32_t *edges;
    int32_t *triangles_start, *triangles_of, *edges_start, *edges_of;
} wc_cloth_elements;

/// A zeroed wc_candidates is the empty set of lists (no memory); this frees its memory and
/// leaves it zeroed, empty again.
void wci_candidates_destroy(wc_candidates *cand);

/// Feature f's contact distance in these lists, for contact distance r: f
/// a collider vertex (a cloth triangle's list) or edge (an edge's).
static inline double wc_candidates_feature_distance(const wc_candidates *cand, const wc_collider *col,
                                                    int vertex, int32_t f, double r)
{
    int smooth = cand->smooth_features && (vertex ? col->vertex_smooth[f] : col->edge_smooth[f]);
    return (smooth ? WC_SMOOTH_FEATURE_DISTANCE : WC_FEATURE_DISTANCE) * r;
}

/// Particle i's local path by the end of the step being computed.
static inline double wc_candidates_path_now(const wc_candidates *cand, int32_t i)
{
    return cand->local_path[i] + cand->local_step[i];
}

/// Whether particle i, at displacement `d` from its base, is still covered
/// by its lists: what is unlisted stays beyond reach.
static inline int wc_candidates_covers(const wc_candidates *cand, int32_t i, double d)
{
    return d + (wc_candidates_path_now(cand, i) - cand->base_path[i]) < cand->margin[i];
}

/// The fraction of its margin a particle may use before the stage rebases
/// it ahead of a step. Rebased together before the step, neighbours moving
/// together have the lists of their shared triangles and edges made once
/// rather than once per particle; and a particle rebased while it still
/// has margin left wastes it. At half the margin (measured alternated, 12
/// frames, 1 thread, the same bits): collisions per frame 224-235 ms on
/// the bending tube, 81 on the 30,624-triangle sphere, 77-83 on the soaked
/// 2 m cloth over 16 frames, 34-36 on the 101 x 101 drape over 8; at 0.9
/// of it 184-189, 65-67, 61 and 26 (0.75: 195-202 and 70-72; 0.99: 182-184
/// and 62, with the 3,968-triangle sphere no better than at 0.9).
#define WC_REBASE_AHEAD 0.9

/// Whether particle i has used WC_REBASE_AHEAD of its margin (see there).
static inline int wc_candidates_rebase_due(const wc_candidates *cand, int32_t i, double d)
{
    return d + (wc_candidates_path_now(cand, i) - cand->base_path[i]) >= WC_REBASE_AHEAD * cand->margin[i];
}

/// This step's frame steps and local steps of every particle (see local
/// and relative motion above): the collider's triangles near particle i are
/// those whose boxes meet the cube of half-side r + (the largest margin of i
/// and its neighbours) + (its farthest neighbour's distance) + 2 S around
/// its base (S the collider's step motion); its frame's step is the centre
/// of the box of their displacements, its own step the farthest of them
/// from it, and its local step the largest own step of it and its
/// neighbours. 0 for a collider that stands still.
/// Runs on up to `threads` threads, the same values for any count.
void wci_candidates_local_motion(wc_candidates *cand, const wc_cloth_elements *el,
                                 const wc_collider *col, int threads);

/// After a committed step: every particle's local step added to its path
/// and its frame's step to its frame.
void wci_candidates_commit(wc_candidates *cand, int32_t particle_count);

/// The most a renewed snapshot of the owner with particles idx[0 .. count)
/// may credit a pair with: r + M - D, r the distance its list was made for
/// (cand->r for a particle's, cand->feature_r for a triangle's or an
/// edge's), M the largest margin of its particles, D the farthest of their
/// ends from their bases (see the local motion above).
double wci_candidates_ceiling(const wc_candidates *cand, double r, const int32_t *idx, int count,
                              const wc_particle_arrays *p);

/// Particle i's distance from its base in its frame: the larger at the
/// start (x) and at the end (nx) of the step, which by convexity bounds it
/// over the step.
double wci_candidates_displacement(const wc_candidates *cand, const wc_particle_arrays *p, int32_t i);

/// Makes every list (first use, or the contact distance changed), with
/// every particle rebased at its start-of-step position; `steps_left` is
/// how many steps of the running frame follow this one (margins). The lists
/// are made on up to `threads` threads, the same bits for any count.
/// WC_ERROR_OUT_OF_MEMORY on failure.
wc_status wci_candidates_update(wc_candidates *cand, const wc_cloth_elements *el,
                              const wc_collider *col, double r, const wc_particle_arrays *p,
                              int32_t steps_left, int threads);

/// Rebases the `count` particles listed (new base at their start-of-step
/// position and a new margin) and makes their lists and those of their
/// triangles and edges again; a neighbour whose local step that raises past
/// its cover is rebased too. `mark` is per-element scratch (zero, left
/// zero), sized for the larger of the cloth's triangle and edge counts.
wc_status wci_candidates_rebase(wc_candidates *cand, const wc_cloth_elements *el,
                               const wc_collider *col, const int32_t *particles, int32_t count,
                               const wc_particle_arrays *p, int32_t steps_left, uint8_t *mark,
                               int threads);

/// How far owner k's particles can be from where they were at its
/// snapshot, over the step (starts and ends), each in its frame.
double wci_pair_lists_drift(const wc_candidates *cand, const wc_pair_lists *l, int32_t k,
                           const int32_t *particles, const wc_particle_arrays *p);

/// Its square, without the root: a caller that only compares it with a
/// bound compares squares (the root's latency held up the feature pass'
/// quick way out of most visits).
double wci_pair_lists_drift2(const wc_candidates *cand, const wc_pair_lists *l, int32_t k,
                            const int32_t *particles, const wc_particle_arrays *p);

/// How far owner k's particles' ends are from where they were at its
/// snapshot, each in its frame.
double wci_pair_lists_end_drift(const wc_candidates *cand, const wc_pair_lists *l, int32_t k,
                               const int32_t *particles, const wc_particle_arrays *p);

/// After a visit of owner k that moved nothing: its snapshot renewed at its
/// particles' present ends and the collider's end of step. The items at
/// positions at[0 .. n) were measured, at squared distances measured2[0 ..
/// n), each kept less[j] less than its distance (NULL: 0; a sharp
/// feature's shift) and credited with at most `ceiling`
/// (wci_candidates_ceiling); the
/// others keep their bound less `drift_end` (how far owner and collider can
/// have moved from the old snapshot to now), and the least of their d is
/// `least_unmeasured` (INFINITY if none). `collider_path` is the local path
/// that the owner's drift is measured against, now.
void wci_pair_lists_renew(const wc_candidates *cand, wc_pair_lists *l, int32_t k, const int32_t *particles,
                         const wc_particle_arrays *p, double collider_path, const int32_t *at,
                         const double *measured2, const double *less, int32_t n, double least_unmeasured,
                         double drift_end, double ceiling);

/// Distance from a point to a collider triangle, vertex and edge in the
/// collider's current positions (what the lists' d0 are measured in).
double wci_candidates_particle_distance(const wc_collider *col, int32_t triangle, const double p[3]);

#endif
