/* Contact records and the one response every contact gets (docs/model.md,
 * Collisions, "Response").
 *
 * Detection (narrowphase.c for colliders, selfcollide.c between layers of
 * cloth and between cloths) describes each contact it finds as a wc_contact:
 * which particles, with which barycentric weights, against what, along which
 * normal, how far apart now and how far apart the response must leave them,
 * and its friction. wci_response_apply answers it against the current state,
 * always by the same law:
 *
 *  * normal: the approach along n is removed (an inelastic impulse: a change
 *    of velocity), then the separation is set to the target (a change of
 *    position only, which must not become velocity);
 *  * Coulomb friction: the tangential relative motion loses at most mu times
 *    the normal change (thesis: dry contact);
 *  * wet friction (thesis eq. 2.10): in sustained contact (the contact's
 *    particles touched something in the last step too) what Coulomb leaves is
 *    scaled by 1 - w (1 - q), w the contact's wetness there, but less by at
 *    most the wet grip's g h^2 (g the particles' grip, an acceleration: the
 *    most tangential force wet friction holds is wet_grip * A * w, so that
 *    a cloth pulled harder slides instead of stretching, whatever the step);
 *    dry contacts take exactly the Coulomb path, so dry cloth keeps the plain
 *    model's bits;
 *  * the changes are shared among the particles by w_k / m_k (Bridson,
 *    Fedkiw & Anderson 2002, eq. 4): the contact point then moves by exactly
 *    what is asked; a collider has infinite mass.
 *
 * Everything works in displacements over the step, u = nx - q (q the
 * previous position the next step will see: the start of the step, or the
 * history override an earlier response set), so dt drops out: a velocity
 * change is a change of nx and q together, a position change moves nx alone
 * and q with it. Friction acts on the tangential displacement of the contact
 * point at its new place, and takes the same share off its velocity: a
 * particle stopped where its path met a surface (a contact found by the
 * continuous test) has moved sideways only up to there, and taking the whole
 * step's sideways motion off it would put it behind where it started (a
 * ratchet: at large steps it pushed cloth outward round a sphere's pole
 * until its links stretched without bound).
 *
 * Contacts are answered one after another in the order their detection
 * makes them (a fixed order: serial, or per particle in a parallel loop in
 * which each particle's contacts touch only that particle), so results do
 * not depend on the thread count. Adhesion, the wet pull of a contact, acts
 * as a force in the next step (wetness.c) from the contact marks and
 * normals this module writes. */
#ifndef WC_RESPONSE_H
#define WC_RESPONSE_H

#include <stdint.h>

#include "cloth.h"

/// The per-particle arrays a response reads and writes (one cloth's, or the
/// combined cloth's of a cloth group).
typedef struct wc_particle_arrays {
    int32_t count;
    /// Positions at the start of the step.
    const double *x, *y, *z;
    /// Positions at the end of the step, as corrected so far.
    double *nx, *ny, *nz;
    /// Previous positions the next step will see where history_override is set.
    double *qx, *qy, *qz;
    uint8_t *history_override;
    const double *inv_mass;
    const int32_t *pin_slot;
    /// wc_contact_kind of each particle in this step and the normal of its
    /// contact (toward the particle).
    uint8_t *contact;
    double *normal_x, *normal_y, *normal_z;
    /// What the last step's contacts were, the wetness and the wet grip
    /// (cloth.h), and the step's length squared, s^2: wet friction.
    const uint8_t *contact_prev;
    const double *wetness, *grip;
    double step_squared;
} wc_particle_arrays;

/// The arrays of one cloth.
wc_particle_arrays wci_particle_arrays_of(wc_cloth *cloth);

/// What a contact touches.
typedef enum wc_contact_source {
    /// A collider: its point moves by surface_motion over the step and does
    /// not give way.
    WC_SOURCE_COLLIDER = 0,
    /// Another part of a cloth (the particles with negative weights).
    WC_SOURCE_CLOTH = 1
} wc_contact_source;

/// One contact, as detection found it.
typedef struct wc_contact {
    uint8_t source;
    /// Found by the continuous test (the elements met during the step)
    /// rather than by proximity at its end.
    uint8_t impact;
    /// Particles taking part (1 to 4), and their weights: the contact point
    /// of the first side is sum over w_k > 0 of w_k x_k, that of the second
    /// (cloth) side the sum over w_k < 0; weights of each side sum to 1.
    uint8_t count;
    int32_t particle[4];
    double weight[4];
    /// Unit normal from the second side (or the collider) toward the first.
    double normal[3];
    /// Separation along the normal at the end of the step as detected, and
    /// the separation the response leaves.
    double distance, target;
    /// Collider contacts: how far the collider's point moves over the step.
    double surface_motion[3];
    /// A correction of the first side's contact point that is not along the
    /// normal and not velocity (zero but for a particle whose path crossed a
    /// collider face: back to the point where its path met it).
    double place[3];
    /// Coulomb coefficient, and wet friction q (thesis eq. 2.10).
    double friction, wet_friction;
} wc_contact;

/// How to answer: for contacts between cloth, leftovers of a proximity
/// below `slack` (m) are not worth another pass, and a particle resting on a
/// collider is not pushed into it by a contact with cloth (along that
/// surface's normal it is as good as pinned).
typedef struct wc_response_options {
    double slack;
} wc_response_options;

/// Answers one contact against the current state: moves nx (and q for what
/// must not become velocity), sets history overrides, and marks contacts
/// (collider contacts: kind and normal, a single particle's always, an
/// element's where it had none; cloth contacts where it had none, with the
/// normal seen from the particle's side; *marked counts those). Returns 1 if
/// a particle moved, and then in moved[k] whether particle[k] did.
int wci_response_apply(const wc_particle_arrays *p, const wc_contact *contact,
                      const wc_response_options *options, int32_t *marked, uint8_t moved[4]);

/// The share of the tangential relative motion a contact keeps: Coulomb's
/// 1 - mu * normal_change / tangential (at least 0), then, with wet > 0,
/// less the wet share wet * (1 - q) of that, but less by at most `grip`
/// (m) of the motion. The friction law, in one place.
double wci_friction_keep(double mu, double normal_change, double tangential, double wet, double q,
                         double grip);

#endif
