"""Baking: reads the Blender scene, runs libwetcloth through the `wetcloth`
package frame by frame, writes a PC2 cache and hooks up a Mesh Cache
modifier. No physics here: every position comes from the library. One bake
is one library world: of one object (Bake), or of every Wet Cloth object
together (Bake All), where the library collides them with each other.

Coordinates: the simulation runs in world space (1 Blender unit = 1 m);
the cache holds object-local coordinates, so the baked motion plays back
under the object's own (possibly animated) transform.
"""

import ctypes
import os
import time

import bpy
import numpy as np

from . import props

MODIFIER_NAME = "Wet Cloth Cache"
WETNESS_ATTRIBUTE = "wet_cloth_wetness"
STUCK_ATTRIBUTE = "wet_cloth_stuck"


class BakeError(Exception):
    """A problem to tell the user about (reported, never a traceback)."""


# ---------------------------------------------------------------------------
# The library

_wetcloth = None


def _preload_bundled(folder):
    """The zip bundles the shared libraries libwetcloth needs besides libc
    (libccd, libgomp). The system's copy is used when it has one; the
    bundled copy otherwise, loaded globally so that libwetcloth finds it."""
    if not os.path.isdir(folder):
        return
    for name in sorted(os.listdir(folder)):
        try:
            ctypes.CDLL(name, mode=ctypes.RTLD_GLOBAL)
        except OSError:
            ctypes.CDLL(os.path.join(folder, name), mode=ctypes.RTLD_GLOBAL)


def load_wetcloth():
    """The `wetcloth` package: the copy inside this add-on (the installed
    extension), else one installed in Blender's Python."""
    global _wetcloth
    if _wetcloth is not None:
        return _wetcloth
    here = os.path.dirname(os.path.abspath(__file__))
    try:
        if os.path.isdir(os.path.join(here, "wetcloth")):
            _preload_bundled(os.path.join(here, "wetcloth", "libs"))
            from . import wetcloth
            from .wetcloth import meshio  # noqa: F401 (the PC2 writer)
        else:
            import wetcloth
            import wetcloth.meshio  # noqa: F401
    except (ImportError, OSError) as e:
        raise BakeError("cannot load libwetcloth: %s" % e) from None
    _wetcloth = wetcloth
    return wetcloth


# ---------------------------------------------------------------------------
# Reading meshes


def _matrix(m):
    return np.array(m, dtype=np.float64).reshape(4, 4)


def _to_world(local, matrix):
    return local @ matrix[:3, :3].T + matrix[:3, 3]


def _to_local(world, matrix):
    inv = np.linalg.inv(matrix)
    return world @ inv[:3, :3].T + inv[:3, 3]


def _positions(mesh):
    co = np.empty(3 * len(mesh.vertices), dtype=np.float32)
    mesh.vertices.foreach_get("co", co)
    return co.reshape(-1, 3).astype(np.float64)


def loop_triangles(mesh):
    """((T, 3) vertex indices, (T,) polygon indices) of Blender's
    triangulation of the mesh, in an order set by the vertices alone.

    The order of the triangles is part of the library's input (its sums run
    in it), but not part of a shape: Blender's own order follows the order of
    the polygons and loops, which edits can change without moving a vertex,
    and which bpy 4.5's primitive operators (UV sphere) make differently in
    each process. Each triangle starts at its lowest vertex index (which keeps
    its winding), and the triangles are sorted by their vertices."""
    mesh.calc_loop_triangles()
    n = len(mesh.loop_triangles)
    tri = np.empty(3 * n, dtype=np.int32)
    poly = np.empty(n, dtype=np.int32)
    mesh.loop_triangles.foreach_get("vertices", tri)
    mesh.loop_triangles.foreach_get("polygon_index", poly)
    tri = _lowest_first(tri.reshape(-1, 3))
    order = np.lexsort(tri.T[::-1])
    return tri[order], poly[order]


def _lowest_first(faces):
    """(F, k) faces, each turned to start at its lowest vertex index (the
    winding stays)."""
    k = faces.shape[1]
    first = np.argmin(faces, axis=1)
    return faces[np.arange(faces.shape[0])[:, None], (first[:, None] + np.arange(k)[None, :]) % k]


def cloth_faces(mesh):
    """(F, 4) faces for the library: triangles and quads as they are
    (a last index of -1 makes a triangle), other polygons as Blender
    triangulates them. The polygons' own order and first corners stay:
    the library splits a quad from its first corner, as the mesh has it."""
    sizes = np.empty(len(mesh.polygons), dtype=np.int32)
    starts = np.empty(len(mesh.polygons), dtype=np.int32)
    mesh.polygons.foreach_get("loop_total", sizes)
    mesh.polygons.foreach_get("loop_start", starts)
    loops = np.empty(len(mesh.loops), dtype=np.int32)
    mesh.loops.foreach_get("vertex_index", loops)
    faces = []
    for size in (3, 4):
        sel = np.flatnonzero(sizes == size)
        if sel.size:
            idx = loops[starts[sel, None] + np.arange(size)[None, :]]
            if size == 3:
                idx = np.concatenate([idx, np.full((idx.shape[0], 1), -1, np.int32)], axis=1)
            faces.append(idx)
    if np.any(sizes > 4):
        tri, poly = loop_triangles(mesh)
        tri = tri[sizes[poly] > 4]
        faces.append(np.concatenate([tri, np.full((tri.shape[0], 1), -1, np.int32)], axis=1))
    if not faces:
        return np.zeros((0, 4), dtype=np.int32)
    return np.concatenate(faces).astype(np.int32)


def group_weights(ob, name):
    """(n,) weights of vertex group `name`, 0 outside it."""
    group = ob.vertex_groups.get(name)
    if group is None:
        raise BakeError("%s has no vertex group %r" % (ob.name, name))
    gi = group.index
    w = np.zeros(len(ob.data.vertices))
    for v in ob.data.vertices:
        for g in v.groups:
            if g.group == gi:
                w[v.index] = g.weight
                break
    return w


def _is_collider(o):
    return (o.collision is not None and o.collision.use and
            any(m.type == "COLLISION" and m.show_viewport for m in o.modifiers))


def find_colliders(scene, view_layer, settings, cloth_objects):
    """The colliders of a cloth with these settings: objects with Collision
    physics (in its collection, if set) that are not cloths of the bake."""
    pool = (settings.collision_collection.all_objects if settings.collision_collection
            else scene.objects)
    return [o for o in pool
            if o not in cloth_objects and _is_collider(o) and view_layer.objects.get(o.name) == o]


def _evaluated_mesh(ob, depsgraph, matrix=None):
    """(world vertices (n, 3), triangles (T, 3)) of the evaluated object."""
    ev = ob.evaluated_get(depsgraph)
    mesh = ev.to_mesh()
    try:
        v = _positions(mesh)
        t, _poly = loop_triangles(mesh)
        m = _matrix(ev.matrix_world if matrix is None else matrix)
    finally:
        ev.to_mesh_clear()
    return _to_world(v, m), t


# ---------------------------------------------------------------------------
# Paths


def cache_paths(ob, settings):
    """(folder as given, absolute folder, absolute cache file)."""
    given = settings.cache_dir.strip()
    if not given:
        raise BakeError("the cache folder is empty: choose one in the Wet Cloth panel")
    if given.startswith("//") and not bpy.data.filepath:
        raise BakeError("the cache folder %r is relative to the .blend file, which is not "
                        "saved yet: save the file or choose an absolute folder" % given)
    folder = os.path.normpath(bpy.path.abspath(given))
    name = bpy.path.clean_name(ob.name) + ".pc2"
    return given, folder, os.path.join(folder, name)


def _check_folder(folder):
    try:
        os.makedirs(folder, exist_ok=True)
    except OSError as e:
        raise BakeError("cannot create the cache folder %s: %s" % (folder, e.strerror or e))
    if not os.access(folder, os.W_OK | os.X_OK):
        raise BakeError("cannot write into the cache folder %s" % folder)


# ---------------------------------------------------------------------------
# The bake

def _world_settings(settings, scene):
    """The settings of one object that belong to the world, not to its cloth,
    as (name, value) pairs: every object of a bake together must agree on
    them."""
    substeps = "automatic" if settings.substeps_auto else settings.substeps
    return (("frame range", "%d to %d" % props.frame_range(settings, scene)),
            ("integrator", settings.integrator),
            ("solver tolerance", settings.implicit_tolerance
             if settings.integrator == "IMPLICIT" else None),
            ("substeps", substeps))


class _ClothPart:
    """One object's part of a bake: its cloth in the world, its pins, its
    cache being written."""

    def __init__(self, ob):
        self.ob = ob
        self.settings = ob.wet_cloth
        self.writer = None
        self.tmp_path = None
        self.hidden_modifiers = []

    def check(self, scene):
        """What can be checked before anything is made; BakeError if not."""
        ob, s = self.ob, self.settings
        if ob.type != "MESH":
            raise BakeError("%s is not a mesh (it is a %s): Wet Cloth bakes mesh objects"
                            % (ob.name, ob.type.lower()))
        if not s.enabled:
            raise BakeError("Wet Cloth is not enabled on %s: tick it in Physics > Wet Cloth"
                            % ob.name)
        mesh = ob.data
        if len(mesh.polygons) == 0:
            raise BakeError("%s has no faces: a cloth needs a mesh with faces" % ob.name)
        start, end = props.frame_range(s, scene)
        if end <= start:
            raise BakeError("the frame range %d to %d is empty: the end must come after the "
                            "start" % (start, end))
        self.given_dir, self.folder, self.path = cache_paths(ob, s)
        n = len(mesh.vertices)
        self.faces = cloth_faces(mesh)
        self.wet = np.full(n, float(s.wetness))
        if s.wetness_group:
            self.wet *= np.clip(group_weights(ob, s.wetness_group), 0.0, 1.0)
        self.pins = (np.flatnonzero(group_weights(ob, s.pin_group) > 0.0).astype(np.int32)
                     if s.pin_group else np.zeros(0, np.int32))

    def find_colliders(self, scene, view_layer, cloth_objects):
        """The objects this cloth collides with (none when Object Collisions
        is off); BakeError if it is on and there are none."""
        s = self.settings
        if not s.use_colliders:
            return []
        found = find_colliders(scene, view_layer, s, cloth_objects)
        if not found:
            where = ("in the collection %r" % s.collision_collection.name
                     if s.collision_collection else "in the scene")
            raise BakeError("nothing to collide with: no object %s has Collision physics; "
                            "add it to an object (Physics > Collision) or turn off Object "
                            "Collisions" % where)
        return found

    def add_to(self, world, wetcloth, start_world, collide_with_cloths):
        s = self.settings
        material = wetcloth.Material(**props.material_kwargs(s))
        self.cloth = world.add_cloth(start_world, self.faces, material=material,
                                     wetness=self.wet, self_collision=s.self_collision,
                                     collide_with_cloths=collide_with_cloths)
        if self.pins.size:
            self.cloth.pin(self.pins)

    def open_cache(self, wetcloth, frame_count, start_frame):
        self.tmp_path = os.path.join(self.folder, ".%s.%d.tmp" % (os.path.basename(self.path),
                                                                  os.getpid()))
        try:
            self.writer = wetcloth.meshio.PC2Writer(self.tmp_path, len(self.ob.data.vertices),
                                                    frame_count, start=float(start_frame))
        except OSError as e:
            raise BakeError("cannot write the cache %s: %s" % (self.tmp_path, e.strerror or e))

    def hide_cache_modifiers(self):
        mods = list(self.ob.modifiers)
        for i, m in enumerate(mods):
            if m.type == "MESH_CACHE" and m.name == MODIFIER_NAME:
                for later in mods[i:]:
                    if later.show_viewport:
                        later.show_viewport = False
                        self.hidden_modifiers.append(later.name)
                break

    def restore_modifiers(self):
        for name in self.hidden_modifiers:
            m = self.ob.modifiers.get(name)
            if m is not None:
                m.show_viewport = True
        self.hidden_modifiers = []

    def world_positions(self, depsgraph):
        """The evaluated mesh in world space (its pins' motion); sets matrix."""
        ev = self.ob.evaluated_get(depsgraph)
        n = len(self.ob.data.vertices)
        mesh = ev.to_mesh()
        try:
            if len(mesh.vertices) != n:
                raise BakeError(
                    "the modifiers of %s change its vertex count (%d, the mesh has %d): move "
                    "them below the %r modifier or apply them" % (self.ob.name,
                                                                  len(mesh.vertices), n,
                                                                  MODIFIER_NAME))
            v = _positions(mesh)
        finally:
            ev.to_mesh_clear()
        self.matrix = _matrix(ev.matrix_world)
        return _to_world(v, self.matrix)

    def follow(self, depsgraph):
        """The pins' targets (or the object's transform) at the new frame."""
        if self.pins.size:
            self.cloth.set_pin_targets(self.world_positions(depsgraph)[self.pins])
        else:
            self.matrix = _matrix(self.ob.evaluated_get(depsgraph).matrix_world)

    def write_frame(self, world_positions, matrix=None):
        self.writer.write(_to_local(world_positions,
                                    self.matrix if matrix is None else _matrix(matrix)))

    def take_cache(self):
        """Closes the new cache and puts it in place of the previous one."""
        s = self.settings
        self.writer.close()
        self.writer = None
        previous = bpy.path.abspath(s.cache_file) if s.cache_file else ""
        os.replace(self.tmp_path, self.path)
        self.tmp_path = None
        if previous and os.path.normpath(previous) != self.path and os.path.isfile(previous):
            try:
                os.remove(previous)
            except OSError:
                pass

    def hook_up(self, start_frame, frame_count, wetness, stuck, info):
        """The Mesh Cache modifier, the attributes and the settings."""
        ob, s = self.ob, self.settings
        file_setting = self.path
        if self.given_dir.startswith("//"):
            file_setting = bpy.path.relpath(self.path)
        mod = ob.modifiers.get(MODIFIER_NAME)
        if mod is None or mod.type != "MESH_CACHE":
            mod = ob.modifiers.new(MODIFIER_NAME, "MESH_CACHE")
        mod.cache_format = "PC2"
        mod.filepath = file_setting
        mod.frame_start = float(start_frame)
        mod.frame_scale = 1.0
        mod.play_mode = "SCENE"
        mod.time_mode = "FRAME"
        mod.deform_mode = "OVERWRITE"
        mod.interpolation = "LINEAR"
        mod.forward_axis = "POS_Y"
        mod.up_axis = "POS_Z"
        mod.factor = 1.0
        mod.show_viewport = True
        mod.show_render = True

        set_attribute(ob.data, WETNESS_ATTRIBUTE, wetness)
        set_attribute(ob.data, STUCK_ATTRIBUTE, stuck)

        s.cache_file = file_setting
        s.baked_frames = frame_count
        s.baked_start = start_frame
        s.bake_info = info
        ob.update_tag()

    def drop_cache(self):
        """Removes what this bake wrote for the object."""
        if self.writer is not None:
            try:
                self.writer.file.close()
            except OSError:
                pass
            self.writer = None
        if self.tmp_path and os.path.exists(self.tmp_path):
            try:
                os.remove(self.tmp_path)
            except OSError:
                pass
        self.tmp_path = None
        self.restore_modifiers()


class Baker:
    """One bake of one or more objects in one world, where they collide with
    each other (those with Collide with Cloths) and share the colliders:
    start(), step() until done, then finish(); abort() at any point leaves
    every object's previous bake as it was. The world's settings (frame
    range, integrator, substeps) come from the first object, and the others
    must agree with it."""

    def __init__(self, context, objects):
        self.scene = context.scene
        self.view_layer = context.view_layer
        if not isinstance(objects, (list, tuple)):
            objects = [objects]
        self.parts = [_ClothPart(ob) for ob in objects]
        self.ob = objects[0]
        self.settings = self.ob.wet_cloth
        self.world = None
        self.frame_before = self.scene.frame_current
        self.done = False
        self.info = ""
        self.started = time.perf_counter()

    @property
    def objects(self):
        return [p.ob for p in self.parts]

    # setup ------------------------------------------------------------------

    def _check_world_settings(self):
        lead = _world_settings(self.settings, self.scene)
        for p in self.parts[1:]:
            for (name, want), (_n, got) in zip(lead, _world_settings(p.settings, self.scene)):
                if got != want:
                    raise BakeError("objects baked together share one world, so they need the "
                                    "same %s: %s has %s, %s has %s" % (
                                        name, self.ob.name, want, p.ob.name, got))

    def _check_paths(self):
        seen = {}
        for p in self.parts:
            other = seen.get(p.path)
            if other is not None:
                raise BakeError("%s and %s would write the same cache %s: rename one or give "
                                "it another cache folder" % (other, p.ob.name, p.path))
            seen[p.path] = p.ob.name

    def _shared_colliders(self, cloth_objects):
        """Every collider of any of the cloths, once, in the order found."""
        found = []
        for p in self.parts:
            for o in p.find_colliders(self.scene, self.view_layer, cloth_objects):
                if o not in found:
                    found.append(o)
        return found

    def start(self):
        scene = self.scene
        for p in self.parts:
            p.check(scene)
        self._check_world_settings()
        self._check_paths()
        self.start_frame, self.end_frame = props.frame_range(self.settings, scene)
        self.frame_count = self.end_frame - self.start_frame + 1
        self.frame = self.start_frame
        self.frame_dt = scene.render.fps_base / scene.render.fps
        self.colliders = self._shared_colliders(self.objects)
        for p in self.parts:
            _check_folder(p.folder)

        wetcloth = load_wetcloth()
        self.wetcloth = wetcloth

        # The cloth's own motion (pins) is read from the mesh as evaluated
        # without this add-on's cache and what comes after it.
        for p in self.parts:
            p.hide_cache_modifiers()
        scene.frame_set(self.start_frame)
        depsgraph = self._depsgraph()
        start_world = [p.world_positions(depsgraph) for p in self.parts]

        gravity = tuple(scene.gravity) if scene.use_gravity else (0.0, 0.0, 0.0)
        # alone, a cloth is baked as it always was (collide_with_cloths
        # then changes nothing: a world of one cloth has no group)
        together = len(self.parts) > 1
        try:
            self.world = wetcloth.World(gravity=gravity,
                                        integrator=props.integrator_name(self.settings),
                                        implicit_tolerance=self.settings.implicit_tolerance)
            for p, positions in zip(self.parts, start_world):
                p.add_to(self.world, wetcloth, positions,
                         not together or p.settings.collide_with_cloths)
            self.sim_colliders = []
            for o in self.colliders:
                v, t = _evaluated_mesh(o, depsgraph)
                if t.shape[0] == 0:
                    raise BakeError("collider %s has no faces" % o.name)
                c = o.collision
                self.sim_colliders.append(self.world.add_mesh_collider(
                    v, t, thickness=float(c.thickness_outer),
                    friction=min(10.0, float(c.cloth_friction) / 10.0)))
        except wetcloth.WetclothError as e:
            raise BakeError(str(e)) from None

        for p, positions in zip(self.parts, start_world):
            p.open_cache(wetcloth, self.frame_count, self.start_frame)
            p.write_frame(positions, p.ob.matrix_world)
        self.substeps = 0

    def _depsgraph(self):
        return bpy.context.evaluated_depsgraph_get()

    # stepping ---------------------------------------------------------------

    def step(self):
        """Simulates and writes the next frame."""
        if self.done:
            return
        self.frame += 1
        self.scene.frame_set(self.frame)
        depsgraph = self._depsgraph()
        try:
            for o, c in zip(self.colliders, self.sim_colliders):
                v, _t = _evaluated_mesh(o, depsgraph)
                if v.shape[0] != c.vertices.shape[0]:
                    raise BakeError("collider %s changed its vertex count at frame %d (%d, was "
                                    "%d): colliders must keep their topology" %
                                    (o.name, self.frame, v.shape[0], c.vertices.shape[0]))
                c.set_vertices(v)
            for p in self.parts:
                p.follow(depsgraph)
            substeps = 0 if self.settings.substeps_auto else self.settings.substeps
            self.substeps += self.world.advance(self.frame_dt, substeps)
            positions = [p.cloth.positions for p in self.parts]
        except self.wetcloth.WetclothError as e:
            raise BakeError("frame %d: %s" % (self.frame, e)) from None
        for p, x in zip(self.parts, positions):
            p.write_frame(x)
        if self.frame >= self.end_frame:
            self.done = True

    @property
    def progress(self):
        return self.frame - self.start_frame + 1

    # ending -----------------------------------------------------------------

    def finish(self):
        """Puts the new caches in place, then the modifiers and attributes."""
        for p in self.parts:
            p.take_cache()
        state = [(p.cloth.wetness, p.cloth.stuck.astype(np.float64)) for p in self.parts]
        elapsed = time.perf_counter() - self.started
        frames = self.frame_count - 1
        self.world.close()
        self.info = "%d frames in %.1f s, %.1f substeps per frame" % (
            self.frame_count, elapsed, self.substeps / max(1, frames))
        for p, (wetness, stuck) in zip(self.parts, state):
            p.restore_modifiers()
            others = [o.name for o in self.objects if o is not p.ob]
            p.hook_up(self.start_frame, self.frame_count, wetness, stuck,
                      self.info + (", with " + ", ".join(others) if others else ""))
        self.scene.frame_set(self.frame_before)

    def abort(self):
        """Drops what this bake wrote; the previous bakes stay."""
        for p in self.parts:
            p.drop_cache()
        if self.world is not None:
            self.world.close()
        self.scene.frame_set(self.frame_before)


def bake_all_objects(context):
    """The objects Bake All bakes: every mesh in the view layer with Wet
    Cloth enabled, by name."""
    return sorted((o for o in context.view_layer.objects
                   if o.type == "MESH" and o.wet_cloth.enabled), key=lambda o: o.name)


def set_attribute(mesh, name, values):
    a = mesh.attributes.get(name)
    if a is not None and (a.data_type != "FLOAT" or a.domain != "POINT"):
        mesh.attributes.remove(a)
        a = None
    if a is None:
        a = mesh.attributes.new(name, "FLOAT", "POINT")
    a.data.foreach_set("value", np.asarray(values, dtype=np.float32))


def free_bake(ob):
    """Removes the modifier, the cache file and the attributes. Returns what
    was removed, as words."""
    s = ob.wet_cloth
    removed = []
    mod = ob.modifiers.get(MODIFIER_NAME)
    if mod is not None and mod.type == "MESH_CACHE":
        ob.modifiers.remove(mod)
        removed.append("modifier")
    if s.cache_file:
        path = bpy.path.abspath(s.cache_file)
        if os.path.isfile(path):
            try:
                os.remove(path)
                removed.append("cache")
            except OSError as e:
                raise BakeError("cannot remove the cache %s: %s" % (path, e.strerror or e))
    if ob.type == "MESH":
        for name in (WETNESS_ATTRIBUTE, STUCK_ATTRIBUTE):
            a = ob.data.attributes.get(name)
            if a is not None:
                ob.data.attributes.remove(a)
                if "attributes" not in removed:
                    removed.append("attributes")
    s.cache_file = ""
    s.baked_frames = 0
    s.bake_info = ""
    return removed
