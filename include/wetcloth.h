/* libwetcloth: wet cloth as a mass-spring system.
 *
 * The one public header. Everything here is plain C99 with fixed-width types:
 * opaque handles, description structs that come with a `..._default()` function,
 * status codes with a message that names what was wrong.
 *
 * Units are SI throughout: metres, kilograms, seconds, newtons.
 *
 * Ownership: the world owns everything added to it. Cloths and colliders are
 * addressed by the small integer index their `add` call returned; indices stay
 * valid for the world's lifetime.
 *
 * Threading: one world must not be used from two threads at once. Different
 * worlds are independent. Inside a step the world uses OpenMP threads
 * (see wc_world_def.thread_count); results are bitwise identical for any
 * thread count.
 */
#ifndef WETCLOTH_H
#define WETCLOTH_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The library exports exactly the functions marked WC_API (it is built with
 * WC_BUILD_SHARED and hidden visibility). A program that uses the DLL needs
 * no dllimport: the import library resolves the calls. */
#if defined(_WIN32)
#if defined(WC_BUILD_SHARED)
#define WC_API __declspec(dllexport)
#else
#define WC_API
#endif
#elif defined(__GNUC__)
#define WC_API __attribute__((visibility("default")))
#else
#define WC_API
#endif

/// Version of this header. wc_version() gives the library's at run time.
#define WC_VERSION_MAJOR 0
#define WC_VERSION_MINOR 2
#define WC_VERSION_PATCH 0
/// Single number: major * 10000 + minor * 100 + patch.
#define WC_VERSION (WC_VERSION_MAJOR * 10000 + WC_VERSION_MINOR * 100 + WC_VERSION_PATCH)

/// Library version as major * 10000 + minor * 100 + patch.
WC_API int32_t wc_version(void);
/// Library version as "major.minor.patch".
WC_API const char *wc_version_string(void);
/// Size in bytes of the public struct named `name` (its typedef name, e.g.
/// "wc_world_def") as this library was compiled; 0 for NULL or a name it
/// does not know. A binding that declares the structs itself (the Python
/// package's cffi description, generated from this header) compares its
/// sizes with these when it loads the library: a library and a binding
/// built from different versions of this header then fail with a message
/// instead of reading and writing past the end of a struct.
WC_API int64_t wc_struct_size(const char *name);

/// Result of every call that can fail. On anything but WC_OK the call changed
/// nothing, and wc_world_last_error() (or the wc_message of wc_world_create)
/// says what was wrong.
typedef enum wc_status {
    WC_OK = 0,
    /// An argument is out of range, not finite, inconsistent or NULL.
    WC_ERROR_INVALID_ARGUMENT = 1,
    /// An allocation failed; the world is as it was before the call.
    WC_ERROR_OUT_OF_MEMORY = 2,
    /// The step would have produced a non-finite position, or (Verlet) it is
    /// unstable: a time step above what the integrator keeps stable, seen by
    /// the growing, alternating oscillation it starts. The world keeps its
    /// last good state.
    WC_ERROR_NON_FINITE = 3,
    /// A cloth or collider index that the world does not have.
    WC_ERROR_NOT_FOUND = 4
} wc_status;

/// Short name of a status, e.g. "WC_ERROR_INVALID_ARGUMENT".
WC_API const char *wc_status_name(wc_status status);

/// Error text for calls that have no world to keep it in (wc_world_create).
typedef struct wc_message {
    char text[256];
} wc_message;

/* ------------------------------------------------------------------------ */
/* World                                                                    */
/* ------------------------------------------------------------------------ */

typedef struct wc_world wc_world;

/// How a step advances positions.
typedef enum wc_integrator {
    /// Position Verlet, x(t+dt) = 2x(t) - x(t-dt) + a dt^2 (thesis eq. 2.4).
    /// Explicit: stable for dt below wc_world_stable_dt().
    WC_INTEGRATOR_VERLET = 0,
    /// Strain-limited stretch: Verlet for every force but the stretch links,
    /// which are tension-only constraints solved by compliant projection
    /// (XPBD, one Gauss-Seidel iteration per step, as in Macklin et al.
    /// 2019, "Small Steps in Physics Simulation"; the steps are the small
    /// substeps). Stretch stiffness no longer limits the step (any value,
    /// up to inextensible); bending, drag and soft pins still do.
    WC_INTEGRATOR_XPBD = 1,
    /// Semi-implicit backward Euler (Choi & Ko 2002; Baraff & Witkin 1998):
    /// the stretch links' linearised Jacobian, the bend links' axial
    /// stiffness (their indefinite transverse term dropped, as Choi & Ko do)
    /// and the soft pins' goal springs, with the stretch dashpots and the air
    /// drag, in one linear system per step, solved by block-Jacobi
    /// preconditioned conjugate gradients to wc_world_def.implicit_tolerance.
    /// Free fall is exact, as with Verlet, for equal and for changing steps
    /// (solved to round-off).
    WC_INTEGRATOR_IMPLICIT = 2
} wc_integrator;

/// Description of a world. Start from wc_world_def_default().
typedef struct wc_world_def {
    /// Gravitational acceleration, m/s^2, finite. Default (0, 0, -9.81).
    double gravity[3];
    /// OpenMP threads used inside a step, at most. 0 = OpenMP's default
    /// (the machine's cores); 1 .. 1024. Ignored when the library was built
    /// without OpenMP. See adapt_threads.
    int32_t thread_count;
    /// Integrator. Default WC_INTEGRATOR_IMPLICIT at automatic substeps (12
    /// per frame of 1/24 s): the cheapest single setting within 1 % of its
    /// converged answer on the thesis drape at 400 and at 10,201 particles
    /// (docs/model.md, "The default integrator"). WC_INTEGRATOR_VERLET is
    /// the thesis' own, the reference the others are measured against.
    wc_integrator integrator;
    /// Fraction of the stable step that automatic substepping uses,
    /// (0, 1]. Default 0.9.
    double substep_safety;
    /// Largest number of substeps wc_world_advance() may choose on its own,
    /// 1 .. 10^7. Default 100000. Asking for more is an error, not a silent cap.
    int32_t max_substeps;
    /// WC_INTEGRATOR_IMPLICIT only: how exactly each step's linear system is
    /// solved, as an acceleration, m/s^2, [0, 1000], finite. The conjugate
    /// gradients stop once their estimated velocity error (mass-weighted RMS,
    /// bounded by the energy norm, Hestenes-Stiefel estimate) is at most this
    /// times the step: the solve's error then acts like a stray acceleration
    /// of at most this size over one step. 0 solves to round-off (residual
    /// 1e-8 of the right-hand side, which also ends every solve). The
    /// estimate bounds the error of an iterate 8 iterations back, so the
    /// error left is well below this (1.7 and 0.4 m/s^2 measured at 8 on one
    /// step of stretched, swirling 20^2 and 65^2 cloths). The preconditioner
    /// solves for the
    /// cloth's motion as a whole exactly, so no tolerance slows a sliding
    /// cloth. Default 8: on the thesis drape at 400 and 10,201 particles the
    /// error against a fine-step reference solved to round-off is where a
    /// full solve leaves it, at 1.7x fewer iterations than at 1 on the
    /// larger; above it a near-inextensible cloth gained energy at more of
    /// the settings tried (docs/model.md has the figures).
    double implicit_tolerance;
    /// 1 (default): the world times its steps and runs them on fewer than
    /// thread_count threads whenever that is faster: when other programs
    /// keep cores busy (a thread the scheduler takes away holds up every
    /// barrier of the step), or when a cloth is too small to share. It
    /// probes a neighbouring count now and then and keeps the faster, and
    /// does not try more threads while the system counts the cores they
    /// would need as busy. The results are the same bits for any thread
    /// count, so this changes only the time. 0: always thread_count threads
    /// (for measuring scaling).
    int32_t adapt_threads;
} wc_world_def;

/// The default world description.
WC_API wc_world_def wc_world_def_default(void);

/// Creates a world. On failure *out_world is NULL and, when out_message is not
/// NULL, its text says what was wrong.
WC_API wc_status wc_world_create(const wc_world_def *def, wc_world **out_world,
                                 wc_message *out_message);

/// Destroys a world and everything in it. NULL is allowed.
WC_API void wc_world_destroy(wc_world *world);

/// Message of the last failed call on this world ("" if none failed yet).
/// Valid until the next call on the world.
WC_API const char *wc_world_last_error(const wc_world *world);

/// Advances every cloth by one step of dt seconds, (0, 10] and finite:
/// forces, integration, collisions, wet response. Pin targets set with
/// wc_cloth_set_pin_targets() are reached at the end of this step.
/// On WC_ERROR_NON_FINITE the world keeps the state before the step.
WC_API wc_status wc_world_step(wc_world *world, double dt);

/// Advances by one frame of frame_dt seconds in `substeps` equal steps.
/// substeps = 0 picks the smallest count whose step is at most
/// substep_safety * wc_world_stable_dt() (an error if that exceeds max_substeps).
/// Pinned particles move linearly from where they were to their targets
/// across the substeps. If a substep fails, the world keeps the state after
/// the last good substep (see wc_world_time()).
WC_API wc_status wc_world_advance(wc_world *world, double frame_dt, int32_t substeps);

/// Largest step, s, at which the world's integrator is estimated to stay
/// stable for every cloth in the world (an upper bound on the highest
/// frequency of what the integrator treats explicitly, from Gershgorin's
/// theorem, so it errs on the safe side): every link, drag and the soft
/// pins' springs (omega^2 = their stiffness) for Verlet; bend links, drag
/// and soft pins for XPBD; the dropped transverse bending term for the
/// implicit integrator, which solves drag and soft pins implicitly. +inf
/// when there is no cloth.
WC_API double wc_world_stable_dt(const wc_world *world);

/// Substeps the last wc_world_advance() used (0 before any).
WC_API int32_t wc_world_last_substeps(const wc_world *world);

/// Simulated time, s: the sum of all successful steps.
WC_API double wc_world_time(const wc_world *world);

/// Number of cloths in the world.
WC_API int32_t wc_world_cloth_count(const wc_world *world);

/* ------------------------------------------------------------------------ */
/* Material                                                                  */
/* ------------------------------------------------------------------------ */

/// Cloth material in physical units that do not depend on the mesh
/// resolution. The library derives per-particle masses and per-link
/// constants from it:
///
/// * particle mass m_i = density * A_i, where A_i is one third of the area
///   of each triangle and one quarter of each quad around particle i;
/// * stretch link stiffness K = c * stretch_stiffness * A_e / l^2, where l is
///   the rest length, A_e the link's share of the area of its faces (each
///   face shares its area equally among its links: 3 edges of a triangle;
///   4 edges and 2 diagonals of a quad), and c = 8/3 for triangles,
///   12/5 for quads: with these the uniaxial-strain modulus of a regular grid
///   or equilateral triangle mesh equals stretch_stiffness;
/// * stretch link damping coefficient 2 * stretch_damping * sqrt(K * m_r)
///   with m_r = m_a m_b / (m_a + m_b) the link's reduced mass;
/// * bend link constant R = bend_stiffness * A_b / l with l the link's rest
///   length and A_b = A_a / n_a + A_c / n_c its share of the area of its two
///   end particles (n = a particle's number of bend links). For a sheet bent
///   to curvature k, a bend link of rest length l stores 0.5 * R * k^2 * l.
typedef struct wc_material {
    /// Areal density of the dry cloth, kg/m^2, (0, 1000]. Default 0.15
    /// (cotton shirting, 150 g/m^2).
    double density;
    /// In-plane stretch stiffness, N/m, [0, 1e9]. Links resist only tension.
    /// Default 1000.
    double stretch_stiffness;
    /// Bending stiffness, N*m, [0, 1e3]. Bend links resist only compression
    /// (Choi & Ko's buckling model). Default 1e-5.
    double bend_stiffness;
    /// Damping along stretch links as a fraction of each link's critical
    /// damping, [0, 1]. Default 0.05.
    double stretch_damping;
    /// Linear air drag, N*s/m^3: force -air_drag * A_i * (v - u) on each
    /// particle, u the air's velocity there (still air, u = 0, unless
    /// wc_cloth_set_air_velocity gives one). [0, 1e4]. Default 0.02.
    double air_drag;
    /// Collision thickness of the cloth, m, [0, 1]: particles keep at least
    /// this much (plus the collider's thickness) from every surface (the
    /// cloth's triangles and edges keep 0.9 of it from a mesh collider's
    /// vertices and edges, so that a cloth resting on a smooth dense mesh
    /// is held by its faces alone; half of it from a smooth vertex or edge,
    /// where the surface turns by at most 6 degrees and the faces around it
    /// hold the cloth off it already, unless the cloth's edges are longer
    /// than 3.8 times the contact distance), and at least this much from other
    /// parts of the same cloth when it self-collides, and from other cloths
    /// it collides with. Default 0.005.
    double thickness;
    /// Coulomb friction coefficient against colliders and itself, [0, 10].
    /// A contact uses sqrt(cloth friction * collider friction). Default 0.5.
    double friction;

    /* Wetness (thesis 2.3-2.4). Each takes effect in proportion to a
     * particle's wetness w in [0, 1]; a dry cloth (w = 0 everywhere) behaves,
     * bit for bit and at no extra cost, as if they were all zero. */

    /// Adhesion pressure of soaked cloth (w = 1), Pa, [0, 1e6]: a particle of
    /// area A in contact is pulled toward the surface with s w, s = adhesion * A
    /// (thesis eq. 2.8), every step while in contact. Default 30 (about 10
    /// times the weight of soaked cotton per area: it holds on a vertical
    /// wall and wraps round what it falls on).
    double adhesion;
    /// Spread factor beta, [0, 1]: a particle linked to a stuck one is pulled
    /// toward the same surface with s w beta l / d per stuck neighbour (l the
    /// link's rest length, d its length now), at most s w in all (thesis
    /// eq. 2.9). Default 0.5.
    double spread;
    /// Wet friction q, [0, 1]: in sustained contact (this step and the last),
    /// the tangential velocity relative to the surface is scaled by
    /// 1 - w (1 - q) on top of Coulomb friction (thesis eq. 2.10); 1 = no
    /// extra friction. Default 0.05.
    double wet_friction;
    /// Wet grip of soaked cloth (w = 1), Pa, [0, 1e6]: the most tangential
    /// stress wet friction holds. It takes off at most g w A / m of a
    /// particle's tangential acceleration (g this grip, A the particle's area,
    /// m its wet mass), however hard its links pull; beyond that wet cloth
    /// slides. 0 turns wet friction off; a large value keeps the thesis' law
    /// whatever the pull (wet cloth on a moving collider then stretches
    /// without bound: docs/wetness.md). Default 60 (twice the default
    /// adhesion: 200 m/s^2 on soaked default cloth, about 20 g).
    double wet_grip;
    /// Water uptake at w = 1 as a fraction of dry mass, [0, 10]: mass is
    /// multiplied by 1 + wet_mass_gain * w. Default 1.0 (100 %; cotton takes
    /// up 50-200 %).
    double wet_mass_gain;
    /// Softening at w = 1, [0, 0.99]: stretch and bend stiffness are
    /// multiplied by 1 - wet_softening * w (the link's mean wetness).
    /// Default 0.3.
    double wet_softening;
    /// Wicking: wetness diffuses along stretch links at this rate, m^2/s,
    /// [0, 1]. 0 (default) = off, and costs nothing.
    double wicking;
    /// Drying: wetness decays as dw/dt = -drying * w, 1/s, [0, 100].
    /// 0 (default) = off, and costs nothing.
    double drying;
} wc_material;

/// The default material (plausible cotton).
WC_API wc_material wc_material_default(void);

/* ------------------------------------------------------------------------ */
/* Cloth                                                                     */
/* ------------------------------------------------------------------------ */

/// A cloth from a triangle and/or quad mesh.
typedef struct wc_mesh_cloth_def {
    /// Rest positions, m, interleaved xyz, 3 * vertex_count finite values.
    /// Also the starting positions. Copied; the caller keeps ownership.
    const double *vertices;
    /// Number of vertices, 3 .. 2^26.
    int32_t vertex_count;
    /// Vertex indices of the faces, face_size per face, each in
    /// [0, vertex_count). With face_size 4, a last index of -1 makes the face
    /// a triangle, so triangles and quads can mix. Copied.
    const int32_t *faces;
    /// Number of faces, 1 .. 2^27.
    int32_t face_count;
    /// Indices per face: 3 or 4.
    int32_t face_size;
    /// Material.
    wc_material material;
    /// 1 to keep the cloth from passing through itself, 0 (default) not to.
    /// Off costs nothing.
    int32_t self_collision;
    /// 1 (default) to collide with the world's other cloths that have it
    /// set, 0 not to: vertex-face and edge-edge contact with continuous
    /// detection, friction sqrt(mu_a * mu_b), and the same guarantee of no
    /// intersection as self-collision. Between cloths the thickness is the
    /// larger of the two materials'. A world with fewer than two such
    /// cloths pays nothing; cloths far apart pay one pass over their
    /// particles per step. Wet cloths do not adhere to each other.
    int32_t collide_with_cloths;
    /// Starting wetness of every particle, [0, 1]. Default 0 (dry).
    double wetness;
} wc_mesh_cloth_def;

/// Default mesh cloth description (no geometry, default material).
WC_API wc_mesh_cloth_def wc_mesh_cloth_def_default(void);

/// A regular grid of count_u x count_v particles (the thesis' cloth). Particle
/// (i, j) has index j * count_u + i and rest position
/// center + (i / (count_u-1) - 0.5) size_u axis_u + (j / (count_v-1) - 0.5) size_v axis_v.
/// Faces are the grid's quads.
typedef struct wc_grid_cloth_def {
    /// Particles along axis_u, 2 .. 32768.
    int32_t count_u;
    /// Particles along axis_v, 2 .. 32768. count_u * count_v <= 2^26.
    int32_t count_v;
    /// Size along axis_u, m, (0, 1e6]. Default 1.
    double size_u;
    /// Size along axis_v, m, (0, 1e6]. Default 1.
    double size_v;
    /// Centre of the cloth, m. Default (0, 0, 0).
    double center[3];
    /// Direction of u, unit length (within 1e-6). Default (1, 0, 0).
    double axis_u[3];
    /// Direction of v, unit length and perpendicular to axis_u (within 1e-6).
    /// Default (0, 1, 0).
    double axis_v[3];
    /// Material.
    wc_material material;
    /// 1 to keep the cloth from passing through itself, 0 (default) not to.
    int32_t self_collision;
    /// 1 (default) to collide with the world's other cloths that have it
    /// set, 0 not to: vertex-face and edge-edge contact with continuous
    /// detection, friction sqrt(mu_a * mu_b), and the same guarantee of no
    /// intersection as self-collision. Between cloths the thickness is the
    /// larger of the two materials'. A world with fewer than two such
    /// cloths pays nothing; cloths far apart pay one pass over their
    /// particles per step. Wet cloths do not adhere to each other.
    int32_t collide_with_cloths;
    /// Starting wetness of every particle, [0, 1]. Default 0 (dry).
    double wetness;
} wc_grid_cloth_def;

/// Default grid: 32 x 32 particles, 1 m x 1 m in the plane z = 0.
WC_API wc_grid_cloth_def wc_grid_cloth_def_default(void);

/// Adds a cloth; *out_cloth receives its index.
WC_API wc_status wc_world_add_mesh_cloth(wc_world *world, const wc_mesh_cloth_def *def,
                                         int32_t *out_cloth);
/// Adds a grid cloth; *out_cloth receives its index.
WC_API wc_status wc_world_add_grid_cloth(wc_world *world, const wc_grid_cloth_def *def,
                                         int32_t *out_cloth);

/// Number of particles of a cloth (0 if the index is not a cloth).
WC_API int32_t wc_cloth_particle_count(const wc_world *world, int32_t cloth);

/// Kinds of links.
typedef enum wc_link_kind {
    /// Tension-only links: mesh edges and both diagonals of every quad.
    WC_LINK_STRETCH = 0,
    /// Compression-only (buckling) links: (a, c) when (a, b) and (b, c) are
    /// stretch links, the rest angle a-b-c is at least 150 degrees, and c is
    /// the straightest continuation of a -> b through b and a that of c -> b.
    /// On a regular grid: each particle to the one two steps away in each of
    /// the 8 directions (the thesis' "skip one" links).
    WC_LINK_BEND = 1
} wc_link_kind;

/// Number of links of a kind.
WC_API int32_t wc_cloth_link_count(const wc_world *world, int32_t cloth, wc_link_kind kind);

/// Copies the links of a kind as particle index pairs (2 * count values,
/// lower index first, sorted) and their rest lengths (count values, m).
/// Either output may be NULL. capacity is the number of links the outputs
/// hold; it must be at least wc_cloth_link_count().
WC_API wc_status wc_cloth_get_links(const wc_world *world, int32_t cloth, wc_link_kind kind,
                                    int32_t *out_pairs, double *out_rest_lengths,
                                    int32_t capacity);

/// Number of triangles of the cloth's surface (quads count as two).
WC_API int32_t wc_cloth_triangle_count(const wc_world *world, int32_t cloth);

/// Copies the surface triangles, 3 * count particle indices.
WC_API wc_status wc_cloth_get_triangles(const wc_world *world, int32_t cloth,
                                        int32_t *out_indices, int32_t capacity);

/// Copies positions, m, interleaved xyz. count must equal the particle count.
WC_API wc_status wc_cloth_get_positions(const wc_world *world, int32_t cloth,
                                        double *out_xyz, int32_t count);
/// Same as wc_cloth_get_positions, as float (what Blender's foreach_set takes).
WC_API wc_status wc_cloth_get_positions_f32(const wc_world *world, int32_t cloth,
                                            float *out_xyz, int32_t count);

/// Moves every particle to new positions (m, interleaved xyz, finite) with
/// zero velocity. Pinned particles move too and stay pinned there: every
/// pin's target, hard or soft, becomes its particle's new position.
WC_API wc_status wc_cloth_set_positions(wc_world *world, int32_t cloth,
                                        const double *xyz, int32_t count);

/// Velocities, m/s, interleaved xyz: estimated from the last step as
/// (x - x_prev) / dt, or the velocity set with wc_cloth_set_velocities
/// before the first step.
WC_API wc_status wc_cloth_get_velocities(const wc_world *world, int32_t cloth,
                                         double *out_xyz, int32_t count);

/// Sets velocities, m/s, interleaved xyz, finite. The next step starts from
/// them exactly (x(dt) = x + v dt + a dt^2 / 2).
WC_API wc_status wc_cloth_set_velocities(wc_world *world, int32_t cloth,
                                         const double *xyz, int32_t count);

/// What a particle touched in the last step.
typedef enum wc_contact_kind {
    WC_CONTACT_NONE = 0,
    /// A collider (mesh or convex shape).
    WC_CONTACT_COLLIDER = 1,
    /// Another part of a cloth.
    WC_CONTACT_CLOTH = 2
} wc_contact_kind;

/// Read-only structure-of-arrays view of one cloth's particles. The pointers
/// stay valid until the next call that changes the world (a step, advance,
/// adding a cloth, set_positions, ...): the world keeps all its cloths'
/// particles in arrays of its own, which move when they grow.
typedef struct wc_cloth_view {
    int32_t particle_count;
    /// Positions, m.
    const double *x;
    const double *y;
    const double *z;
    /// Masses, kg.
    const double *mass;
    /// wc_contact_kind of each particle in the last step.
    const uint8_t *contact;
    /// Unit normal of the surface each particle touched in the last step,
    /// pointing from the surface toward the particle; zero without contact.
    const double *normal_x;
    const double *normal_y;
    const double *normal_z;
    /// Wetness of each particle, [0, 1].
    const double *wetness;
    /// 1 where a particle is stuck: wet and in contact in the last step and
    /// the one before (held by adhesion and wet friction), else 0.
    const uint8_t *stuck;
} wc_cloth_view;

/// Fills a view of a cloth's particles.
WC_API wc_status wc_cloth_get_view(const wc_world *world, int32_t cloth, wc_cloth_view *out_view);

/// Pins particles where they are now (hard pins). Indices must be in range
/// and not already pinned, hard or soft (nor repeated in the list). Hard-
/// pinned particles follow their targets exactly and feel no forces.
WC_API wc_status wc_cloth_pin(wc_world *world, int32_t cloth, const int32_t *indices,
                              int32_t count);

/// Soft-pins particles where they are now: each stays a free particle (it
/// feels every force, collides, gets wet and sticks) and is pulled toward
/// its pin target by a goal spring of stiffness k_i = m_i * stiffness[k]
/// (N/m), m_i its mass (wet mass included): stiffness is the square of the
/// particle's angular frequency about its target, 1/s^2, finite, in
/// (0, 1e8], the same motion at any mesh resolution. Under gravity g a
/// soft-pinned particle hangs g / stiffness below its target, and it swings
/// about it with period 2 pi / sqrt(stiffness). indices and stiffness hold
/// count values each; indices as for wc_cloth_pin. Soft pins join the pin
/// list after the pins already there: wc_cloth_set_pin_targets moves them
/// (their targets moving linearly across substeps, as hard pins do),
/// wc_cloth_pin_count counts them and wc_cloth_unpin_all releases them.
/// Verlet and XPBD treat the spring explicitly, so it shortens their stable
/// step (wc_cloth_stable_dt: omega^2 = stiffness); the implicit integrator
/// puts it in its linear system, where it costs no stability.
WC_API wc_status wc_cloth_pin_soft(wc_world *world, int32_t cloth, const int32_t *indices,
                                   const double *stiffness, int32_t count);

/// Releases every pin, hard and soft.
WC_API wc_status wc_cloth_unpin_all(wc_world *world, int32_t cloth);

/// Number of pins, hard and soft.
WC_API int32_t wc_cloth_pin_count(const wc_world *world, int32_t cloth);

/// Sets where the pins go: one xyz target (m, finite) per pin, hard or soft,
/// in the order the pins were added. They are reached at the end of the next
/// wc_world_step() or wc_world_advance(), moving linearly across its
/// substeps; a soft pin's spring pulls toward its target where it is at the
/// start of each substep (Verlet, XPBD) or at its end (implicit).
WC_API wc_status wc_cloth_set_pin_targets(wc_world *world, int32_t cloth,
                                          const double *targets_xyz, int32_t count);

/// Sets the velocity of the air at each particle (m/s, interleaved xyz,
/// finite, each at most 1e4 m/s long; count = the particle count), held
/// until set again (an application that animates wind sets it every
/// frame). The air drag then acts on the velocity relative to the air,
/// -material.air_drag * A_i * (v_i - u_i), so a cloth in uniform wind u
/// drifts toward u with the time constant density / air_drag (dry cloth).
/// NULL with count 0 clears it: still air again, at no cost. With
/// material.air_drag 0 the air velocity has no effect. Hard-pinned
/// particles ignore it.
WC_API wc_status wc_cloth_set_air_velocity(wc_world *world, int32_t cloth,
                                           const double *velocity_xyz, int32_t count);

/// Sets an external force on each particle as a density per rest area,
/// N/m^2, interleaved xyz (finite, each at most 1e6 N/m^2 long; count = the
/// particle count): particle i feels A_i * p_i with A_i its rest area (see
/// wc_material), so the same field gives the same motion at any mesh
/// resolution (a dry cloth accelerates by p / density). Held until set
/// again; NULL with count 0 clears it, at no cost. Hard-pinned particles
/// ignore it.
WC_API wc_status wc_cloth_set_external_forces(wc_world *world, int32_t cloth,
                                              const double *force_per_area_xyz, int32_t count);

/// Largest stable step, s, for one cloth (see wc_world_stable_dt).
WC_API double wc_cloth_stable_dt(const wc_world *world, int32_t cloth);

/// Mechanical energy of a cloth, J. The work of what acts from outside
/// the cloth (drag, air velocity, external forces, soft pins' springs) is
/// not in it.
typedef struct wc_energy {
    /// 0.5 m v^2 with v as wc_cloth_get_velocities gives it.
    double kinetic;
    /// -m g . x (zero at the origin).
    double gravity;
    /// 0.5 K (d - l)^2 over stretched links.
    double stretch;
    /// 0.5 R c^2 l over compressed bend links (c the arc curvature), the
    /// potential whose gradient is the buckling force (with its onset ramped
    /// in over the first 0.1 % of compression, where the model jumps).
    double bend;
} wc_energy;

/// Computes a cloth's energy in its current state.
WC_API wc_status wc_cloth_get_energy(const wc_world *world, int32_t cloth, wc_energy *out_energy);

/// Copies each particle's contact kind (wc_contact_kind, count values) and
/// surface normal (interleaved xyz, 3 * count values) from the last step.
/// Either output may be NULL. count must equal the particle count.
WC_API wc_status wc_cloth_get_contacts(const wc_world *world, int32_t cloth, uint8_t *out_kind,
                                       double *out_normals_xyz, int32_t count);

/// Sets the wetness of every particle to one value in [0, 1].
WC_API wc_status wc_cloth_set_wetness_uniform(wc_world *world, int32_t cloth, double wetness);

/// Sets each particle's wetness (count values in [0, 1], count = the
/// particle count): a wetness map, e.g. from a Blender vertex group.
WC_API wc_status wc_cloth_set_wetness(wc_world *world, int32_t cloth, const double *wetness,
                                      int32_t count);

/// Copies each particle's wetness (count values).
WC_API wc_status wc_cloth_get_wetness(const wc_world *world, int32_t cloth, double *out_wetness,
                                      int32_t count);

/// Copies each particle's stuck flag (count values, 0 or 1; see wc_cloth_view).
WC_API wc_status wc_cloth_get_stuck(const wc_world *world, int32_t cloth, uint8_t *out_stuck,
                                    int32_t count);

/* ------------------------------------------------------------------------ */
/* Colliders                                                                 */
/* ------------------------------------------------------------------------ */

/// A triangle mesh collider: a thin surface (both sides repel) or the skin of
/// a solid. Static unless wc_collider_set_vertices gives it new positions.
typedef struct wc_mesh_collider_def {
    /// Vertex positions, m, interleaved xyz, 3 * vertex_count finite values. Copied.
    const double *vertices;
    /// Number of vertices, 3 .. 2^26.
    int32_t vertex_count;
    /// Vertex indices, 3 per triangle, each in [0, vertex_count). Copied.
    const int32_t *triangles;
    /// Number of triangles, 1 .. 2^27.
    int32_t triangle_count;
    /// Thickness, m, [0, 1]: cloth particles keep this much (plus the
    /// cloth's thickness) from the surface, the cloth's triangles and edges
    /// 0.9 of it from the mesh's vertices and edges (half of it from a
    /// smooth one, as wc_material's thickness says). Default 0.
    double thickness;
    /// Coulomb friction coefficient, [0, 10]. Default 0.5.
    double friction;
} wc_mesh_collider_def;

/// Default mesh collider description (no geometry).
WC_API wc_mesh_collider_def wc_mesh_collider_def_default(void);

/// Adds a mesh collider; *out_collider receives its index. Degenerate
/// (zero-area) triangles are accepted and ignored; they can come from
/// animation.
WC_API wc_status wc_world_add_mesh_collider(wc_world *world, const wc_mesh_collider_def *def,
                                            int32_t *out_collider);

/// Gives an animated mesh collider new vertex positions (m, interleaved xyz,
/// finite; count = its vertex count). They are reached at the end of the
/// next wc_world_step() or wc_world_advance(), moving linearly across its
/// substeps; contacts use the relative motion, so fast colliders do not
/// tunnel through cloth. A mesh that moves as one piece costs the cloth on
/// it only what the cloth's motion against it costs (docs/c-api.md,
/// Colliders).
WC_API wc_status wc_collider_set_vertices(wc_world *world, int32_t collider, const double *xyz,
                                          int32_t count);

/// Solid convex shapes. Their contacts come from libccd.
typedef enum wc_shape {
    /// Ball of `radius` around the position.
    WC_SHAPE_SPHERE = 0,
    /// Segment from -half_height to +half_height along the local z axis,
    /// swept by a ball of `radius`.
    WC_SHAPE_CAPSULE = 1,
    /// Box with `half_extents` along the local axes.
    WC_SHAPE_BOX = 2,
    /// Convex hull of `points` (local coordinates).
    WC_SHAPE_CONVEX_HULL = 3
} wc_shape;

/// A solid convex collider.
typedef struct wc_convex_collider_def {
    wc_shape shape;
    /// Position of the local origin, m. Default (0, 0, 0).
    double position[3];
    /// Orientation as a unit quaternion (w, x, y, z) (normalised on input;
    /// must not be zero). Default (1, 0, 0, 0).
    double rotation[4];
    /// Sphere and capsule radius, m, (0, 1e6]. Default 0.5.
    double radius;
    /// Capsule half length of its core segment, m, [0, 1e6]. Default 0.5.
    double half_height;
    /// Box half extents, m, each (0, 1e6]. Default (0.5, 0.5, 0.5).
    double half_extents[3];
    /// Hull points, local coordinates, m, interleaved xyz. Copied.
    const double *points;
    /// Number of hull points, 4 .. 65536; they must span a volume.
    int32_t point_count;
    /// Thickness, m, [0, 1]. Default 0.
    double thickness;
    /// Coulomb friction coefficient, [0, 10]. Default 0.5.
    double friction;
} wc_convex_collider_def;

/// Default convex collider: unit-diameter sphere at the origin.
WC_API wc_convex_collider_def wc_convex_collider_def_default(void);

/// Adds a convex collider; *out_collider receives its index (colliders of
/// both kinds share one index space).
WC_API wc_status wc_world_add_convex_collider(wc_world *world, const wc_convex_collider_def *def,
                                              int32_t *out_collider);

/// Moves a convex collider: position (m) and unit quaternion (w, x, y, z),
/// reached at the end of the next step or advance, interpolated across its
/// substeps.
WC_API wc_status wc_collider_set_transform(wc_world *world, int32_t collider,
                                           const double position[3], const double rotation[4]);

/// Number of colliders in the world.
WC_API int32_t wc_world_collider_count(const wc_world *world);

/* ------------------------------------------------------------------------ */
/* Statistics and the intersection checker                                  */
/* ------------------------------------------------------------------------ */

/// What the last step (or, for wc_world_advance, its last substep) did.
typedef struct wc_step_stats {
    /// Particles in contact with a collider.
    int32_t collider_contacts;
    /// Particles in contact with cloth (self-collision).
    int32_t cloth_contacts;
    /// Particles a fail-safe had to put back where they were at the start of
    /// the step, because no response left them free of intersection.
    int32_t failsafe_particles;
    /// Particles stuck (wet, in sustained contact) after the step.
    int32_t stuck_particles;
    /// Wall time in seconds by phase, of the last wc_world_step, or of the
    /// whole last wc_world_advance (all its substeps together): forces
    /// (with the wet pull), integration, collisions (colliders and
    /// self-collision), and the wet response with the commit (stuck marking,
    /// commit, wicking and drying). >= 0; what they do not cover (argument
    /// checks, pin bookkeeping) is negligible.
    double force_seconds;
    double integrate_seconds;
    double collide_seconds;
    double wet_seconds;
    /// Iterations of the implicit integrator's linear solver (preconditioned
    /// conjugate gradients), summed over the cloths and, for
    /// wc_world_advance, over its substeps. 0 for Verlet and XPBD.
    int64_t solver_iterations;
    /// Threads the last step ran on (see wc_world_def.adapt_threads).
    int32_t threads;
    /// Steps of the last wc_world_step or wc_world_advance that were taken
    /// again as two half steps because their collisions would have torn a
    /// cloth (stretched a link past 1.5 times its rest length, by more than
    /// half of it, in that one step), counting each halving, down to 3
    /// halvings (what still tears then is kept); >= 0.
    int32_t halved_steps;
} wc_step_stats;

/// Statistics of the last step.
WC_API wc_step_stats wc_world_get_stats(const wc_world *world);

/// Intersecting triangle pairs in the current state.
typedef struct wc_intersection_counts {
    /// Pairs of cloth triangles that share no vertex and intersect (within a
    /// cloth, and between cloths).
    int32_t cloth_cloth;
    /// Pairs of a cloth triangle and a collider triangle that intersect, plus
    /// cloth triangles that reach inside a convex collider.
    int32_t cloth_collider;
} wc_intersection_counts;

/// Counts intersecting triangle pairs in the current state. Written
/// independently of the collision solver (its own triangle-triangle test and
/// its own broadphase), so tests and benchmarks can trust it to catch what
/// the solver misses. Thickness is ignored: only true intersections count.
WC_API wc_status wc_world_count_intersections(const wc_world *world,
                                              wc_intersection_counts *out_counts);

/* ------------------------------------------------------------------------ */
/* Memory                                                                    */
/* ------------------------------------------------------------------------ */

/// Allocation hook: returns `size` bytes (size >= 1) aligned for any type, as
/// malloc does, or NULL when it cannot. The library zeroes the memory itself.
/// `user` is the pointer given to wc_set_allocator().
typedef void *wc_alloc_fcn(size_t size, void *user);
/// Frees what the allocation hook returned (never called with NULL).
typedef void wc_free_fcn(void *memory, void *user);

/// Routes every heap allocation of the library (worlds, cloths, colliders,
/// the buffers a step grows) through alloc_fcn and free_fcn, in the manner
/// of Box2D's b2SetAllocator. Both NULL (or either NULL) restores malloc and
/// free. Process-wide: call it while no world exists, since a world's
/// memory must be freed by the hook that allocated it. The hooks may be
/// called from several OpenMP threads at once inside a step unless
/// wc_world_def.thread_count is 1. When the hook returns NULL, the call
/// that needed the memory returns WC_ERROR_OUT_OF_MEMORY with a message,
/// frees what it had allocated and leaves the world as it was (a step keeps
/// its last good state). libccd's and OpenMP's own small internal
/// allocations do not pass through the hook.
WC_API void wc_set_allocator(wc_alloc_fcn *alloc_fcn, wc_free_fcn *free_fcn, void *user);

#ifdef __cplusplus
}
#endif

#endif /* WETCLOTH_H */
