"""The binding proper: World, Material, Cloth and colliders over the C API.

Python holds no physics here: every quantity is computed by libwetcloth.
This module converts arguments (numpy arrays in, numpy arrays out), turns
C status codes into WetclothError, and keeps the handles alive and valid.

Every array a property returns is a fresh copy owned by numpy: it stays
valid after the next step and after the world is closed, and writing to it
does not change the simulation.
"""

import dataclasses
import math
import time

import numpy as np

from ._ffi import ffi

lib = None  # set by wetcloth/__init__.py once the library is loaded

_INT32_MIN, _INT32_MAX = -(2 ** 31), 2 ** 31 - 1


class WetclothError(Exception):
    """Bad input, or a call the library refused. ``str(error)`` is the
    library's message (it names the argument, the index, what was expected
    and what was found). ``status`` is the wc_status code, ``status_name``
    its name (e.g. "WC_ERROR_INVALID_ARGUMENT")."""

    def __init__(self, message, status=1):
        super().__init__(message)
        self.status = int(status)
        self.status_name = (ffi.string(lib.wc_status_name(status)).decode()
                            if lib is not None else str(status))


def _bad(message):
    return WetclothError(message, 1)


# ---------------------------------------------------------------------------
# argument conversion


def _float(name, value):
    if isinstance(value, (bool, np.bool_)):
        raise _bad("%s must be a number, found %r" % (name, value))
    try:
        return float(value)
    except (TypeError, ValueError):
        raise _bad("%s must be a number, found %r" % (name, value)) from None


def _int32(name, value):
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise _bad("%s must be an integer, found %r" % (name, value))
    value = int(value)
    if not _INT32_MIN <= value <= _INT32_MAX:
        raise _bad("%s must fit in 32 bits, found %d" % (name, value))
    return value


def _vector(name, value, size):
    try:
        a = np.ascontiguousarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise _bad("%s must be %d numbers, found %r" % (name, size, value)) from None
    if a.shape != (size,):
        raise _bad("%s must be %d numbers, found shape %s" % (name, size, a.shape))
    return a


def _float_array(name, value, columns=None, rows=None):
    """C-contiguous float64 copy-or-view of value with shape (rows, columns)
    (or (rows,) when columns is None); rows None = any."""
    try:
        a = np.ascontiguousarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise _bad("%s must be an array of numbers" % name) from None
    want = (rows if rows is not None else "n",) + ((columns,) if columns else ())
    ok = a.ndim == len(want) and (columns is None or a.shape[1] == columns) and \
        (rows is None or a.shape[0] == rows)
    if not ok:
        raise _bad("%s must have shape (%s), found shape %s" %
                   (name, ", ".join(str(w) for w in want), a.shape))
    return a


def _index_array(name, value, columns=None):
    a = np.asarray(value)
    if a.size == 0:
        a = a.astype(np.int64)
    if a.dtype.kind not in "iu":
        raise _bad("%s must be integers, found %s values" % (name, a.dtype))
    if columns is None:
        if a.ndim != 1:
            raise _bad("%s must be a list of indices, found shape %s" % (name, a.shape))
    elif a.ndim != 2 or a.shape[1] not in columns:
        raise _bad("%s must have shape (n, %s), found shape %s" %
                   (name, " or ".join(str(c) for c in columns), a.shape))
    if a.size and (a.min() < _INT32_MIN or a.max() > _INT32_MAX):
        raise _bad("%s has an index outside 32 bits" % name)
    return np.ascontiguousarray(a, dtype=np.int32)


def _dptr(a):
    return ffi.cast("const double *", ffi.from_buffer(a))


def _iptr(a):
    return ffi.cast("const int32_t *", ffi.from_buffer(a))


# ---------------------------------------------------------------------------
# Material

# Python name -> C field of wc_material.
_MATERIAL_FIELDS = {
    "density": "density",
    "stretch": "stretch_stiffness",
    "bend": "bend_stiffness",
    "damping": "stretch_damping",
    "air_drag": "air_drag",
    "thickness": "thickness",
    "friction": "friction",
    "adhesion": "adhesion",
    "spread": "spread",
    "wet_friction": "wet_friction",
    "wet_grip": "wet_grip",
    "wet_mass_gain": "wet_mass_gain",
    "wet_softening": "wet_softening",
    "wicking": "wicking",
    "drying": "drying",
}


def _make_material_class():
    default = lib.wc_material_default()
    fields = [(py, float, dataclasses.field(default=float(getattr(default, c))))
              for py, c in _MATERIAL_FIELDS.items()]
    doc = """Cloth material in physical units that do not depend on the mesh
    resolution. Every field is optional; the defaults are the library's
    (a plausible cotton). Ranges are checked by the library when a cloth is
    added.

    density        kg/m^2, areal density of the dry cloth (0, 1000]
    stretch        N/m, in-plane stretch stiffness (tension only) [0, 1e9]
    bend           N*m, bending stiffness (compression-only bend links) [0, 1e3]
    damping        fraction of critical damping along stretch links [0, 1]
    air_drag       N*s/m^3, linear air drag [0, 1e4]
    thickness      m, collision thickness [0, 1]
    friction       Coulomb coefficient against colliders and itself [0, 10]
    adhesion       Pa, adhesion pressure of soaked cloth (w = 1) [0, 1e6]
    spread         spread factor beta, pull on neighbours of stuck particles [0, 1]
    wet_friction   q, tangential velocity kept in sustained wet contact [0, 1]
    wet_grip       Pa, most tangential stress wet friction holds before wet
                   cloth slides (0 = no wet friction) [0, 1e6]
    wet_mass_gain  water uptake at w = 1 as a fraction of dry mass [0, 10]
    wet_softening  stiffness loss at w = 1 [0, 0.99]
    wicking        m^2/s, diffusion of wetness along links (0 = off) [0, 1]
    drying         1/s, exponential drying rate (0 = off) [0, 100]

    include/wetcloth.h (wc_material) documents each in full.
    """
    cls = dataclasses.make_dataclass("Material", fields, namespace={"__doc__": doc})
    cls.__module__ = "wetcloth"
    return cls


Material = None  # made in _init() from the library's defaults


def _c_material(material):
    if material is None:
        material = Material()
    if not isinstance(material, Material):
        raise _bad("material must be a wetcloth.Material, found %r" % (material,))
    m = lib.wc_material_default()
    for py, c in _MATERIAL_FIELDS.items():
        setattr(m, c, _float("material.%s" % py, getattr(material, py)))
    return m


def _python_names(message):
    """Adds the Python field name to a C message about a material field."""
    for py, c in _MATERIAL_FIELDS.items():
        if py != c and ("material.%s " % c) in message:
            return message + " (Material.%s)" % py
    return message


# ---------------------------------------------------------------------------
# World


class World:
    """A simulation world: cloths, colliders, stepping.

    gravity        m/s^2, (x, y, z)
    threads        OpenMP threads inside a step at most, 0 = OpenMP's default
    adapt_threads  True (default): each step may run on fewer threads when
                   the world measures that to be faster (a busy machine, a
                   small cloth); the results are the same bits either way.
                   False: always `threads`
    substep_safety fraction of the stable step advance() uses, (0, 1]
    max_substeps   most substeps advance() may choose, 1 .. 10^7
    integrator     "implicit" (default: semi-implicit backward Euler, the
                   measured fast path), "verlet" (explicit, the thesis'
                   reference) or "xpbd" (strain-limited stretch); see
                   docs/model.md
    implicit_tolerance  the implicit integrator's solve tolerance, m/s^2,
                   [0, 1000]: its linear solve stops at an estimated
                   velocity error of this times the step; 0 solves to
                   round-off. None: the library's default,
                   World.DEFAULT_IMPLICIT_TOLERANCE (8.0)

    Use as a context manager, or call close(), to free the C world at once;
    otherwise it is freed when the World and all its cloths and colliders
    are garbage. After close() every call raises WetclothError.
    """

    INTEGRATORS = {"verlet": "WC_INTEGRATOR_VERLET", "xpbd": "WC_INTEGRATOR_XPBD",
                   "implicit": "WC_INTEGRATOR_IMPLICIT"}
    # the library's default (wc_world_def_default), what implicit_tolerance=None
    # means; set by _init once the library is loaded
    DEFAULT_IMPLICIT_TOLERANCE = None

    def __init__(self, gravity=(0.0, 0.0, -9.81), threads=0, substep_safety=0.9,
                 max_substeps=100000, integrator="implicit", implicit_tolerance=None,
                 adapt_threads=True):
        if not isinstance(integrator, str) or integrator not in World.INTEGRATORS:
            raise _bad("integrator must be one of %s but is %r"
                       % (", ".join(repr(k) for k in World.INTEGRATORS), integrator))
        d = lib.wc_world_def_default()
        d.integrator = getattr(lib, World.INTEGRATORS[integrator])
        d.gravity = list(_vector("gravity", gravity, 3))
        d.thread_count = _int32("threads", threads)
        if not isinstance(adapt_threads, (bool, np.bool_)):
            raise _bad("adapt_threads must be True or False but is %r" % (adapt_threads,))
        d.adapt_threads = int(bool(adapt_threads))
        d.substep_safety = _float("substep_safety", substep_safety)
        d.max_substeps = _int32("max_substeps", max_substeps)
        if implicit_tolerance is not None:
            d.implicit_tolerance = _float("implicit_tolerance", implicit_tolerance)
        out = ffi.new("wc_world **")
        msg = ffi.new("wc_message *")
        status = lib.wc_world_create(ffi.new("wc_world_def *", d), out, msg)
        if status != lib.WC_OK:
            raise WetclothError("World: " + ffi.string(msg.text).decode(), status)
        self._ptr = ffi.gc(out[0], lib.wc_world_destroy)
        self.cloths = []
        self.colliders = []
        self._steps = 0
        self._step_seconds = 0.0

    # lifetime ---------------------------------------------------------------

    def close(self):
        """Frees the C world now. Arrays taken from it stay valid (they are
        copies); the World, its cloths and colliders refuse further calls."""
        if self._ptr is not None:
            ptr, self._ptr = self._ptr, None
            ffi.release(ptr)

    @property
    def closed(self):
        return self._ptr is None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def _handle(self):
        if self._ptr is None:
            raise WetclothError("this world is closed", 1)
        return self._ptr

    def _check(self, status, what):
        if status != lib.WC_OK:
            text = ffi.string(lib.wc_world_last_error(self._ptr)).decode()
            raise WetclothError("%s: %s" % (what, _python_names(text)), status)

    # cloths -----------------------------------------------------------------

    def add_grid_cloth(self, nu, nv, size=(1.0, 1.0), center=(0.0, 0.0, 0.0), material=None,
                       wetness=0.0, self_collision=False, axis_u=(1.0, 0.0, 0.0),
                       axis_v=(0.0, 1.0, 0.0), collide_with_cloths=True):
        """A regular grid of nu x nv particles, size (m) along axis_u and
        axis_v, centred at center (m). Particle (i, j) has index j*nu + i;
        x grows with i and y with j (with the default axes), in the plane
        z = center[2]. wetness: a scalar or one value per particle, [0, 1].
        collide_with_cloths: collide with the world's other cloths that do
        (wc_grid_cloth_def.collide_with_cloths)."""
        h = self._handle()
        d = lib.wc_grid_cloth_def_default()
        d.count_u = _int32("nu", nu)
        d.count_v = _int32("nv", nv)
        s = _vector("size", size, 2)
        d.size_u, d.size_v = float(s[0]), float(s[1])
        d.center = list(_vector("center", center, 3))
        d.axis_u = list(_vector("axis_u", axis_u, 3))
        d.axis_v = list(_vector("axis_v", axis_v, 3))
        d.material = _c_material(material)
        d.self_collision = 1 if self_collision else 0
        d.collide_with_cloths = 1 if collide_with_cloths else 0
        n = d.count_u * d.count_v if d.count_u > 0 and d.count_v > 0 else 0
        uniform, wet_map = self._wetness_arg(wetness, n)
        d.wetness = uniform
        out = ffi.new("int32_t *")
        self._check(lib.wc_world_add_grid_cloth(h, ffi.new("wc_grid_cloth_def *", d), out),
                    "add_grid_cloth")
        nu_, nv_ = d.count_u, d.count_v
        i, j = np.meshgrid(np.arange(nu_ - 1), np.arange(nv_ - 1))
        base = (j * nu_ + i).ravel()
        faces = np.stack([base, base + 1, base + nu_ + 1, base + nu_], axis=1).astype(np.int32)
        return self._new_cloth(out[0], faces, wet_map)

    def add_cloth(self, vertices, faces, material=None, wetness=0.0, self_collision=False,
                  collide_with_cloths=True):
        """A cloth from a mesh: vertices (n, 3) in m, faces (F, 3) or (F, 4)
        vertex indices (with 4 columns, a last index of -1 makes a triangle).
        wetness: a scalar or one value per vertex, [0, 1]. collide_with_cloths:
        collide with the world's other cloths that do
        (wc_mesh_cloth_def.collide_with_cloths)."""
        h = self._handle()
        v = _float_array("vertices", vertices, 3)
        f = _index_array("faces", faces, (3, 4))
        d = lib.wc_mesh_cloth_def_default()
        d.vertices = _dptr(v)
        d.vertex_count = v.shape[0]
        d.faces = _iptr(f)
        d.face_count = f.shape[0]
        d.face_size = f.shape[1]
        d.material = _c_material(material)
        d.self_collision = 1 if self_collision else 0
        d.collide_with_cloths = 1 if collide_with_cloths else 0
        uniform, wet_map = self._wetness_arg(wetness, v.shape[0])
        d.wetness = uniform
        out = ffi.new("int32_t *")
        self._check(lib.wc_world_add_mesh_cloth(h, ffi.new("wc_mesh_cloth_def *", d), out),
                    "add_cloth")
        return self._new_cloth(out[0], f.copy(), wet_map)

    @staticmethod
    def _wetness_arg(wetness, n):
        """(uniform value for the def, per-particle map or None). A map is
        checked here in full, because it is applied after the cloth exists
        and a failure then would leave the cloth added."""
        if np.ndim(wetness) == 0:
            return _float("wetness", wetness), None
        w = _float_array("wetness", wetness, rows=n)
        bad = np.flatnonzero(~((w >= 0.0) & (w <= 1.0)))
        if bad.size:
            raise _bad("wetness[%d] must be in [0, 1] but is %r" % (bad[0], float(w[bad[0]])))
        return 0.0, w

    def _new_cloth(self, index, faces, wet_map):
        cloth = Cloth(self, index, faces)
        if wet_map is not None:
            cloth.set_wetness(wet_map)
        self.cloths.append(cloth)
        return cloth

    # colliders --------------------------------------------------------------

    def add_mesh_collider(self, vertices, triangles, thickness=0.0, friction=0.3):
        """A triangle mesh collider: vertices (n, 3) in m, triangles (T, 3).
        Static until set_vertices() animates it."""
        h = self._handle()
        v = _float_array("vertices", vertices, 3)
        t = _index_array("triangles", triangles, (3,))
        d = lib.wc_mesh_collider_def_default()
        d.vertices = _dptr(v)
        d.vertex_count = v.shape[0]
        d.triangles = _iptr(t)
        d.triangle_count = t.shape[0]
        d.thickness = _float("thickness", thickness)
        d.friction = _float("friction", friction)
        out = ffi.new("int32_t *")
        self._check(lib.wc_world_add_mesh_collider(h, ffi.new("wc_mesh_collider_def *", d), out),
                    "add_mesh_collider")
        c = MeshCollider(self, out[0], v.copy(), t.copy(), d.thickness, d.friction)
        self.colliders.append(c)
        return c

    def _add_convex(self, what, shape, thickness, friction, position=(0.0, 0.0, 0.0),
                    rotation=(1.0, 0.0, 0.0, 0.0), radius=None, half_height=None,
                    half_extents=None, points=None, params=None):
        h = self._handle()
        d = lib.wc_convex_collider_def_default()
        d.shape = shape
        d.position = list(_vector("center", position, 3))
        d.rotation = list(_vector("rotation", rotation, 4))
        if radius is not None:
            d.radius = _float("radius", radius)
        if half_height is not None:
            d.half_height = _float("half_height", half_height)
        if half_extents is not None:
            d.half_extents = list(_vector("half_extents", half_extents, 3))
        keep = None
        if points is not None:
            keep = _float_array("points", points, 3)
            d.points = _dptr(keep)
            d.point_count = keep.shape[0]
        d.thickness = _float("thickness", thickness)
        d.friction = _float("friction", friction)
        out = ffi.new("int32_t *")
        self._check(lib.wc_world_add_convex_collider(h, ffi.new("wc_convex_collider_def *", d),
                                                     out), what)
        c = ConvexCollider(self, out[0], what.replace("add_", ""), np.array(list(d.position)),
                           np.array(list(d.rotation)), d.thickness, d.friction, params or {})
        self.colliders.append(c)
        return c

    def add_sphere(self, center, radius, thickness=0.0, friction=0.3):
        """A solid ball of radius (m) around center (m)."""
        return self._add_convex("add_sphere", lib.WC_SHAPE_SPHERE, thickness, friction,
                                position=center, radius=radius,
                                params={"radius": _float("radius", radius)})

    def add_box(self, center, half_extents, rotation=(1.0, 0.0, 0.0, 0.0), thickness=0.0,
                friction=0.3):
        """A solid box with half_extents (m) along its axes, centred at
        center (m), turned by the unit quaternion rotation (w, x, y, z)."""
        return self._add_convex("add_box", lib.WC_SHAPE_BOX, thickness, friction,
                                position=center, rotation=rotation, half_extents=half_extents,
                                params={"half_extents": _vector("half_extents", half_extents,
                                                                3).tolist()})

    def add_capsule(self, a, b, radius, thickness=0.0, friction=0.3):
        """A solid capsule: the segment from a to b (m) swept by a ball of
        radius (m)."""
        a = _vector("a", a, 3)
        b = _vector("b", b, 3)
        axis = b - a
        length = float(np.linalg.norm(axis))
        rotation = _quaternion_z_to(axis / length) if length > 0.0 else (1.0, 0.0, 0.0, 0.0)
        return self._add_convex("add_capsule", lib.WC_SHAPE_CAPSULE, thickness, friction,
                                position=(a + b) / 2, rotation=rotation, radius=radius,
                                half_height=length / 2,
                                params={"radius": _float("radius", radius),
                                        "half_height": length / 2})

    def add_convex(self, points, thickness=0.0, friction=0.3):
        """A solid convex hull of points (k, 3), m; at least 4 points that
        span a volume."""
        pts = _float_array("points", points, 3)
        return self._add_convex("add_convex", lib.WC_SHAPE_CONVEX_HULL, thickness, friction,
                                points=pts, params={"points": pts.copy()})

    # stepping ---------------------------------------------------------------

    def step(self, dt):
        """One step of dt seconds, (0, 10]. Pin and collider targets are
        reached at its end."""
        h = self._handle()
        dt = _float("dt", dt)
        start = time.perf_counter()
        status = lib.wc_world_step(h, dt)
        self._step_seconds += time.perf_counter() - start
        if status == lib.WC_OK:
            self._steps += 1
        self._check(status, "step")

    def advance(self, frame_dt, substeps=0):
        """One frame of frame_dt seconds in `substeps` equal steps; 0 picks
        the count from the stable step. Returns the substeps used."""
        h = self._handle()
        frame_dt = _float("frame_dt", frame_dt)
        substeps = _int32("substeps", substeps)
        t0 = lib.wc_world_time(h)
        start = time.perf_counter()
        status = lib.wc_world_advance(h, frame_dt, substeps)
        self._step_seconds += time.perf_counter() - start
        used = lib.wc_world_last_substeps(h)
        if status == lib.WC_OK:
            self._steps += used
        elif lib.wc_world_time(h) > t0 and used > 0:
            # the substeps that succeeded before the failure
            self._steps += int(round((lib.wc_world_time(h) - t0) / (frame_dt / used)))
        self._check(status, "advance")
        return used

    def stable_dt(self):
        """Largest stable step, s (inf without cloth)."""
        return float(lib.wc_world_stable_dt(self._handle()))

    @property
    def time(self):
        """Simulated time, s."""
        return float(lib.wc_world_time(self._handle()))

    def count_intersections(self):
        """Intersecting triangle pairs now, from the library's independent
        checker: {"cloth_cloth": int, "cloth_collider": int}."""
        h = self._handle()
        out = ffi.new("wc_intersection_counts *")
        self._check(lib.wc_world_count_intersections(h, out), "count_intersections")
        return {"cloth_cloth": int(out.cloth_cloth), "cloth_collider": int(out.cloth_collider)}

    @property
    def stats(self):
        """What the world has done: steps (successful steps so far), time
        (simulated, s), last_substeps, and from the last step collider_contacts,
        cloth_contacts, failsafe_particles, stuck_particles; step_seconds is
        the wall time spent inside step() and advance(); phase_seconds is the
        library's wall time by phase (forces, integrate, collide, wet) of the
        last step(), or of all substeps of the last advance(); and
        solver_iterations, the implicit integrator's conjugate-gradient
        iterations over the same steps (0 for the other integrators); threads,
        the threads the last step ran on; halved_steps, the steps of the last
        step() or advance() taken again as two half steps because their
        collisions would have torn a cloth."""
        h = self._handle()
        s = lib.wc_world_get_stats(h)
        return {
            "steps": self._steps,
            "time": float(lib.wc_world_time(h)),
            "last_substeps": int(lib.wc_world_last_substeps(h)),
            "collider_contacts": int(s.collider_contacts),
            "cloth_contacts": int(s.cloth_contacts),
            "failsafe_particles": int(s.failsafe_particles),
            "stuck_particles": int(s.stuck_particles),
            "step_seconds": self._step_seconds,
            "phase_seconds": {
                "forces": float(s.force_seconds),
                "integrate": float(s.integrate_seconds),
                "collide": float(s.collide_seconds),
                "wet": float(s.wet_seconds),
            },
            "solver_iterations": int(s.solver_iterations),
            "threads": int(s.threads),
            "halved_steps": int(s.halved_steps),
        }


def _quaternion_z_to(direction):
    """Unit quaternion (w, x, y, z) turning +z onto the unit vector."""
    z = np.array([0.0, 0.0, 1.0])
    c = float(np.dot(z, direction))
    if c < -1.0 + 1e-12:
        return (0.0, 1.0, 0.0, 0.0)  # half turn about x
    axis = np.cross(z, direction)
    q = np.array([1.0 + c, axis[0], axis[1], axis[2]])
    return tuple(q / np.linalg.norm(q))


# ---------------------------------------------------------------------------
# Cloth


class Cloth:
    """A cloth in a world (from World.add_grid_cloth or World.add_cloth).

    Array properties return fresh numpy copies (see the module docstring).
    """

    def __init__(self, world, index, faces):
        self.world = world
        self.index = int(index)
        self.particle_count = int(lib.wc_cloth_particle_count(world._ptr, index))
        #: faces as given (a grid: its quads), (F, 3) or (F, 4) int32
        self.faces = faces
        self.faces.setflags(write=False)

    def _get(self, fn, dtype, shape, what):
        h = self.world._handle()
        out = np.empty(shape, dtype=dtype)
        ctype = {np.float64: "double *", np.uint8: "uint8_t *", np.int32: "int32_t *"}[dtype]
        self.world._check(fn(h, self.index, ffi.cast(ctype, ffi.from_buffer(out)),
                             self.particle_count), what)
        return out

    @property
    def positions(self):
        """(n, 3) float64 positions, m."""
        return self._get(lib.wc_cloth_get_positions, np.float64, (self.particle_count, 3),
                         "positions")

    def set_positions(self, positions):
        """Moves every particle to positions (n, 3), m, at rest."""
        h = self.world._handle()
        p = _float_array("positions", positions, 3, self.particle_count)
        self.world._check(lib.wc_cloth_set_positions(h, self.index, _dptr(p),
                                                     self.particle_count), "set_positions")

    @property
    def velocities(self):
        """(n, 3) float64 velocities, m/s (from the last step)."""
        return self._get(lib.wc_cloth_get_velocities, np.float64, (self.particle_count, 3),
                         "velocities")

    def set_velocities(self, velocities):
        h = self.world._handle()
        v = _float_array("velocities", velocities, 3, self.particle_count)
        self.world._check(lib.wc_cloth_set_velocities(h, self.index, _dptr(v),
                                                      self.particle_count), "set_velocities")

    @property
    def wetness(self):
        """(n,) float64 wetness of each particle, [0, 1]."""
        return self._get(lib.wc_cloth_get_wetness, np.float64, (self.particle_count,), "wetness")

    def set_wetness(self, wetness):
        """Sets the wetness: a scalar for every particle, or (n,) values, [0, 1]."""
        h = self.world._handle()
        if np.ndim(wetness) == 0:
            self.world._check(lib.wc_cloth_set_wetness_uniform(
                h, self.index, _float("wetness", wetness)), "set_wetness")
            return
        w = _float_array("wetness", wetness, rows=self.particle_count)
        self.world._check(lib.wc_cloth_set_wetness(h, self.index, _dptr(w),
                                                   self.particle_count), "set_wetness")

    @property
    def stuck(self):
        """(n,) bool: stuck in the last step (wet and in sustained contact)."""
        return self._get(lib.wc_cloth_get_stuck, np.uint8, (self.particle_count,),
                         "stuck").astype(bool)

    def _contacts(self):
        h = self.world._handle()
        kind = np.empty(self.particle_count, dtype=np.uint8)
        normals = np.empty((self.particle_count, 3), dtype=np.float64)
        self.world._check(lib.wc_cloth_get_contacts(
            h, self.index, ffi.cast("uint8_t *", ffi.from_buffer(kind)),
            ffi.cast("double *", ffi.from_buffer(normals)), self.particle_count), "contacts")
        return kind, normals

    @property
    def in_contact(self):
        """(n,) bool: touched a collider or cloth in the last step."""
        return self._contacts()[0] != lib.WC_CONTACT_NONE

    @property
    def contact_kind(self):
        """(n,) uint8: 0 none, 1 collider, 2 cloth, in the last step."""
        return self._contacts()[0]

    @property
    def contact_normals(self):
        """(n, 3) unit normals of the surfaces touched in the last step (from
        the surface toward the particle), zero without contact."""
        return self._contacts()[1]

    @property
    def triangles(self):
        """(T, 3) int32 surface triangles (quads split in two)."""
        h = self.world._handle()
        count = int(lib.wc_cloth_triangle_count(h, self.index))
        out = np.empty((count, 3), dtype=np.int32)
        self.world._check(lib.wc_cloth_get_triangles(
            h, self.index, ffi.cast("int32_t *", ffi.from_buffer(out)), count), "triangles")
        return out

    @property
    def masses(self):
        """(n,) particle masses, kg (wet mass included)."""
        h = self.world._handle()
        view = ffi.new("wc_cloth_view *")
        self.world._check(lib.wc_cloth_get_view(h, self.index, view), "masses")
        return np.frombuffer(ffi.buffer(view.mass, 8 * self.particle_count),
                             dtype=np.float64).copy()

    def pin(self, indices, stiffness=None):
        """Pins particles where they are now (indices not yet pinned).

        stiffness None: hard pins, which follow their targets exactly and
        feel no forces. A number for all, or one per index, 1/s^2 in
        (0, 1e8]: soft pins, free particles (they feel every force, collide
        and get wet) pulled toward their targets by springs of stiffness
        mass * stiffness, so stiffness is the square of a particle's angular
        frequency about its target: under gravity g it hangs g / stiffness
        below it and swings with period 2 pi / sqrt(stiffness), at any mesh
        resolution. Hard and soft pins share one list, in the order pinned:
        set_pin_targets moves them, pin_count counts them, unpin_all
        releases them. Soft pins shorten the stable step of "verlet" and
        "xpbd" (to at most 2 / sqrt(stiffness)); "implicit" solves them
        implicitly."""
        h = self.world._handle()
        idx = _index_array("indices", indices)
        if stiffness is None:
            self.world._check(lib.wc_cloth_pin(h, self.index, _iptr(idx), idx.shape[0]), "pin")
            return
        if np.ndim(stiffness) == 0:
            s = np.full(idx.shape[0], _float("stiffness", stiffness))
        else:
            s = _float_array("stiffness", stiffness, rows=idx.shape[0])
        self.world._check(lib.wc_cloth_pin_soft(h, self.index, _iptr(idx), _dptr(s),
                                                idx.shape[0]), "pin")

    def unpin_all(self):
        """Releases every pin, hard and soft."""
        h = self.world._handle()
        self.world._check(lib.wc_cloth_unpin_all(h, self.index), "unpin_all")

    @property
    def pin_count(self):
        """Number of pins, hard and soft."""
        return int(lib.wc_cloth_pin_count(self.world._handle(), self.index))

    def set_pin_targets(self, positions):
        """Where the pins go, (pin_count, 3) m in the order they were pinned
        (hard and soft); reached at the end of the next step or advance."""
        h = self.world._handle()
        t = _float_array("positions", positions, 3, self.pin_count)
        self.world._check(lib.wc_cloth_set_pin_targets(h, self.index, _dptr(t), t.shape[0]),
                          "set_pin_targets")

    def set_air_velocity(self, velocity):
        """The velocity of the air at each particle, m/s: an (n, 3) array, or
        one 3-vector for every particle (uniform wind); None for still air
        again. Held until set again (set it every frame to animate wind).
        The drag acts on the velocity relative to the air,
        -Material.air_drag * A * (v - u), so the cloth drifts toward the
        wind's velocity with the time constant density / air_drag; with
        air_drag 0 it has no effect. Each vector finite, at most 1e4 m/s."""
        self._set_field(lib.wc_cloth_set_air_velocity, "velocity", velocity,
                        "set_air_velocity")

    def set_external_forces(self, force_per_area):
        """An external force on each particle as a density per rest area,
        N/m^2: an (n, 3) array, or one 3-vector for every particle; None to
        clear it. A particle of rest area A feels A * p, so the same field
        gives the same motion at any mesh resolution (a dry cloth
        accelerates by p / density). Held until set again; hard-pinned
        particles ignore it. Each vector finite, at most 1e6 N/m^2."""
        self._set_field(lib.wc_cloth_set_external_forces, "force_per_area", force_per_area,
                        "set_external_forces")

    def _set_field(self, fn, name, value, what):
        h = self.world._handle()
        if value is None:
            self.world._check(fn(h, self.index, ffi.NULL, 0), what)
            return
        n = self.particle_count
        try:
            a = np.ascontiguousarray(value, dtype=np.float64)
        except (TypeError, ValueError):
            raise _bad("%s: %s must be 3 numbers or an array of shape (%d, 3), found %r"
                       % (what, name, n, value)) from None
        if a.shape == (3,):
            a = np.ascontiguousarray(np.broadcast_to(a, (n, 3)))
        elif a.shape != (n, 3):
            raise _bad("%s: %s must be 3 numbers (one vector for every particle) or an array "
                       "of shape (%d, 3), found shape %s" % (what, name, n, a.shape))
        self.world._check(fn(h, self.index, _dptr(a), n), "%s: %s" % (what, name))

    def stable_dt(self):
        """Largest stable step of this cloth for the world's integrator, s."""
        return float(lib.wc_cloth_stable_dt(self.world._handle(), self.index))

    @property
    def energy(self):
        """{"kinetic", "gravity", "stretch", "bend"}, J."""
        h = self.world._handle()
        e = ffi.new("wc_energy *")
        self.world._check(lib.wc_cloth_get_energy(h, self.index, e), "energy")
        return {"kinetic": e.kinetic, "gravity": e.gravity, "stretch": e.stretch,
                "bend": e.bend}


# ---------------------------------------------------------------------------
# Colliders


class MeshCollider:
    """A triangle mesh collider (World.add_mesh_collider)."""

    def __init__(self, world, index, vertices, triangles, thickness, friction):
        self.world = world
        self.index = int(index)
        self.kind = "mesh"
        self._vertices = vertices
        self.triangles = triangles
        self.triangles.setflags(write=False)
        self.thickness = thickness
        self.friction = friction

    @property
    def vertices(self):
        """(n, 3) the positions last given (a copy)."""
        return self._vertices.copy()

    def set_vertices(self, vertices):
        """New positions (n, 3), m, reached at the end of the next step or
        advance; contacts use the relative motion."""
        h = self.world._handle()
        v = _float_array("vertices", vertices, 3, self._vertices.shape[0])
        self.world._check(lib.wc_collider_set_vertices(h, self.index, _dptr(v), v.shape[0]),
                          "set_vertices")
        self._vertices = v.copy()


class ConvexCollider:
    """A solid convex collider: sphere, box, capsule or convex hull."""

    def __init__(self, world, index, kind, position, rotation, thickness, friction, params):
        self.world = world
        self.index = int(index)
        self.kind = kind
        self.position = position
        self.rotation = rotation
        self.thickness = thickness
        self.friction = friction
        #: shape parameters: radius, half_height, half_extents or points
        self.params = params

    def set_transform(self, position, rotation=None):
        """Moves the shape: position (m) and unit quaternion (w, x, y, z),
        reached at the end of the next step or advance."""
        h = self.world._handle()
        p = _vector("position", position, 3)
        r = self.rotation if rotation is None else _vector("rotation", rotation, 4)
        self.world._check(lib.wc_collider_set_transform(h, self.index, _dptr(p), _dptr(r)),
                          "set_transform")
        self.position, self.rotation = p.copy(), np.array(r, dtype=np.float64)


def _init(loaded_lib):
    global lib, Material
    lib = loaded_lib
    World.DEFAULT_IMPLICIT_TOLERANCE = float(lib.wc_world_def_default().implicit_tolerance)
    Material = _make_material_class()
    return Material
