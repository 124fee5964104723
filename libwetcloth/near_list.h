/* Cloth elements near a static collider, kept across steps.
 *
 * The feature pass (collide_features.c) asks a collider's vertex and edge
 * grids, for every cloth triangle and edge, which features are near it. A
 * cloth moves a tiny part of a cell per step, so those answers hardly
 * change from one step to the next; asking again every pass of every step
 * was most of the cost of a step (the thesis scene: 55 %). A near list asks
 * once with every particle's box grown by a margin, keeps the elements
 * that found something with what they found, and is reused while each
 * particle stays inside its grown box and the collider has not moved (the
 * "Verlet list" of molecular dynamics). A reused candidate is tested
 * against the element's exact box before use, so the pass sees exactly the
 * candidates the grid would have given: results do not change, bit for
 * bit. */
#ifndef WC_NEAR_LIST_H
#define WC_NEAR_LIST_H

#include <stdint.h>

#include "cloth.h"
#include "collider.h"

/// Elements (ascending) that found candidates, and the candidates of
/// element k: found[start[k] .. start[k+1]), ascending.
///
/// Clearances (kept by the feature pass, collide_features.c): the element's
/// particles may go this far from where they were when measured before a
/// candidate could come within reach of a contact (collide_features.c, REACH:
/// a little less than the contact distance). A cloth resting on a
/// collider stays near the same features step after step and moves a tiny
/// part of its clearance, so most pairs need no distance computed: the
/// distance between a collider feature and a cloth element changes by no
/// more than the farthest its particles move (every point of the element
/// is a weighted mean of them), and a particle moves no farther than the
/// length of its path (which the feature pass keeps per particle).
typedef struct wc_near_elements {
    int32_t count;
    int32_t *element;
    int32_t *start;
    int32_t *found;
    /// Per element of the cloth (listed or not): its index k here, or -1.
    int32_t *slot_of;
    int64_t slot_capacity;
    int64_t element_capacity;
    int64_t start_capacity;
    int64_t found_capacity;
    /// Per element, per particle: the length of the particle's path when
    /// the element's clearances were measured.
    double *path_at;
    /// Per candidate (as found): its clearance, m; negative when unknown.
    double *clearance;
    /// Per element: the least clearance of its candidates.
    double *least_clearance;
    int64_t path_at_capacity;
    int64_t clearance_capacity;
    int64_t least_capacity;
} wc_near_elements;

typedef struct wc_near_list {
    /// Which collider grid the lists were made from, and with which contact
    /// distances; any change makes them stale.
    const wc_collider *collider;
    int64_t grid_version;
    double r_triangles;
    double r_edges;
    double r_particles;
    int built;
    /// Per particle: box (min xyz, max xyz) it must stay in for the lists to
    /// hold: from its start position at the build to as far again past its
    /// end, grown by the margin.
    double *particle_boxes;
    int32_t particle_count;
    /// Collider vertices near each cloth triangle, collider edges near each
    /// cloth edge.
    wc_near_elements triangles;
    wc_near_elements edges;
    /// Collider triangles near each particle (collide.c), and where each
    /// particle is in that list (-1: it found none).
    wc_near_elements particles;
    int32_t *particle_slot;
    /// Where a rebuild that keeps what still holds writes the new lists
    /// before they replace the old (swapped, so both keep their buffers),
    /// and which particles left their boxes.
    wc_near_elements spare;
    uint8_t *left;
} wc_near_list;

void wc_near_list_init(wc_near_list *list);
void wc_near_list_free(wc_near_list *list);

/// Whether the lists still hold for this step's motion (x -> nx) of the
/// cloth against this collider with these contact distances. With `only`,
/// only the only_count particles it lists are checked (the others have not
/// moved since the lists were last found to hold).
int wc_near_list_holds(const wc_near_list *list, const wc_cloth *cloth, const wc_collider *collider,
                       double r_triangles, double r_edges, double r_particles,
                       const int32_t *only, int32_t only_count);

/// For one particle of the particle pass: whether the list was made for
/// this collider (unchanged) with this r_particles and the particle is
/// still inside its box from then; if so, its candidate triangles (a
/// superset of what the grid gives for any box inside its grown box) in
/// *found, *count.
int wc_near_list_particle(const wc_near_list *list, const wc_collider *collider, double r_particles,
                          int32_t particle, double sx, double sy, double sz, double ex, double ey,
                          double ez, const int32_t **found, int32_t *count);

/// (Re)builds the lists for a collider whose grids are static: cloth
/// triangles against its vertex grid (boxes grown by r_triangles), cloth
/// edges (edges: 2 particles each) against its edge grid (grown by
/// r_edges), particles against its triangle grid (grown by r_particles).
/// Lists made for the same collider and distances are rebuilt only where
/// they no longer hold: the particles that left their boxes get new ones,
/// the elements with such a particle are asked again, and every other
/// element keeps its candidates and clearances (what it would be given
/// again, since its box has not changed).
/// WC_ERROR_OUT_OF_MEMORY on failure (the list is then unbuilt).
wc_status wc_near_list_build(wc_near_list *list, const wc_cloth *cloth, const int32_t *edges,
                             int32_t edge_count, const wc_collider *collider, double r_triangles,
                             double r_edges, double r_particles);

#endif
