/* Self-collision of one cloth over one step (docs/model.md, Collisions): vertex-face and
 * edge-edge proximity within the cloth's thickness, continuous detection of
 * the step's motion, an inelastic response with friction, and a fail-safe
 * that puts particles back where they were at the start of the step (an
 * intersection-free state) until no intersection is left. */
#ifndef WC_SELFCOLLIDE_H
#define WC_SELFCOLLIDE_H

#include "cloth.h"

/// Per-cloth buffers (broadphase grid, edge list, scratch). Opaque.
typedef struct wc_self_state wc_self_state;

/// Allocates the state for a cloth (its topology must be built: asserted).
/// NULL on out-of-memory.
wc_self_state *wci_self_state_create(const wc_cloth *cloth);
void wci_self_state_destroy(wc_self_state *state);

/// Several cloths as pieces of one combined cloth (cloth_group.h): piece k
/// holds particles [first[k], first[k + 1]). Pairs of two pieces are always
/// tested and keep the full thickness (their distance at rest means
/// nothing); pairs within piece k only when self[k]. A pair's friction is
/// its piece's, or between pieces the geometric mean of theirs.
typedef struct wc_self_pieces {
    int32_t count;
    const int32_t *first;
    const uint8_t *self;
    const double *friction, *wet_friction;
} wc_self_pieces;

/// The state for a combined cloth of pieces (copied); the combined cloth's
/// positions are the rest shape. NULL on out-of-memory.
wc_self_state *wci_self_state_create_pieces(const wc_cloth *combined, const wc_self_pieces *pieces);

/// New friction and wet friction per piece (materials can change).
void wci_self_state_set_friction(wc_self_state *state, const double *friction,
                                const double *wet_friction);

/// Drops the candidate pairs: the next call rebuilds them. For a state that
/// skipped steps, in which its particles moved out of the boxes the
/// candidates were made for.
void wci_self_state_invalidate(wc_self_state *state);

/// The rest shape the state was made with, xyz per particle.
const double *wci_self_state_rest(const wc_self_state *state);

/// The particles the last wci_self_collide moved (one flag each), and how
/// many: the collider stage checks them again (collider_contacts.h).
const uint8_t *wci_self_state_moved(const wc_self_state *state, int32_t *count);

/// Resolves self-collisions of the motion from (x, y, z) to (nx, ny, nz):
/// moves nx/ny/nz, sets the history override (qx/qy/qz, history_override)
/// where it changes velocities through the previous position, and marks
/// contacts (contact = WC_CONTACT_CLOTH, normal). Pinned particles do not
/// move. Adds to stats->cloth_contacts and stats->failsafe_particles.
/// Deterministic for any thread count.
wc_status wci_self_collide(wc_cloth *cloth, double dt, int threads, wc_step_stats *stats);

/// After the collider stage moved some particles again (flags in moved)
/// once wci_self_collide was done: detects the pairs of their new motion
/// that collide and puts them back as its fail-safe does, so the step still
/// ends free of intersection between layers. Adds to
/// stats->failsafe_particles. Deterministic for any thread count.
wc_status wci_self_verify(wc_cloth *cloth, const uint8_t *moved, int threads, wc_step_stats *stats);

/// The thickness self-collision keeps between layers of a cloth that has
/// self-collision: the material's, but at least a small fraction of the mean
/// rest edge length.
double wci_self_thickness(const wc_cloth *cloth);

#endif
