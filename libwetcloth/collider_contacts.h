/* The cloth-against-colliders stage of a step (docs/model.md, Collisions): candidates, the
 * per-step filter, the exact tests and the response, for one cloth against
 * every collider of the world.
 *
 *  1. Candidates (candidates.h): each mesh collider keeps, per cloth, lists
 *     of the pairs that may come within the contact distance r, made from
 *     the collider's tree (broadphase.h) and kept while every particle stays
 *     within its margin of where the lists were made. Particles that left
 *     theirs are rebased first, so the passes below find the lists whole.
 *  2. Particle pass (parallel over particles: each touches only its own
 *     state): each particle's motion against the collider triangles its list
 *     keeps through the filter (a prefix of the list sorted by distance),
 *     and against the convex shapes; a touch is a contact record answered at
 *     once (response.h), and the particle is tested again, up to
 *     PARTICLE_PASSES times, since one push can bring it to another face.
 *  3. Feature pass (serial, in a fixed order: collider, element, candidate):
 *     collider vertices against cloth triangles and collider edges against
 *     cloth edges, which step 2 alone misses (a faceted solid's vertices
 *     stand proud of its faces; a thin plate's rim cuts between particles).
 *     Its first pass visits every element with candidates, a later one only
 *     those with a particle the last one moved.
 *  Steps 2 and 3 alternate, each looking only at what the other moved,
 *  until step 3 moves nothing (at most ROUNDS rounds).
 *  4. Fail-safes: a particle still pushed around after its passes keeps the
 *     place relative to the surface it last touched that it had at the start
 *     of the step (free of intersection): it moves with that surface. */
#ifndef WC_COLLIDER_CONTACTS_H
#define WC_COLLIDER_CONTACTS_H

#include "cloth.h"
#include "collider.h"

/// Per-cloth buffers of the stage. Opaque.
typedef struct wc_collider_contacts wc_collider_contacts;

/// NULL on out-of-memory.
wc_collider_contacts *wci_collider_contacts_create(const wc_cloth *cloth);
void wci_collider_contacts_destroy(wc_collider_contacts *state);

/// Resolves the cloth's motion x -> nx against every collider: moves nx,
/// sets history overrides and collider contacts (kind and normal). The
/// colliders have begun their step (wci_collider_begin_step). `steps_left`
/// is how many steps of the running advance follow this one (the
/// candidates' margins look that far ahead). Adds fail-safe particles to
/// stats. Deterministic for any thread count. WC_ERROR_OUT_OF_MEMORY on
/// out-of-memory.
wc_status wci_collider_contacts_resolve(wc_cloth *cloth, wc_collider_contacts *state,
                                       wc_collider *const *colliders, int32_t collider_count,
                                       int32_t steps_left, int threads, wc_step_stats *stats);

/// The stage again for the particles marked in moved (moved since resolve,
/// by self-collision or collision between cloths): what they touch now is
/// pushed out as in resolve, so no later pass leaves a cloth through a
/// collider. *changed gets one flag per particle for those this moved, or
/// NULL if it moved none (the flags are the state's, valid until its next
/// call). Otherwise the same contract as resolve.
wc_status wci_collider_contacts_recheck(wc_cloth *cloth, wc_collider_contacts *state,
                                       wc_collider *const *colliders, int32_t collider_count,
                                       const uint8_t *moved, int32_t steps_left, int threads,
                                       wc_step_stats *stats, const uint8_t **changed);

/// After a committed step: the candidates' local paths take the step's
/// local motion (candidates.h), and the triangles that held particles
/// become their hints for the next step (support.h).
void wci_collider_contacts_commit(wc_collider_contacts *state, int32_t particle_count);

/// For tests: 0 bounds the collider's motion near every particle by its
/// largest anywhere (the candidates' whole_collider); 1, the default, by
/// what is near.
void wci_collider_contacts_use_local_motion(wc_collider_contacts *state, int use);

/// Test switch: 1 (default) skips the pairs the filter proves apart, 0
/// gives every listed pair the exact test. The results are the same bit for
/// bit; tests compare the two.
void wci_collider_contacts_use_filter(wc_collider_contacts *state, int use);

/// Tests: whether the candidates may keep the colliders' smooth features at
/// the smooth distance (candidates.h; 1 by default). Changing it makes the
/// lists again at the next step.
void wci_collider_contacts_use_smooth_features(wc_collider_contacts *state, int use);

/// Tests: whether the lists against the collider at `collider` (its index
/// among the world's colliders) keep its smooth features at the smooth
/// distance.
int wci_collider_contacts_smooth_features(const wc_collider_contacts *state, int32_t collider);

/// Test switch: 1 (default) skips the whole stage for a step in which the
/// box of the cloth's particles (start and end) is farther than twice the
/// contact distance from every collider's bounds (a falling cloth, one far
/// from every collider), and forgets the lists, made again when it comes
/// near; 0 runs the stage at every step. The same bits either way.
void wci_collider_contacts_use_apart(wc_collider_contacts *state, int use);

/// How many resolves the stage has skipped so (tests).
int64_t wci_collider_contacts_apart_steps(const wc_collider_contacts *state);

/// How many exact tests of feature pairs (collider vertex against cloth
/// triangle, collider edge against cloth edge) the stage has run so far:
/// what the filter left (tests/test_collide.c).
int64_t wci_collider_contacts_feature_tests(const wc_collider_contacts *state);

/// Test switch: 1 (default) lets a static mesh collider's triangle that
/// holds a particle (support.h) answer for the whole collider, and tests it
/// first at the next step; 0 tests every triangle the filter keeps.
void wci_collider_contacts_use_support(wc_collider_contacts *state, int use);

/// How many exact tests of a particle against a collider face the stage has
/// run so far (tests).
int64_t wci_collider_contacts_face_tests(const wc_collider_contacts *state);

/// A test's check of the candidates' invariant: how many particles of the
/// cloth are, against some mesh collider, farther from their lists' cover
/// than it allows (wc_candidates_covers); 0 whenever the stage is between
/// steps.
int32_t wci_collider_contacts_uncovered(const wc_collider_contacts *state, const wc_cloth *cloth);

#endif
