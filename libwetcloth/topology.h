/* Cloth topology, built once from the rest shape (docs/model.md, Particles and links): particle areas,
 * stretch links (mesh edges and quad diagonals), bend links (the 150-degree
 * rule), and the surface triangles. Material-free: the cloth turns the area
 * shares into stiffnesses, so a material can change without a rebuild. */
#ifndef WC_TOPOLOGY_H
#define WC_TOPOLOGY_H

#include <stdint.h>

#include "wetcloth.h"

/// A set of links between particle pairs, a < b, sorted by (a, b).
typedef struct wc_link_set {
    int32_t count;
    int32_t *a;
    int32_t *b;
    /// Rest length, m.
    double *rest;
    /// Area share, m^2: for stretch links already multiplied by the face
    /// calibration factor (8/3 or 12/5, see wc_material).
    double *share;
} wc_link_set;

typedef struct wc_topology {
    int32_t particle_count;
    /// Area of each particle, m^2 (a third of each triangle around it, a quarter
    /// of each quad).
    double *area;
    wc_link_set stretch;
    wc_link_set bend;
    int32_t triangle_count;
    /// 3 * triangle_count particle indices.
    int32_t *triangles;
} wc_topology;

/// Builds the topology of a mesh. Validates everything: finite vertices,
/// indices in range, no face using a vertex twice, no degenerate face, no
/// vertex outside every face. On failure nothing is allocated.
wc_status wci_topology_create(wc_topology *out, const double *xyz, int32_t vertex_count,
                            const int32_t *faces, int32_t face_count, int32_t face_size,
                            wc_message *msg);

void wci_topology_destroy(wc_topology *topology);

/// The rest angle a-b-c counts as "nearly straight" when its cosine is at most
/// this: cos(150 degrees), with a little slack so exact 150 degrees qualifies.
#define WC_BEND_COS_LIMIT (-0.86602540378443865 + 1e-12)

#endif
