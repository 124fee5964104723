/* A cloth: particles in structure-of-arrays form, its topology, the per-link
 * constants derived from its material, and its pins. */
#ifndef WC_CLOTH_H
#define WC_CLOTH_H

#include <stdint.h>

#include "step_guard.h"
#include "topology.h"
#include "wetcloth.h"

/// Pins and where their targets move during the current advance. Hard pins
/// (wc_cloth_pin) put their particle on the target; soft pins
/// (wc_cloth_pin_soft) pull a free particle toward it with a spring
/// (applied.h). Both kinds share one list, in the order they were added.
typedef struct wc_pins {
    int32_t count;
    /// Particle index of each pin, in the order they were added.
    int32_t *particle;
    /// xyz per pin: where the pin's target was at the start of the advance...
    double *from;
    /// ...and where it must be at its end.
    double *to;
    /// Per pin: 0 for a hard pin, the spring's stiffness per unit mass
    /// (1/s^2, the squared angular frequency about the target) for a soft
    /// one. NULL until the first soft pin: a cloth with hard pins only
    /// never has it.
    double *stiffness;
    /// Number of soft pins among the count.
    int32_t soft_count;
} wc_pins;

typedef struct wc_cloth {
    int32_t particle_count;
    /// Once the cloth is in a world (in_world), the per-particle arrays
    /// below (positions, forces, masses, contacts, wetness, pin slots; see
    /// particles.h for which) are views of the world's arrays from particle
    /// `first` on; before, the cloth owns them.
    int32_t first;
    int in_world;
    /// Positions now, m.
    double *x, *y, *z;
    /// Positions one step ago. Before the first step (has_history == 0) they
    /// hold the starting velocity instead, m/s, so the first step can be the
    /// exact x + v dt + a dt^2 / 2.
    double *px, *py, *pz;
    /// Positions after the step being computed; committed only when the
    /// whole step succeeded, so a failed step leaves x and px untouched.
    double *nx, *ny, *nz;
    /// Total force on each particle, N.
    double *fx, *fy, *fz;
    /// Velocity estimate used by damping and drag, m/s (allocated only when
    /// the material has either).
    double *vx, *vy, *vz;
    double *mass;
    double *inv_mass;
    int has_history;
    /// Length of the last step, s.
    double dt_prev;
    /// Length of the step being computed, s: set before its collisions, for
    /// the bound on wet friction (response.h).
    double dt_step;

    wc_material material;
    wc_topology topology;
    /// Stretch stiffness K per stretch link, N/m.
    double *stretch_k;
    /// Damping coefficient per stretch link, N s/m (NULL without damping).
    double *stretch_c;
    /// Buckling constant R per bend link, N m^2.
    double *bend_r;
    /// Per bend link, what its force needs every step (forces.c), derived
    /// with R: 1 / l, 1/m, and R / l^2, N, computed as (R * (1 / l)) * (1 / l),
    /// the rounding the force loop had when it computed them itself.
    double *bend_inv_rest, *bend_coef;
    /// Force on the lower-index end of each link, N: stretch links first,
    /// then bend links. Written once per link, then gathered per particle.
    double *link_fx, *link_fy, *link_fz;
    /// Links of each particle (CSR): entry k >= 0 means link k with this
    /// particle at its first end (force +), ~k at its second end (force -).
    int32_t *link_start;
    int32_t *link_list;

    /// Hard pin slot of each particle, or -1 when it moves by its forces
    /// (free, or soft-pinned).
    int32_t *pin_slot;
    /// Soft pin slot of each particle, or -1 (NULL until the first soft pin).
    int32_t *soft_pin_slot;
    wc_pins pins;

    /* Applied forces (applied.h), each NULL until the application sets it:
     * a cloth that has none pays nothing for them. */
    /// Velocity of the air at each particle, m/s, interleaved xyz.
    double *air_velocity;
    /// External force on each particle, N, interleaved xyz: the force
    /// density given (N/m^2) times the particle's rest area.
    double *external_force;

    /// The world's integrator (set when the cloth joins a world).
    wc_integrator integrator;
    /// Stable step estimate for that integrator, s (see wc_world_stable_dt
    /// and estimate_stable_dt in cloth.c).
    double stable_dt;
    /// Buffers of the large-step integrators (xpbd.c, implicit.c), made at
    /// their first step: NULL in a Verlet world, which pays nothing for them.
    struct wc_xpbd_state *xpbd;
    struct wc_implicit_state *implicit;
    /// The unstable-step guard's history, and what it becomes if the step
    /// being computed succeeds (step_guard.h).
    wc_step_guard guard, guard_next;

    /* Collisions. */
    /// wc_contact_kind of each particle in the last step.
    uint8_t *contact;
    /// Surface normal at each particle's contact (toward the particle).
    double *normal_x, *normal_y, *normal_z;
    /// Where a collision response changed a particle's velocity, the
    /// previous position that encodes the new velocity: at commit, px gets
    /// q instead of x for particles whose history_override is set.
    double *qx, *qy, *qz;
    uint8_t *history_override;
    /// Self-collision buffers; NULL when self-collision is off.
    struct wc_self_state *self;
    /// Whether the cloth collides with the world's other cloths that do
    /// (cloth_group.h).
    int collide_cloths;
    /// Buffers of the collider contact stage (collider_contacts.h): made at
    /// the first step with a collider.
    struct wc_collider_contacts *collider_contacts;

    /* Wetness. */
    /// Wetness of each particle, [0, 1].
    double *wetness;
    /// Wet grip of each particle, m/s^2: wet_grip * area * w / m, the most
    /// tangential acceleration wet friction takes off it (response.h). Kept
    /// by wci_cloth_apply_material.
    double *grip;
    /// Contact kind of each particle in the step before the last one.
    uint8_t *contact_prev;
    /// Stuck: wet and in contact in the last two steps.
    uint8_t *stuck;
    /// Whether the wet forces can act at all (some particle wet and the
    /// material adhesive): a dry cloth skips them entirely.
    int wet_forces;
    /// Scratch for wicking (NULL unless the material wicks).
    double *wetness_next;
    /// Self-adhesion (wet cloth with self-collision, wetness.c): the
    /// vertex-face pairs (vertex, triangle) the self-collision answered in
    /// this step, and whether recording one ran out of memory...
    int32_t *self_touched;
    int64_t self_touched_count, self_touched_capacity;
    int self_touched_failed;
    /// ...and the pairs that adhere, from the last step: (vertex, triangle)
    /// and per pair the barycentric weights of the face point (3) and the
    /// unit normal from the face toward the vertex (3).
    int32_t *adhesive_pairs;
    double *adhesive_data;
    int64_t adhesive_count, adhesive_capacity;
} wc_cloth;

/// Creates a cloth from a validated description. On failure nothing leaks.
wc_status wci_cloth_create(wc_cloth **out, const double *xyz, int32_t vertex_count,
                          const int32_t *faces, int32_t face_count, int32_t face_size,
                          const wc_material *material, int self_collision, double wetness,
                          wc_message *msg);

void wci_cloth_destroy(wc_cloth *cloth);

/// After a successful step of length dt, once the world moved px/x/nx one
/// step on (wci_particles_commit): with overrides, particles whose
/// history_override is set get q as their previous position, which carries
/// the velocity a collision gave them.
void wci_cloth_commit(wc_cloth *cloth, double dt, int with_overrides);

/// Derives masses, link constants and the stable step from the material and
/// the current wetness (see wc_material). Call after wetness changes.
void wci_cloth_apply_material(wc_cloth *cloth);

/// Sets the integrator that will step the cloth, and the stable step
/// estimate with it.
void wci_cloth_set_integrator(wc_cloth *cloth, wc_integrator integrator);

/// Recomputes the stable step estimate, after the explicit forces changed
/// (soft pins added or released).
void wci_cloth_update_stable_dt(wc_cloth *cloth);

/// Velocity of particle i, m/s (see wc_cloth_get_velocities).
void wci_cloth_velocity(const wc_cloth *cloth, int32_t i, double v[3]);

#endif
