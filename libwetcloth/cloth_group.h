/* Collision between the different cloths of one world. The cloths that
 * collide with cloths (collide_with_cloths in their description) form the
 * world's group; for collision they are pieces of one combined cloth, and
 * the self-collision of that combined cloth (selfcollide.c) answers all of
 * its pairs, within a cloth (where that cloth self-collides) and between
 * cloths, in one set of passes with one fail-safe. The guarantee that a step
 * ends free of intersections then covers them together, which separate
 * passes could not give: answering cloth A against cloth B could push A
 * through itself, and nothing would look again.
 *
 * A step in which no two members' motions come within the thickness of
 * each other leaves every cloth to its own self-collision, so cloths far
 * apart pay one pass over their particles. A world with fewer than two
 * members has no group and pays nothing. */
#ifndef WC_CLOTH_GROUP_H
#define WC_CLOTH_GROUP_H

#include "cloth.h"

typedef struct wc_cloth_group wc_cloth_group;

/// Makes, remakes or drops *group to match the world's cloths (members: the
/// cloths with collide_cloths set, in world order; a group needs two).
/// Cheap when nothing changed. Non-zero on out-of-memory, with *group as it
/// was.
int wci_cloth_group_update(wc_cloth_group **group, wc_cloth *const *cloths, int32_t cloth_count);

void wci_cloth_group_destroy(wc_cloth_group *group);

/// After every cloth's collider passes: when two members' motions x -> nx
/// come within the group's thickness, resolves the collisions of all
/// members together (moves nx, sets history overrides and contacts as the
/// self-collision does; records and updates the self-adhesion of wet
/// self-colliding members, and the wet pairs between members), and marks
/// them handled; otherwise marks none.
/// Deterministic for any thread count. WC_ERROR_OUT_OF_MEMORY on
/// out-of-memory (the caller restores the contact state).
wc_status wci_cloth_group_collide(wc_cloth_group *group, wc_cloth *const *cloths, double dt,
                                 int threads, wc_step_stats *stats);

/// Before a step's collisions, with the members' contact state
/// (contact_backup.h): keeps the wet pairs between members for
/// wci_cloth_group_restore. Non-zero on out-of-memory, nothing changed.
/// Nothing to copy without such pairs. NULL is a no-op.
int wci_cloth_group_save(wc_cloth_group *group);

/// After the collisions of a step failed: the wet pairs between members as
/// wci_cloth_group_save found them (the members' own state is put back by
/// contact_backup.h). NULL is a no-op.
void wci_cloth_group_restore(wc_cloth_group *group);

/// Adds the wet adhesion between members (the pairs the last collision
/// kept, wetness.c's self-adhesion law across cloths) to their fx, fy, fz:
/// equal and opposite, serial in pair order, so the sums do not depend on
/// the thread count. Nothing to do, and no cost, without such pairs (no
/// member wet, or none touching another). NULL is a no-op.
void wci_cloth_group_adhesion(wc_cloth_group *group, wc_cloth *const *cloths);

/// Whether the last wci_cloth_group_collide resolved cloth `cloth` (a world
/// index): then its own self-collision must not run in that step.
int wci_cloth_group_handled(const wc_cloth_group *group, int32_t cloth);

/// For a cloth the last wci_cloth_group_collide handled: its particles'
/// flags of having been moved there (one each), with *any set when the group
/// moved any particle; NULL (and *any 0) for a cloth it did not handle.
const uint8_t *wci_cloth_group_moved(const wc_cloth_group *group, int32_t cloth, int32_t *any);

/// For a cloth the last wci_cloth_group_collide handled: where to mark (one
/// flag per particle, zero until marked) the particles the collider stage
/// moved again after it; NULL for a cloth it did not handle.
uint8_t *wci_cloth_group_flags(wc_cloth_group *group, int32_t cloth);

/// After the collider stage moved marked particles of handled members again:
/// detects the combined motion's colliding pairs among them and puts them
/// back (wci_self_verify), then clears the marks. WC_ERROR_OUT_OF_MEMORY on
/// out-of-memory.
wc_status wci_cloth_group_verify(wc_cloth_group *group, wc_cloth *const *cloths, int threads,
                                 wc_step_stats *stats);

/// Whether the cloths can collide with each other at all: two or more with
/// collide_cloths set.
int wci_cloth_group_possible(wc_cloth *const *cloths, int32_t cloth_count);

#endif
