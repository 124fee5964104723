"""Blender's force fields evaluated at the cloth's particles.

Blender's cloth responds to the scene's force fields (effectors); a Wet
Cloth bake does too. This module reads the Wind, Force and Turbulence fields
of a scene at the current frame and evaluates them at the cloth's particles,
for the library: it computes no motion (the library integrates), only what
the fields are at given points. Blender's own code is the reference
throughout: source/blender/blenkernel/intern/effect.cc (get_effector_data,
effector_falloff, falloff_func, do_physical_effector), cited below by
function name.

What the library takes, per particle per frame:

* the air velocity u (m/s): its air drag on a particle is
  -air_drag * A * (v - u), so the cloth is pulled toward moving with the air;
* an external force density f (N per m² of cloth area).

The mapping, field by field (s: the field's Strength; F: the falloff below;
W: the cloth's Field Weights for the field's type times their All):

* Wind -> air velocity  u = s * F * W * z, z the field object's world Z axis
  (normalised), s read as m/s. Blender's wind is a force along z
  (do_physical_effector: force = z * s * F) which its cloth applies as a
  pressure along each face's normal, plus, with the field's Flow (1 by
  default), a drag -Flow * F * v: with Flow 1 that is F * (s z - v), a drag
  toward air moving at s z. Here the wind is that air's velocity, and the
  library's own air drag does the pulling: a cloth in wind moves toward the
  wind's speed, not faster. Flow itself is not applied (the air moves at s
  whatever it is; Blender's terminal speed would be s / Flow).
* Force -> force density  f = s * F * W * d, d the unit vector from the
  field to the particle (get_effector_data: from the object's origin for
  the Point shape; from the closest point of the object's XY plane for
  Plane, so along +z or -z, away from the plane; from the closest point of
  its Z axis for Line), s read as N/m² (Blender's cloth too applies it per
  unit area of its faces: implicit.h, SIM_mass_spring_force_face_extern): a
  positive strength pushes away, a negative one pulls, as in Blender.
  Gravitation (1/distance²) is honoured; Flow is not applied.
* Turbulence -> force density  f = s * F * W * t, t Blender's noise vector:
  t_i = 2 T(p_i) - 1 with T Blender's turbulence (BLI_noise_generic_turbulence,
  3 octaves of "new Perlin" noise, p scaled by 1/Size) at the particle's
  position p, taken relative to the field (p - origin + z) unless Global
  Coordinates is on, its components permuted per axis (x y z, y z x, z x y)
  as do_physical_effector's PFIELD_TURBULENCE does. Evaluated with
  mathutils.noise (see turbulence_noise): deterministic, each component in
  [-1, 1], so |f_i| <= |s| F W.

The falloff F (effector_falloff, falloff_func) is Blender's: Sphere, Tube
and Cone falloff types, Power, Min/Max Distance, the Radial settings of Tube
and Cone, and Shape's Z direction (Both, +Z, -Z); see falloff(). The shape
sets the distance the Sphere falloff uses (see geometry()): for a Plane
Wind (its default) that is the height above the object's XY plane.

Gravity is not a field: gravity() gives the scene's gravity times the
Gravity weight, which is what Blender's cloth takes (SIM_mass_spring.cc,
cloth_calc_force); All weighs the fields only.

python/tests/blender/test_fields.py checks these values against closed
forms and against Blender itself (its particle simulation evaluates the
same fields: equal to float precision; its cloth, which objects act).

Which objects are effectors (as BKE_effector_relations_create and
BKE_effectors_create): objects with a supported field that Blender counts as
enabled, i.e. objects of the view layer that are not disabled in viewports
(the object's or a containing collection's monitor icon, or excluded from
the view layer), or with the cloth's Effector Collection set, the objects of
that collection (and its children) not disabled there, whether or not in the
view layer. Hiding an object or collection in the view layer (the eye icon)
does not stop its field, in Blender either. A render depsgraph uses the
render flags instead. Fields on particle systems are not read (listed in
`ignored`).

Not evaluated: Vortex, Magnetic, Harmonic, Charge, Lennard-Jones, Texture,
Curve Guide, Boid, Drag and Fluid Flow fields (listed in `ignored`); of the
supported ones: Noise Amount (Blender adds a random strength each step),
Flow, Wind Factor, Absorption, and the Surface and Every Point shapes
(evaluated as Point); each such case is listed in `notes`.
"""

from types import SimpleNamespace

import numpy as np

SUPPORTED = ("WIND", "FORCE", "TURBULENCE")

# What each supported field gives the library.
AIR, FORCE = "air", "force"
OUTPUT = {"WIND": AIR, "FORCE": FORCE, "TURBULENCE": FORCE}

# Shapes evaluated as Blender does; others are evaluated as POINT.
SHAPES = ("POINT", "LINE", "PLANE")

# The field settings read (FieldSettings' names): copied when the sampler is
# built, so that it holds no reference into Blender's evaluated data (which
# the next depsgraph evaluation frees).
SETTINGS = ("type", "strength", "shape", "falloff_type", "z_direction", "falloff_power",
            "use_min_distance", "distance_min", "use_max_distance", "distance_max",
            "radial_falloff", "use_radial_min", "radial_min", "use_radial_max", "radial_max",
            "use_gravity_falloff", "size", "use_global_coords")

# Blender's normalize_v3 leaves a vector whose squared length is not above
# this as zero (BLI_math_vector_inline.c).
_NORMALIZE_EPS = 1.0e-35
_FLT_EPSILON = float(np.finfo(np.float32).eps)

# 2 T - 1 of Blender's 3-octave turbulence T, written with the signed noise N
# of mathutils (N = 2 U - 1, U Blender's unsigned noise):
#   T = (2^2 / (2^3 - 1)) * sum_{k=0..2} 0.5^k U(2^k q)
#   2 T - 1 = (4/7) * sum_k 0.5^k (N_k + 1) - 1 = (4/7) * sum_k 0.5^k N_k
# (the constants cancel: (4/7) * 1.75 = 1), and sum_k 0.5^k N_k is what
# mathutils.noise.turbulence(q, 3, False) returns.
_TURBULENCE_OCTAVES = 3  # Blender's oct = 2 counts from 0 to 2
_TURBULENCE_SCALE = 4.0 / 7.0
_TURBULENCE_BASIS = "PERLIN_NEW"  # Blender's noisebasis 2 (newPerlinU)


# ---------------------------------------------------------------------------
# Falloff (effector_falloff, falloff_func)


def falloff_func(fac, use_min, min_value, use_max, max_value, power):
    """Blender's falloff_func over an array of distances `fac`:
    0 beyond max (if used), 1 below min (if used), else
    (1 + fac - min) ** -power, min counting only if used."""
    fac = np.asarray(fac, dtype=np.float64)
    if power == 0.0:
        out = np.ones_like(fac)
    else:
        start = min_value if use_min else 0.0
        # entries below min are set to 1 below; the clamp keeps them finite
        out = np.maximum(1.0 + fac - start, 1.0) ** -power
    if use_min:
        out = np.where(fac < min_value, 1.0, out)
    if use_max:
        out = np.where(fac > max_value, 0.0, out)
    return out


def _distance_falloff(field, fac):
    """falloff_func_dist: the field's Min/Max Distance and Power."""
    return falloff_func(fac, field.use_min_distance, field.distance_min,
                        field.use_max_distance, field.distance_max, field.falloff_power)


def _radial_falloff(field, fac):
    """falloff_func_rad: the field's Radial Min/Max and Radial Power."""
    return falloff_func(fac, field.use_radial_min, field.radial_min,
                        field.use_radial_max, field.radial_max, field.radial_falloff)


def falloff(field, z, rel, axial, distance):
    """Blender's effector_falloff, without the weights: (n,) factors.

    z: (3,) the field object's unit Z axis; rel: (n, 3) particle minus the
    object's origin; axial: (n,) rel . z; distance: (n,) the distance of the
    field's shape (see geometry()).

    * Z direction +Z / -Z: 0 where axial < 0 / axial > 0;
    * Sphere: falloff_func_dist(distance);
    * Tube: falloff_func_dist(|axial|) * falloff_func_rad(|rel - axial z|);
    * Cone: falloff_func_dist(|axial|) * falloff_func_rad(angle), the angle
      between rel and z in degrees (radial min/max are angles here); at the
      origin itself the angle is taken as 0.
    """
    kind = field.falloff_type
    if kind == "TUBE":
        radial = np.linalg.norm(rel - axial[:, None] * z, axis=1)
        out = _distance_falloff(field, np.abs(axial)) * _radial_falloff(field, radial)
    elif kind == "CONE":
        length = np.linalg.norm(rel, axis=1)
        cos = np.divide(axial, length, out=np.ones_like(axial), where=length > 0.0)
        angle = np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))
        out = _distance_falloff(field, np.abs(axial)) * _radial_falloff(field, angle)
    else:  # SPHERE
        out = _distance_falloff(field, distance)
    if field.z_direction == "POSITIVE":
        out = np.where(axial < 0.0, 0.0, out)
    elif field.z_direction == "NEGATIVE":
        out = np.where(axial > 0.0, 0.0, out)
    return out


# ---------------------------------------------------------------------------
# Geometry (get_effector_data)


def geometry(shape, origin, z, points):
    """What get_effector_data computes for an object's field at `points`:
    (rel, axial, vec, distance).

    rel (n, 3): points - origin (Blender's vec_to_point2); axial (n,): rel . z
    (the fac of effector_falloff); vec (n, 3): from the field to the point
    (vec_to_point) and distance (n,) its length, by shape:

    * POINT: from the origin, vec = rel;
    * PLANE: from the closest point of the object's XY plane, vec = axial z;
    * LINE: from the closest point of the object's Z axis, vec = rel - axial z.
    """
    rel = points - origin
    axial = rel @ z
    along = axial[:, None] * z
    if shape == "PLANE":
        vec = along
    elif shape == "LINE":
        vec = rel - along
    else:
        vec = rel
    return rel, axial, vec, np.linalg.norm(vec, axis=1)


def _unit_rows(vec):
    """Rows of vec normalised, 0 where too short (as normalize_v3)."""
    sq = np.einsum("ij,ij->i", vec, vec)
    ok = sq > _NORMALIZE_EPS
    out = np.zeros_like(vec)
    out[ok] = vec[ok] / np.sqrt(sq[ok])[:, None]
    return out


# ---------------------------------------------------------------------------
# Turbulence noise


def turbulence_noise(points, size):
    """Blender's turbulence vector (do_physical_effector, PFIELD_TURBULENCE)
    at points (n, 3): component i is 2 T(p_i) - 1, T = BLI_noise_generic_
    turbulence(size, ., 2 octaves from 0, soft, new Perlin) at the point with
    its coordinates in the order x y z, y z x, z x y. Each is in [-1, 1].

    mathutils.noise has no array form, so this is a Python loop over the
    points (three calls each); the sampler calls it only for the points the
    falloff does not zero, and only when a Turbulence field exists."""
    from mathutils import noise  # Blender's; imported here so that the module loads without it

    q = np.asarray(points, dtype=np.float64)
    if size != 0.0:  # Blender skips the scaling for a zero size
        q = q / size
    turb = noise.turbulence
    octaves, basis = _TURBULENCE_OCTAVES, _TURBULENCE_BASIS
    flat = [turb(p, octaves, False, noise_basis=basis)
            for x, y, z in q.tolist()
            for p in ((x, y, z), (y, z, x), (z, x, y))]
    return _TURBULENCE_SCALE * np.array(flat, dtype=np.float64).reshape(-1, 3)


# ---------------------------------------------------------------------------
# Effectors


class Effector:
    """One field object at the current frame: its field settings (a copy of
    SETTINGS), world origin and unit Z axis, and the cloth's weight for it
    (All times the type's). evaluate() gives its contribution at points."""

    def __init__(self, name, field, matrix, weight):
        m = np.array(matrix, dtype=np.float64).reshape(4, 4)
        field = SimpleNamespace(**{k: getattr(field, k) for k in SETTINGS})
        self.name = name
        self.type = field.type
        self.output = OUTPUT[field.type]
        self.field = field
        self.strength = float(field.strength)
        self.weight = float(weight)
        self.origin = m[:3, 3].copy()
        z = m[:3, 2]
        length = np.linalg.norm(z)
        # normalize_v3 of the matrix's Z column (a degenerate scale gives 0)
        self.z = z / length if length * length > _NORMALIZE_EPS else np.zeros(3)
        self.shape = field.shape if field.shape in SHAPES else "POINT"

    def falloff(self, rel, axial, distance):
        """effector_falloff, weights included: (n,)."""
        return self.weight * falloff(self.field, self.z, rel, axial, distance)

    def evaluate(self, points):
        """(n, 3): the air velocity (Wind) or force density (Force,
        Turbulence) this field gives at points."""
        rel, axial, vec, distance = geometry(self.shape, self.origin, self.z, points)
        fall = self.falloff(rel, axial, distance)
        if self.type == "WIND":
            return (self.strength * fall)[:, None] * self.z
        if self.type == "FORCE":
            return _force(self.field, self.strength, vec, distance, fall)
        return _turbulence(self.field, self.strength, points, rel, self.z, fall)


def _force(field, strength, vec, distance, fall):
    """do_physical_effector, PFIELD_FORCE: along vec, s * F (times
    1/distance² with Gravitation, 0 within FLT_EPSILON of the field)."""
    s = np.full(distance.shape, strength)
    if field.use_gravity_falloff:
        far = distance >= _FLT_EPSILON
        s = np.where(far, s / np.where(far, distance, 1.0) ** 2, 0.0)
    return _unit_rows(vec) * (s * fall)[:, None]


def _turbulence(field, strength, points, rel, z, fall):
    """do_physical_effector, PFIELD_TURBULENCE: the noise vector at the
    point (global) or at rel + z (the field's own coordinates), times s * F;
    noise is computed only where F is not 0."""
    out = np.zeros_like(points)
    live = np.flatnonzero(fall != 0.0)
    if live.size:
        where = points[live] if field.use_global_coords else rel[live] + z
        out[live] = turbulence_noise(where, float(field.size)) * (strength * fall[live])[:, None]
    return out


# ---------------------------------------------------------------------------
# Which objects are effectors (BKE_effector_relations_create)


def _hidden(thing, render):
    return thing.hide_render if render else thing.hide_viewport


def _enabled_in_layer(layer_collection, render, restricted, found):
    """Objects of a view layer's collections that Blender enables
    (BASE_ENABLED_VIEWPORT / _RENDER): in a collection not excluded, with
    neither it, a collection above it nor the object disabled. An object in
    several collections is enabled if one of them enables it."""
    if layer_collection.exclude:
        return
    restricted = restricted or _hidden(layer_collection.collection, render)
    if not restricted:
        for ob in layer_collection.collection.objects:
            if not _hidden(ob, render):
                found.setdefault(ob.as_pointer(), ob)
    for child in layer_collection.children:
        _enabled_in_layer(child, render, restricted, found)


def _enabled_in_collection(collection, render, restricted, found):
    """The same within a collection (the Effector Collection): its objects
    and its children's, the collection's own flag included, view layer or
    not (BKE_collection_object_cache_get)."""
    restricted = restricted or _hidden(collection, render)
    if not restricted:
        for ob in collection.objects:
            if not _hidden(ob, render):
                found.setdefault(ob.as_pointer(), ob)
    for child in collection.children:
        _enabled_in_collection(child, render, restricted, found)


def effector_candidates(view_layer, collection, render=False):
    """The objects Blender considers as effectors, in order found."""
    found = {}
    if collection is not None:
        _enabled_in_collection(collection, render, False, found)
    else:
        _enabled_in_layer(view_layer.layer_collection, render, False, found)
    return list(found.values())


def _type_weight(weights, field_type):
    return {"WIND": weights.wind, "FORCE": weights.force,
            "TURBULENCE": weights.turbulence}[field_type]


def _notes(ob, field):
    """What of a supported field is not evaluated, as words."""
    out = []
    if field.shape not in SHAPES:
        out.append("shape %s evaluated as Point" % field.shape.title())
    if field.noise > 0.0:
        out.append("noise amount not applied")
    # the Wind mapping is Blender's wind with its default Flow of 1
    if field.flow != (1.0 if field.type == "WIND" else 0.0):
        out.append("flow %g not applied" % field.flow)
    if field.type != "WIND" and field.wind_factor != 0.0:
        out.append("wind factor not applied")
    if field.use_absorption:
        out.append("absorption not applied")
    return [(ob.name, field.type, text) for text in out]


class FieldSampler:
    """The scene's Wind, Force and Turbulence fields at the current frame,
    evaluated at a cloth's particles.

    Build one per frame (after scene.frame_set), so that animated fields
    (strength, transform) are read at that frame, then call sample().

    Attributes:
        effectors: the Effector of each field that acts.
        ignored: (object name, field type) of each field present but not
            supported (Vortex, Magnetic, ..., and fields of particle
            systems), so that the bake can say they were ignored.
        notes: (object name, field type, text) of each part of a supported
            field that is not applied (see the module's docstring).
    """

    def __init__(self, scene, view_layer, depsgraph, weights, exclude=()):
        """Collects the scene's effectors at the current frame.

        weights: Blender's Field Weights of the cloth, or any object with
            the float attributes all_, gravity, wind, force, turbulence and
            `collection` (a Collection or None: then only its objects are
            effectors, as Field Weights > Effector Collection).
        exclude: objects that are never effectors (the cloths being baked).
        """
        self.weights = weights
        self.effectors = []
        self.ignored = []
        self.notes = []
        render = getattr(depsgraph, "mode", "VIEWPORT") == "RENDER"
        excluded = {ob.as_pointer() for ob in exclude}  # names can repeat across libraries
        for ob in effector_candidates(view_layer, weights.collection, render):
            if ob.as_pointer() in excluded:
                continue
            ev = ob.evaluated_get(depsgraph)
            self._ignore_particle_fields(ev)
            field = ev.field
            if field is None or field.type == "NONE":
                continue
            if field.type not in SUPPORTED:
                self.ignored.append((ob.name, field.type))
                continue
            weight = weights.all_ * _type_weight(weights, field.type)
            # is_effector_relevant: no weight, not applied to location, or
            # (for what is evaluated here) no strength: no effect
            if weight == 0.0 or not field.apply_to_location or field.strength == 0.0:
                continue
            self.effectors.append(Effector(ob.name, field, ev.matrix_world, weight))
            self.notes.extend(_notes(ob, field))

    def _ignore_particle_fields(self, ob):
        for psys in getattr(ob, "particle_systems", ()):
            for pd in (psys.settings.force_field_1, psys.settings.force_field_2):
                if pd is not None and pd.type != "NONE":
                    self.ignored.append(("%s (particles %s)" % (ob.name, psys.name), pd.type))

    def has(self, output):
        """Whether some field gives `output` (AIR or FORCE)."""
        return any(e.output == output for e in self.effectors)

    def sample(self, positions, velocities=None):
        """The fields at the particles.

        positions, velocities: (n, 3) world space (m, m/s). The velocities
        are not used by the fields evaluated here (in Blender only Flow,
        Drag, Magnetic and Vortex read them); they are taken so that the
        bake's call stays the same when such fields come.

        Returns (air_velocity, force_per_area): each an (n, 3) float64 array
        (m/s; N/m²), the sum over the fields, or None when no field gives it
        (a scene without fields costs nothing). A field whose falloff is 0 at
        every particle still gives an array (of zeros).
        """
        x = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
        air = np.zeros_like(x) if self.has(AIR) else None
        force = np.zeros_like(x) if self.has(FORCE) else None
        for e in self.effectors:
            target = air if e.output == AIR else force
            target += e.evaluate(x)
        return air, force

    def gravity(self, scene):
        """(3,) the scene's gravity (0 when Gravity is off) times the cloth's
        Gravity weight. All does not scale it: in Blender's cloth gravity is
        scene gravity * Field Weights > Gravity only (SIM_mass_spring.cc,
        cloth_calc_force); All weighs the effectors (effector_falloff's
        weight[0])."""
        if not scene.use_gravity:
            return np.zeros(3)
        return np.array(scene.gravity, dtype=np.float64) * float(self.weights.gravity)
