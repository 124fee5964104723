"""Scene files (JSON): loading with strict checks, building a World, running.

docs/scenes.md documents the format: every field, unit and default. A
scene that cannot be used raises SceneError, whose message names the file
and the field (as a path such as ``cloths[0].material.density``) or the
line, what was expected and what was found.

The runner writes everything into a temporary folder beside the output
folder and moves the files into place only when the run has finished, so a
failed run leaves no output behind.
"""

import json
import math
import os
import re
import shutil
import tempfile
import time

import numpy as np

from . import _core, meshio
from ._core import Material, WetclothError, World

FORMAT_VERSION = 1


class SceneError(Exception):
    """A scene file that cannot be used. str() is the full message:
    "FILE: FIELD: what is wrong" (or "FILE:LINE:COLUMN: ..." for JSON
    syntax)."""

    def __init__(self, source, where, message):
        self.source, self.where, self.message = source, where, message
        super().__init__("%s: %s: %s" % (source, where, message) if where
                         else "%s: %s" % (source, message))


_REQUIRED = object()


def _type_name(value):
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "a boolean (%s)" % json.dumps(value)
    if isinstance(value, int) and value.bit_length() > 64:
        # Python refuses to print integers past 4300 digits
        return "a %d-bit integer" % value.bit_length()
    if isinstance(value, (int, float)):
        return "the number %s" % json.dumps(value)
    if isinstance(value, str):
        return "the string %s" % json.dumps(value)
    if isinstance(value, list):
        return "an array of %d" % len(value)
    if isinstance(value, dict):
        return "an object"
    return type(value).__name__


class _Reader:
    """Reads one JSON object, field by field, with the path for messages."""

    def __init__(self, source, path, value, allowed):
        self.source, self.path = source, path
        if not isinstance(value, dict):
            self.fail(None, "expected an object, found %s" % _type_name(value))
        for key in value:
            if key not in allowed:
                self.fail(key, "unknown field; expected one of: %s" % ", ".join(allowed))
        self.value = value

    def where(self, key):
        if key is None:
            return self.path
        return "%s.%s" % (self.path, key) if self.path else key

    def fail(self, key, message):
        raise SceneError(self.source, self.where(key), message)

    def has(self, key):
        return key in self.value

    def raw(self, key, default=_REQUIRED):
        if key not in self.value:
            if default is _REQUIRED:
                self.fail(key, "missing (required)")
            return default
        return self.value[key]

    def number(self, key, default=_REQUIRED, minimum=None, maximum=None, above=None):
        v = self.raw(key, default)
        if v is default and key not in self.value:
            return v
        return check_number(self.fail, key, v, minimum, maximum, above)

    def integer(self, key, default=_REQUIRED, minimum=None, maximum=None):
        v = self.raw(key, default)
        if key not in self.value:
            return v
        if isinstance(v, bool) or not isinstance(v, int):
            self.fail(key, "expected an integer, found %s" % _type_name(v))
        if minimum is not None and v < minimum:
            self.fail(key, "must be at least %d, found %d" % (minimum, v))
        if maximum is not None and v > maximum:
            self.fail(key, "must be at most %d, found %d" % (maximum, v))
        return v

    def boolean(self, key, default=_REQUIRED):
        v = self.raw(key, default)
        if key in self.value and not isinstance(v, bool):
            self.fail(key, "expected true or false, found %s" % _type_name(v))
        return v

    def string(self, key, default=_REQUIRED, pattern=None, choices=None):
        v = self.raw(key, default)
        if key not in self.value:
            return v
        if not isinstance(v, str):
            self.fail(key, "expected a string, found %s" % _type_name(v))
        if choices is not None and v not in choices:
            self.fail(key, "expected one of %s, found %s" %
                      (", ".join(json.dumps(c) for c in choices), json.dumps(v)))
        if pattern is not None and not re.fullmatch(pattern, v):
            self.fail(key, "must match %s (letters, digits, _ and -), found %s" %
                      (pattern, json.dumps(v)))
        return v

    def vector(self, key, size, default=_REQUIRED):
        v = self.raw(key, default)
        if key not in self.value:
            return v
        return check_vector(self.fail, key, v, size)

    def array(self, key, default=_REQUIRED, min_items=0):
        v = self.raw(key, default)
        if key not in self.value:
            return v
        if not isinstance(v, list):
            self.fail(key, "expected an array, found %s" % _type_name(v))
        if len(v) < min_items:
            self.fail(key, "expected at least %d item%s, found %d" %
                      (min_items, "s" if min_items > 1 else "", len(v)))
        return v


def check_number(fail, key, v, minimum=None, maximum=None, above=None):
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        fail(key, "expected a number, found %s" % _type_name(v))
    try:
        v = float(v)
    except OverflowError:
        fail(key, "expected a finite number, found %s, too large for a double" % _type_name(v))
    if not math.isfinite(v):
        fail(key, "expected a finite number, found %r" % v)
    if above is not None and not v > above:
        fail(key, "must be greater than %g, found %g" % (above, v))
    if minimum is not None and v < minimum:
        fail(key, "must be at least %g, found %g" % (minimum, v))
    if maximum is not None and v > maximum:
        fail(key, "must be at most %g, found %g" % (maximum, v))
    return v


def check_vector(fail, key, v, size):
    if not isinstance(v, list) or len(v) != size:
        fail(key, "expected an array of %d numbers, found %s" % (size, _type_name(v)))
    for i, x in enumerate(v):
        check_number(fail, "%s[%d]" % (key, i), x)
    return [float(x) for x in v]


# ---------------------------------------------------------------------------
# the scene description

MATERIAL_FIELDS = list(_core._MATERIAL_FIELDS)
SCENE_FIELDS = ["description", "format_version", "duration", "fps", "substeps", "threads",
                "gravity", "start_frame", "integrator", "implicit_tolerance", "cloths",
                "colliders"]
CLOTH_FIELDS = ["name", "grid", "obj", "material", "wetness", "pins", "pin_stiffness",
                "pin_keyframes", "air_velocity", "external_force", "self_collision",
                "collide_with_cloths"]
GRID_FIELDS = ["nu", "nv", "size", "center", "axis_u", "axis_v"]
COLLIDER_TYPES = ["mesh", "sphere", "box", "capsule", "convex"]
COLLIDER_FIELDS = {
    "mesh": ["obj", "vertices", "triangles"],
    "sphere": ["center", "radius"],
    "box": ["center", "half_extents", "rotation"],
    "capsule": ["a", "b", "radius"],
    "convex": ["points"],
}
COMMON_COLLIDER_FIELDS = ["type", "name", "thickness", "friction", "keyframes"]
KEYFRAME_FIELDS = ["time", "translate"]
NAME_PATTERN = r"[A-Za-z0-9_\-]+"
# the library's limits (wc_cloth_pin_soft, wc_cloth_set_air_velocity,
# wc_cloth_set_external_forces), checked here so that the message names the
# scene's field
MAX_PIN_STIFFNESS = 1e8
# per-cloth fields given as a vector or keyframes: (largest length, unit,
# what the value is)
VECTOR_FIELDS = {
    "air_velocity": (1e4, "m/s", "air velocity"),
    "external_force": (1e6, "N/m^2", "force density"),
}


class Keyframes:
    """A piecewise-linear vector over time (a translation, or a field's
    value), held before the first and after the last keyframe."""

    def __init__(self, times, offsets):
        self.times = np.array(times, dtype=np.float64)
        self.offsets = np.array(offsets, dtype=np.float64).reshape(-1, 3)

    def at(self, t):
        if self.times.size == 0:
            return np.zeros(3)
        return np.array([np.interp(t, self.times, self.offsets[:, k]) for k in range(3)])


def _keyframes(reader, key, value_key="translate", check=None):
    """Keyframes {"time", value_key}; check(fail, key, vector) checks each
    value."""
    items = reader.array(key, [])
    times, offsets = [], []
    for i, item in enumerate(items):
        k = _Reader(reader.source, "%s[%d]" % (reader.where(key), i), item,
                    ["time", value_key])
        t = k.number("time", minimum=0.0)
        if times and t <= times[-1]:
            k.fail("time", "keyframe times must increase, found %g after %g" % (t, times[-1]))
        times.append(t)
        offsets.append(k.vector(value_key, 3))
        if check is not None:
            check(k.fail, value_key, offsets[-1])
    return Keyframes(times, offsets)


def _vector_field(reader, key):
    """A per-cloth field (VECTOR_FIELDS): None when absent, a constant
    3-vector, or Keyframes of {"time", "value"} (values between keyframes
    are convex combinations of theirs, so checking the keyframes' lengths
    checks every value)."""
    if not reader.has(key):
        return None
    limit, unit, what = VECTOR_FIELDS[key]

    def check(fail, where, v):
        length = math.sqrt(sum(x * x for x in v))
        if not length <= limit:
            fail(where, "the %s must be at most %g %s long, found [%s] (%g %s)" %
                 (what, limit, unit, ", ".join("%g" % x for x in v), length, unit))

    v = reader.raw(key)
    if isinstance(v, list) and any(isinstance(x, dict) for x in v):
        return _keyframes(reader, key, "value", check)
    if not isinstance(v, list) or len(v) != 3:
        reader.fail(key, "expected 3 numbers (a constant %s, %s) or an array of keyframes "
                    "{\"time\": s, \"value\": [x, y, z]}, found %s" % (what, unit, _type_name(v)))
    vector = reader.vector(key, 3)
    check(reader.fail, key, vector)
    return vector


def _pin_stiffness(reader, pins):
    """None (hard pins), one stiffness for every pin, or one per pin."""
    if not reader.has("pin_stiffness"):
        return None
    v = reader.raw("pin_stiffness")
    if not pins:
        reader.fail("pin_stiffness", "there are no pins to make soft")
    if isinstance(v, list):
        if len(v) != len(pins):
            reader.fail("pin_stiffness", "expected a number or an array of %d numbers (one per "
                        "pin), found an array of %d" % (len(pins), len(v)))
        return [check_number(reader.fail, "pin_stiffness[%d]" % i, x, maximum=MAX_PIN_STIFFNESS,
                             above=0.0) for i, x in enumerate(v)]
    return check_number(reader.fail, "pin_stiffness", v, maximum=MAX_PIN_STIFFNESS, above=0.0)


class Scene:
    """A checked scene; see load()."""

    def __init__(self, source, base_dir):
        self.source = source
        self.base_dir = base_dir
        self.cloths = []
        self.colliders = []

    @property
    def frame_count(self):
        """Simulated frames (the caches hold one more: the start)."""
        return max(1, int(round(self.duration * self.fps)))


def load(path):
    """Reads and checks a scene file; raises SceneError."""
    try:
        with open(path, encoding="utf-8") as f:
            text = f.read()
    except OSError as e:
        raise SceneError(path, "", "cannot read the scene file: %s" % (e.strerror or e)) from None
    except UnicodeDecodeError as e:
        raise SceneError(path, "", "not UTF-8 text: %s" % e) from None
    try:
        data = json.loads(text)
    except json.JSONDecodeError as e:
        raise SceneError("%s:%d:%d" % (path, e.lineno, e.colno), "",
                         "invalid JSON: %s" % e.msg) from None
    except ValueError as e:  # an integer of more than 4300 digits
        raise SceneError(path, "", "invalid JSON: %s" % e) from None
    except RecursionError:
        raise SceneError(path, "", "invalid JSON: nested too deeply") from None
    return from_dict(data, path, os.path.dirname(os.path.abspath(path)))


def from_dict(data, source, base_dir):
    """Checks a scene given as parsed JSON (source names it in messages;
    OBJ paths are relative to base_dir)."""
    r = _Reader(source, "", data, SCENE_FIELDS)
    s = Scene(source, base_dir)
    r.string("description", "")
    version = r.integer("format_version", FORMAT_VERSION)
    if version != FORMAT_VERSION:
        r.fail("format_version", "this wetcloth reads format_version %d, found %d" %
               (FORMAT_VERSION, version))
    s.duration = r.number("duration", 2.0, above=0.0, maximum=1e5)
    s.fps = r.number("fps", 24.0, minimum=0.1, maximum=1e5)  # frames of at most 10 s
    s.substeps = r.integer("substeps", 0, minimum=0, maximum=10 ** 7)
    s.threads = r.integer("threads", 0, minimum=0, maximum=1024)
    s.gravity = r.vector("gravity", 3, [0.0, 0.0, -9.81])
    s.integrator = r.string("integrator", "implicit", choices=["verlet", "xpbd", "implicit"])
    # None: the library's default
    s.implicit_tolerance = r.number("implicit_tolerance", None, minimum=0.0, maximum=1000.0)
    s.start_frame = r.number("start_frame", 1.0)
    if s.duration * s.fps > 1e6:
        r.fail("duration", "duration x fps must be at most 1e6 frames, found %g" %
               (s.duration * s.fps))
    names = set()
    for i, item in enumerate(r.array("cloths", min_items=1)):
        c = _cloth(s, "cloths[%d]" % i, item, i)
        if c["name"] in names:
            raise SceneError(source, "cloths[%d].name" % i,
                             "another cloth is already called %s" % json.dumps(c["name"]))
        names.add(c["name"])
        s.cloths.append(c)
    for i, item in enumerate(r.array("colliders", [])):
        s.colliders.append(_collider(s, "colliders[%d]" % i, item, i))
    return s


def _obj_path(scene, reader, key):
    rel = reader.string(key)
    return rel, os.path.join(scene.base_dir, rel)


def _cloth(scene, path, item, index):
    r = _Reader(scene.source, path, item, CLOTH_FIELDS)
    c = {"path": path, "name": r.string("name", "cloth%d" % index if index else "cloth",
                                        pattern=NAME_PATTERN)}
    if r.has("grid") == r.has("obj"):
        r.fail(None, "give exactly one of \"grid\" (a regular grid) and \"obj\" (a mesh file)")
    if r.has("grid"):
        g = _Reader(scene.source, r.where("grid"), r.raw("grid"), GRID_FIELDS)
        c["grid"] = {
            "nu": g.integer("nu", minimum=2, maximum=32768),
            "nv": g.integer("nv", minimum=2, maximum=32768),
            "size": g.vector("size", 2, [1.0, 1.0]),
            "center": g.vector("center", 3, [0.0, 0.0, 0.0]),
            "axis_u": g.vector("axis_u", 3, [1.0, 0.0, 0.0]),
            "axis_v": g.vector("axis_v", 3, [0.0, 1.0, 0.0]),
        }
        c["particle_count"] = c["grid"]["nu"] * c["grid"]["nv"]
    else:
        rel, full = _obj_path(scene, r, "obj")
        try:
            vertices, faces = meshio.read_obj(full)
            c["vertices"], c["faces"] = vertices, meshio.cloth_faces(faces, full)
        except meshio.MeshError as e:
            r.fail("obj", str(e))
        c["obj"] = rel
        c["particle_count"] = len(vertices)
    m = _Reader(scene.source, r.where("material"), r.raw("material", {}), MATERIAL_FIELDS)
    c["material"] = {k: m.number(k) for k in MATERIAL_FIELDS if m.has(k)}
    wet = r.raw("wetness", 0.0)
    if isinstance(wet, list):
        n = c["particle_count"]
        if len(wet) != n:
            r.fail("wetness", "expected a number or an array of %d numbers (one per particle), "
                   "found an array of %d" % (n, len(wet)))
        c["wetness"] = [check_number(r.fail, "wetness[%d]" % i, x, 0.0, 1.0)
                        for i, x in enumerate(wet)]
    else:
        c["wetness"] = check_number(r.fail, "wetness", wet, 0.0, 1.0)
    pins = r.array("pins", [])
    for i, p in enumerate(pins):
        if isinstance(p, bool) or not isinstance(p, int):
            r.fail("pins[%d]" % i, "expected a particle index, found %s" % _type_name(p))
        if not 0 <= p < c["particle_count"]:
            r.fail("pins[%d]" % i, "particle index must be in [0, %d), found %d" %
                   (c["particle_count"], p))
    c["pins"] = pins
    c["pin_stiffness"] = _pin_stiffness(r, pins)
    c["pin_keyframes"] = _keyframes(r, "pin_keyframes")
    if c["pin_keyframes"].times.size and not pins:
        r.fail("pin_keyframes", "there are no pins to move")
    for key in VECTOR_FIELDS:
        c[key] = _vector_field(r, key)
    c["self_collision"] = r.boolean("self_collision", False)
    c["collide_with_cloths"] = r.boolean("collide_with_cloths", True)
    return c


def _collider(scene, path, item, index):
    if isinstance(item, dict) and isinstance(item.get("type"), str) \
            and item["type"] in COLLIDER_FIELDS:
        allowed = COMMON_COLLIDER_FIELDS + COLLIDER_FIELDS[item["type"]]
    else:
        allowed = None
    if allowed is None:  # no usable type yet: "type" gets the message
        allowed = list(item) if isinstance(item, dict) else []
    r = _Reader(scene.source, path, item, allowed)
    kind = r.string("type", choices=COLLIDER_TYPES)
    c = {"path": path, "type": kind,
         "name": r.string("name", "collider%d" % index, pattern=NAME_PATTERN),
         "thickness": r.number("thickness", 0.0, minimum=0.0),
         "friction": r.number("friction", 0.3, minimum=0.0),
         "keyframes": _keyframes(r, "keyframes")}
    if kind == "mesh":
        if r.has("obj") == (r.has("vertices") or r.has("triangles")):
            r.fail(None, "give either \"obj\" (a mesh file) or \"vertices\" and \"triangles\"")
        if r.has("obj"):
            rel, full = _obj_path(scene, r, "obj")
            try:
                vertices, faces = meshio.read_obj(full)
            except meshio.MeshError as e:
                r.fail("obj", str(e))
            c["vertices"], c["triangles"] = vertices, meshio.triangulate(faces)
            c["obj"] = rel
        else:
            verts = r.array("vertices", min_items=3)
            c["vertices"] = np.array([check_vector(r.fail, "vertices[%d]" % i, v, 3)
                                      for i, v in enumerate(verts)])
            tris = r.array("triangles", min_items=1)
            out = []
            for i, t in enumerate(tris):
                key = "triangles[%d]" % i
                if not isinstance(t, list) or len(t) != 3 or \
                        any(isinstance(k, bool) or not isinstance(k, int) for k in t):
                    r.fail(key, "expected 3 vertex indices, found %s" % _type_name(t))
                for k in t:
                    if not 0 <= k < len(verts):
                        r.fail(key, "vertex index must be in [0, %d), found %d" % (len(verts), k))
                out.append(t)
            c["triangles"] = np.array(out, dtype=np.int64)
    elif kind == "sphere":
        c["center"] = r.vector("center", 3)
        c["radius"] = r.number("radius", above=0.0)
    elif kind == "box":
        c["center"] = r.vector("center", 3)
        c["half_extents"] = r.vector("half_extents", 3)
        c["rotation"] = r.vector("rotation", 4, [1.0, 0.0, 0.0, 0.0])
    elif kind == "capsule":
        c["a"] = r.vector("a", 3)
        c["b"] = r.vector("b", 3)
        c["radius"] = r.number("radius", above=0.0)
    else:
        pts = r.array("points", min_items=4)
        c["points"] = np.array([check_vector(r.fail, "points[%d]" % i, p, 3)
                                for i, p in enumerate(pts)])
    return c


# ---------------------------------------------------------------------------
# building a world


class Built:
    """A world made from a scene: world, cloths and colliders (in scene
    order), and what animates them."""

    def __init__(self, scene, world):
        self.scene = scene
        self.world = world
        self.cloths = []      # (spec, Cloth, pin start positions)
        self.colliders = []   # (spec, collider, rest geometry)

    def set_fields(self, t):
        """The keyframed air velocity and external force density at time t,
        held until set again (the run sets them at the middle of each
        frame: on a linear stretch of keyframes, the frame's mean). Constant
        ones were set when the world was built."""
        for spec, cloth, _ in self.cloths:
            for key, setter in (("air_velocity", cloth.set_air_velocity),
                                ("external_force", cloth.set_external_forces)):
                if isinstance(spec[key], Keyframes):
                    setter(spec[key].at(t))

    def set_targets(self, t):
        """Pin and collider targets for time t (the end of the next frame)."""
        for spec, cloth, start in self.cloths:
            if spec["pin_keyframes"].times.size:
                cloth.set_pin_targets(start + spec["pin_keyframes"].at(t))
        for spec, col, rest in self.colliders:
            if spec["keyframes"].times.size:
                offset = spec["keyframes"].at(t)
                if spec["type"] == "mesh":
                    col.set_vertices(rest + offset)
                else:
                    col.set_transform(rest + offset)


def build(scene, threads=None):
    """A World for the scene; a library refusal becomes SceneError naming
    the scene element."""
    def guarded(where, call, *args, **kwargs):
        try:
            return call(*args, **kwargs)
        except WetclothError as e:
            raise SceneError(scene.source, where, str(e)) from None

    world = guarded("gravity", World, gravity=scene.gravity,
                    threads=scene.threads if threads is None else threads,
                    integrator=scene.integrator, implicit_tolerance=scene.implicit_tolerance)
    b = Built(scene, world)
    try:
        for c in scene.cloths:
            material = Material(**c["material"])
            wetness = np.array(c["wetness"]) if isinstance(c["wetness"], list) else c["wetness"]
            if "grid" in c:
                g = c["grid"]
                cloth = guarded(c["path"], world.add_grid_cloth, g["nu"], g["nv"],
                                size=g["size"], center=g["center"], axis_u=g["axis_u"],
                                axis_v=g["axis_v"], material=material, wetness=wetness,
                                self_collision=c["self_collision"],
                                collide_with_cloths=c["collide_with_cloths"])
            else:
                cloth = guarded(c["path"], world.add_cloth, c["vertices"], c["faces"],
                                material=material, wetness=wetness,
                                self_collision=c["self_collision"],
                                collide_with_cloths=c["collide_with_cloths"])
            start = np.zeros((0, 3))
            if c["pins"]:
                guarded(c["path"] + ".pins", cloth.pin, c["pins"], stiffness=c["pin_stiffness"])
                start = cloth.positions[c["pins"]]
            for key, setter in (("air_velocity", cloth.set_air_velocity),
                                ("external_force", cloth.set_external_forces)):
                field = c[key]
                if field is not None:
                    value = field.at(0.0) if isinstance(field, Keyframes) else field
                    guarded("%s.%s" % (c["path"], key), setter, value)
            b.cloths.append((c, cloth, start))
        for c in scene.colliders:
            k = c["type"]
            common = {"thickness": c["thickness"], "friction": c["friction"]}
            offset = c["keyframes"].at(0.0)
            if k == "mesh":
                rest = c["vertices"]
                col = guarded(c["path"], world.add_mesh_collider, rest + offset, c["triangles"],
                              **common)
            elif k == "sphere":
                rest = np.array(c["center"])
                col = guarded(c["path"], world.add_sphere, rest + offset, c["radius"], **common)
            elif k == "box":
                rest = np.array(c["center"])
                col = guarded(c["path"], world.add_box, rest + offset, c["half_extents"],
                              rotation=c["rotation"], **common)
            elif k == "capsule":
                rest = (np.array(c["a"]) + np.array(c["b"])) / 2
                col = guarded(c["path"], world.add_capsule, np.array(c["a"]) + offset,
                              np.array(c["b"]) + offset, c["radius"], **common)
            else:
                rest = -offset  # the hull's points are placed at offset(0) already
                col = guarded(c["path"], world.add_convex, c["points"] + offset, **common)
            b.colliders.append((c, col, rest))
    except BaseException:
        world.close()
        raise
    return b


# ---------------------------------------------------------------------------
# running


class RunError(Exception):
    """The simulation failed (the library refused a step)."""


def run(scene, out_dir, progress=True, check="every", threads=None, frames=None,
        log=None):
    """Runs the scene and writes into out_dir: <cloth>.pc2 (every frame, the
    start included), <cloth>.obj (the last frame), stats.json and
    preview.png. Nothing is written to out_dir unless the run succeeds.
    Returns the stats dict."""
    from tqdm import tqdm

    from . import preview

    if check not in ("every", "final", "none"):
        raise ValueError("check must be every, final or none")
    if os.path.exists(out_dir) and not os.path.isdir(out_dir):
        raise SceneError(out_dir, "", "the output path exists and is not a folder")
    built = build(scene, threads)
    world = built.world
    frame_count = scene.frame_count if frames is None else min(frames, scene.frame_count)
    parent = os.path.dirname(os.path.abspath(out_dir))
    os.makedirs(parent, exist_ok=True)
    tmp = tempfile.mkdtemp(prefix=".%s.tmp-" % os.path.basename(os.path.abspath(out_dir)),
                           dir=parent)
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o777 & ~umask)  # mkdtemp makes it 0700; the output folder is a normal one
    caches = []
    try:
        for spec, cloth, _ in built.cloths:
            caches.append(meshio.PC2Writer(os.path.join(tmp, spec["name"] + ".pc2"),
                                           cloth.particle_count, frame_count + 1,
                                           start=scene.start_frame))
            caches[-1].write(cloth.positions)
        per_frame = []
        sim_seconds = check_seconds = 0.0
        frame_dt = 1.0 / scene.fps
        started = time.perf_counter()
        bar = tqdm(total=frame_count, unit="frame", disable=not progress,
                   desc=os.path.basename(scene.source), dynamic_ncols=True)
        try:
            for f in range(1, frame_count + 1):
                t0 = time.perf_counter()
                try:
                    built.set_fields((f - 0.5) * frame_dt)
                    built.set_targets(f * frame_dt)
                    used = world.advance(frame_dt, scene.substeps)
                except WetclothError as e:
                    raise RunError("frame %d (t = %.4g s): %s" % (f, f * frame_dt, e)) from None
                wall = time.perf_counter() - t0
                sim_seconds += wall
                s = world.stats
                record = {"frame": f, "substeps": used, "seconds": wall,
                          "phase_seconds": s["phase_seconds"],
                          "solver_iterations": s["solver_iterations"],
                          "collider_contacts": s["collider_contacts"],
                          "cloth_contacts": s["cloth_contacts"],
                          "failsafe_particles": s["failsafe_particles"],
                          "stuck": [int(c.stuck.sum()) for _, c, _ in built.cloths]}
                if check == "every" or (check == "final" and f == frame_count):
                    t1 = time.perf_counter()
                    record["intersections"] = world.count_intersections()
                    check_seconds += time.perf_counter() - t1
                for cache, (_, cloth, _) in zip(caches, built.cloths):
                    cache.write(cloth.positions)
                per_frame.append(record)
                bar.update(1)
                bar.set_postfix(substeps=used, stuck=sum(record["stuck"]), refresh=False)
        finally:
            bar.close()
        for cache in caches:
            cache.close()
        caches = []
        total = time.perf_counter() - started
        stats = _stats(scene, built, per_frame, frame_count, sim_seconds, check_seconds, total,
                       check)
        for spec, cloth, _ in built.cloths:
            meshio.write_obj(os.path.join(tmp, spec["name"] + ".obj"), cloth.positions,
                             cloth.faces, spec["name"],
                             comment="libwetcloth %s: %s, cloth %s, frame %d (t = %.4g s)\n"
                                     "units: metres, z up" % (
                                         _version(), os.path.basename(scene.source),
                                         spec["name"], frame_count, frame_count / scene.fps))
        with open(os.path.join(tmp, "stats.json"), "w", encoding="utf-8") as f:
            json.dump(stats, f, indent=1)
            f.write("\n")
        preview.render(built, os.path.join(tmp, "preview.png"),
                       title="%s, frame %d (t = %.2f s)" % (os.path.basename(scene.source),
                                                            frame_count,
                                                            frame_count / scene.fps))
        meshio.replace_into(tmp, out_dir)
        tmp = None
        return stats
    finally:
        for cache in caches:
            cache.file.close()
        if tmp is not None:
            shutil.rmtree(tmp, ignore_errors=True)
        world.close()


def _version():
    from . import __version__
    return __version__


def _stats(scene, built, per_frame, frame_count, sim_seconds, check_seconds, total, check):
    subs = [r["substeps"] for r in per_frame]
    secs = [r["seconds"] for r in per_frame]
    checked = [r for r in per_frame if "intersections" in r]
    cloths = []
    for k, (spec, cloth, _) in enumerate(built.cloths):
        stuck, contact, wet = cloth.stuck, cloth.in_contact, cloth.wetness
        cloths.append({
            "name": spec["name"], "particles": cloth.particle_count,
            "stuck_final": int(stuck.sum()), "in_contact_final": int(contact.sum()),
            "wetness_mean_final": float(wet.mean()),
            "stuck_max": max(r["stuck"][k] for r in per_frame),
        })
    return {
        "scene": scene.source,
        "wetcloth_version": _version(),
        "frames": frame_count,
        "fps": scene.fps,
        "simulated_seconds": built.world.time,
        "threads": scene.threads,
        "steps": built.world.stats["steps"],
        "substeps_per_frame": {"min": min(subs), "max": max(subs),
                               "mean": sum(subs) / len(subs)},
        "seconds": {
            "total": total,
            "simulation": sim_seconds,
            "simulation_per_frame_mean": sim_seconds / frame_count,
            "simulation_per_frame_max": max(secs),
            "simulation_per_step_mean": sim_seconds / max(1, built.world.stats["steps"]),
            "intersection_checks": check_seconds,
            # the library's own split of the simulation time
            "by_phase": {k: sum(r["phase_seconds"][k] for r in per_frame)
                         for k in ("forces", "integrate", "collide", "wet")},
        },
        # the implicit integrator's conjugate-gradient iterations (0 for the others)
        "solver_iterations": {
            "total": sum(r["solver_iterations"] for r in per_frame),
            "per_step_mean": sum(r["solver_iterations"] for r in per_frame)
            / max(1, built.world.stats["steps"]),
        },
        "contacts": {
            "collider_final": per_frame[-1]["collider_contacts"],
            "collider_max": max(r["collider_contacts"] for r in per_frame),
            "cloth_final": per_frame[-1]["cloth_contacts"],
            "cloth_max": max(r["cloth_contacts"] for r in per_frame),
            "failsafe_particles_total": sum(r["failsafe_particles"] for r in per_frame),
        },
        "intersections": {
            "checked": check,
            "frames_checked": len(checked),
            "frames_with_intersections": sum(1 for r in checked
                                             if r["intersections"]["cloth_cloth"]
                                             or r["intersections"]["cloth_collider"]),
            "cloth_cloth_max": max((r["intersections"]["cloth_cloth"] for r in checked),
                                   default=None),
            "cloth_collider_max": max((r["intersections"]["cloth_collider"] for r in checked),
                                      default=None),
            "final": checked[-1]["intersections"] if checked and
            checked[-1]["frame"] == frame_count else None,
        },
        "cloths": cloths,
        "per_frame": per_frame,
    }
