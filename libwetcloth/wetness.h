/* The wet response (thesis 2.3-2.4; docs/wetness.md): adhesion of particles in
 * contact, spreading of the pull to their linked neighbours, which particles
 * are stuck, and the optional wetness dynamics (wicking, drying). Wet
 * friction lives in the collision response (collide.c), where the
 * tangential velocity is known. */
#ifndef WC_WETNESS_H
#define WC_WETNESS_H

#include "cloth.h"
#include "collider.h"

/// How far past its contact distance r a wet particle that touched a
/// collider in the last step may be and still count as touching it, as a
/// fraction of r (see wci_wet_hold_contacts).
#define WC_WET_HOLD_BAND 0.1

/// Adds the adhesion and spreading forces to cloth->fx/fy/fz, from the
/// contacts of the last step (cloth->contact and its normals). Call only
/// when cloth->wet_forces is set. Each particle gathers its own force.
void wci_wet_forces(wc_cloth *cloth, int threads);

/// After the collider passes of a step, before self-collision: a wet
/// particle that touched a collider in the last step, is not in contact now,
/// but lies within (1 + WC_WET_HOLD_BAND) r of a collider, keeps its contact
/// (kind and the normal from the nearest surface point), unmoved. Call only
/// when cloth->wet_forces is set. Each particle writes only its own entries.
void wci_wet_hold_contacts(wc_cloth *cloth, wc_collider *const *colliders, int32_t count,
                          int threads);

/// Self-collision of a wet cloth answered the vertex-face pair (vertex,
/// triangle) in this step: remember it for self-adhesion. On out-of-memory
/// sets cloth->self_touched_failed.
void wci_wet_note_self_contact(wc_cloth *cloth, int32_t vertex, int32_t triangle);

/// After the self-collision of a wet cloth: the pairs that adhere in the
/// next step, from those it answered and those that adhered in this step
/// and are still within (1 + WC_WET_HOLD_BAND) h (h the self-collision
/// thickness), with their face weights and normals at the end of the step.
/// WC_ERROR_OUT_OF_MEMORY when a buffer could not grow (nothing changed).
wc_status wci_wet_self_pairs(wc_cloth *cloth, double h);

/// Adds the self-adhesion forces of the cloth's adhesive pairs to fx, fy,
/// fz (particle arrays): per pair, -F n on the vertex and +F b_k n on the
/// face's corners (b the face weights), equal and opposite. Serial, in pair
/// order, so the sums do not depend on the thread count.
void wci_wet_self_adhesion(const wc_cloth *cloth, double *fx, double *fy, double *fz);

/// One cloth's share of a list of adhesive pairs whose indices run over
/// several cloths (the cloth group's combined cloth, cloth_group.h): its
/// wetness and area shares, its adhesion pressure, the force arrays its
/// pulls go to, and where its particles and triangles start in the pairs'
/// numbering.
typedef struct wc_wet_piece {
    const double *wetness, *area;
    /// Adhesion pressure, Pa (the cloth's material.adhesion).
    double adhesion;
    double *fx, *fy, *fz;
    int32_t first;
} wc_wet_piece;

/// The self-adhesion law over pairs that may join different pieces: pairs
/// (vertex, triangle) and their data as in wc_cloth (adhesive_pairs,
/// adhesive_data), sorted by vertex; triangles (3 per triangle) in the same
/// numbering; pieces ascending by first. Per pair F = A_v / 2 / n_v *
/// max(a_v w_v, a_f w_f) (a the pieces' adhesion, w_f the face point's
/// wetness), -F n on the vertex and +F b_k n on the corners. Serial, in
/// pair order.
void wci_wet_pair_adhesion(const int32_t *pairs, const double *data, int64_t count,
                          const int32_t *triangles, const wc_wet_piece *pieces,
                          int32_t piece_count);

/// After the collisions of a step: marks the stuck particles (wet, in
/// contact in this step and the one before) and returns their count.
int32_t wci_wet_mark_stuck(wc_cloth *cloth);

/// Wicking and drying over a step of dt, then the material refreshed for
/// the new wetness. Call only when the material wicks or dries.
void wci_wet_update(wc_cloth *cloth, double dt);

#endif
