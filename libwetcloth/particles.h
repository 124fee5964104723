/* The per-particle state of all of a world's cloths, owned by the world:
 * structure of arrays in one block, each cloth the range
 * [first, first + particle_count) of every array. A cloth's per-particle
 * pointers (cloth.h: x, px, nx, fx, mass, contact, ...) are views into that
 * range, so a pass that is handed a cloth reads and writes the world's
 * arrays.
 *
 * The cloths that collide with cloths (collide_cloths) come first, in world
 * order, followed by the others: the members of the world's cloth group are
 * then one contiguous range, and the group's combined cloth (cloth_group.c)
 * is a view of it rather than a copy.
 *
 * A cloth is made with arrays of its own (wci_cloth_create); joining a world
 * moves them into the world's block. Arrays that exist only for some
 * materials or features (velocity scratch for damping and drag, wicking
 * scratch, soft pin slots, applied force fields) stay with the cloth. */
#ifndef WC_PARTICLES_H
#define WC_PARTICLES_H

#include <stdint.h>

#include "cloth.h"

typedef struct wc_particles {
    /// Particles of all cloths.
    int32_t count;
    /// The one allocation every array below points into.
    void *block;
    double *x, *y, *z, *px, *py, *pz, *nx, *ny, *nz, *fx, *fy, *fz;
    double *mass, *inv_mass, *normal_x, *normal_y, *normal_z, *qx, *qy, *qz, *wetness, *grip;
    int32_t *pin_slot;
    uint8_t *contact, *contact_prev, *stuck, *history_override;
} wc_particles;

/// Moves cloths[count - 1], which has arrays of its own, into the world's
/// particles after cloths[0 .. count - 2], which are already there: a new
/// block in the layout above, every cloth's state copied into its range, the
/// new cloth's own arrays freed and every cloth's views pointed at the new
/// block. Non-zero on out-of-memory or when the world would hold more than
/// 2^31 - 1 particles, with the world's particles and every cloth as they
/// were.
int wci_particles_add(wc_particles *p, wc_cloth *const *cloths, int32_t count);

/// After a successful step, for every cloth at once: the positions after
/// the step become the current ones and the current ones the previous
/// (px <- x <- nx <- px, a swap of the arrays), and every cloth's views
/// follow.
void wci_particles_commit(wc_particles *p, wc_cloth *const *cloths, int32_t count);

/// Gives a cloth the per-particle views of another, from the other's first
/// particle on: how the cloth group's combined cloth sees its members'
/// range.
void wci_particles_view(wc_cloth *view, const wc_cloth *from);

/// Frees the per-particle arrays a cloth still owns (not yet in a world).
void wci_particles_free_own(wc_cloth *c);

void wci_particles_free(wc_particles *p);

#endif
