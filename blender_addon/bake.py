"""Baking: reads the Blender scene, runs libwetcloth through the `wetcloth`
package frame by frame, writes the point caches (positions, and wetness and
stuck per frame) and hooks up the Wet Cloth modifiers (stack.py). No physics
here: every position comes from the library, every field value from
fields.py's reading of Blender's fields. One bake
is one library world: of one object (Bake), or of every Wet Cloth object
together (Bake All), where the library collides them with each other.

Coordinates: the simulation runs in world space (1 Blender unit = 1 m);
the cache holds object-local coordinates, so the baked motion plays back
under the object's own (possibly animated) transform.
"""

import ctypes
import math
import os
import time

import bpy
import numpy as np

from . import cache, fields, outdated, props, stack

MODIFIER_NAME = stack.POSITIONS
WETNESS_ATTRIBUTE = stack.WETNESS_ATTRIBUTE
STUCK_ATTRIBUTE = stack.STUCK_ATTRIBUTE

# The share of the stable step that automatic steps take (the library's
# default).
SUBSTEP_SAFETY = 0.9


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


def group_weights(ob, mesh, name):
    """(n,) weights of the object's vertex group `name` on `mesh` (the
    evaluated mesh: modifiers such as Subdivision Surface carry the weights
    over to the vertices they make), 0 outside it."""
    group = ob.vertex_groups.get(name)
    if group is None:
        raise BakeError("%s has no vertex group %r" % (ob.name, name))
    gi = group.index
    w = np.zeros(len(mesh.vertices))
    for v in mesh.vertices:
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
            ("Quality Steps", substeps),
            ("Gravity field weight", settings.field_gravity))


class _ClothPart:
    """One object's part of a bake: its cloth in the world, its pins, its
    caches being written."""

    def __init__(self, ob):
        self.ob = ob
        self.settings = ob.wet_cloth
        self.writers = []
        self.hidden = []
        self.fields_on = {"air": False, "force": False}

    # before anything is made --------------------------------------------------

    def check(self, scene, to_frame=None):
        """What can be checked before anything is made; BakeError if not."""
        ob, s = self.ob, self.settings
        if ob.type != "MESH":
            raise BakeError("%s is not a mesh (it is a %s): Wet Cloth bakes mesh objects"
                            % (ob.name, ob.type.lower()))
        if not s.enabled:
            raise BakeError("Wet Cloth is not enabled on %s: tick it in Physics > Wet Cloth"
                            % ob.name)
        if ob.library is not None:
            raise BakeError("%s is linked from another .blend file: bake it there" % ob.name)
        try:
            props.check_settings(s)
        except props.SettingError as e:
            raise BakeError("%s: %s" % (ob.name, e)) from None
        start, end = props.frame_range(s, scene)
        if to_frame is not None:
            end = to_frame
        if end <= start:
            raise BakeError("the frame range %d to %d is empty: the end must come after the "
                            "start" % (start, end))

    def prepare_files(self, busy):
        """Claims the object's cache identity and picks its files; removes
        the temporary files of its earlier bakes that were killed."""
        ob, s = self.ob, self.settings
        cache.claim_identity(ob)
        self.folder, self.folder_text = cache.folder_for(s)
        try:
            cache.ensure_folder(self.folder)
        except cache.CacheError as e:
            raise BakeError(str(e)) from None
        own = {os.path.normpath(bpy.path.abspath(p)) for p in (s.cache_file, s.wetness_file) if p}
        for _attempt in range(8):
            names = cache.file_names(ob)
            paths = [os.path.join(self.folder, n) for n in names]
            # a file of this name that is not this object's current bake was
            # written by someone else (a copy of this .blend baking into the
            # same Cache Folder): a new identity, never an overwrite
            if all(os.path.normpath(p) in own or not os.path.exists(p) for p in paths):
                break
            s.cache_id = props.new_cache_id()
        else:
            raise BakeError("cannot find free cache file names in %s" % self.folder)
        self.path, self.wetness_path = paths
        cache.remove_stale_temps(self.folder, s.cache_id, busy)

    # the cloth ------------------------------------------------------------------

    def hide_modifiers(self):
        stack.ensure_cloth_modifier(self.ob)
        self.hidden = stack.hide_from_cloth(self.ob)

    def restore_modifiers(self):
        stack.restore(self.ob, self.hidden)
        self.hidden = []

    def read_rest(self, depsgraph):
        """The cloth at the first frame: the mesh as the modifiers above Wet
        Cloth leave it. Returns its world positions."""
        ob, s = self.ob, self.settings
        ev = ob.evaluated_get(depsgraph)
        mesh = ev.to_mesh()
        try:
            if len(mesh.polygons) == 0:
                raise BakeError("%s has no faces: a cloth needs a mesh with faces" % ob.name)
            self.n = len(mesh.vertices)
            self.faces = cloth_faces(mesh)
            local = _positions(mesh)
            wet = np.full(self.n, float(props.checked(s, "wetness")))
            if s.wetness_group:
                wet *= np.clip(group_weights(ob, mesh, s.wetness_group), 0.0, 1.0)
            self.wet = wet
            pins = group_weights(ob, mesh, s.pin_group) if s.pin_group else np.zeros(self.n)
        finally:
            ev.to_mesh_clear()
        self.hard_pins = np.flatnonzero(pins >= props.HARD_PIN_WEIGHT).astype(np.int32)
        soft = (pins > 0.0) & (pins < props.HARD_PIN_WEIGHT)
        self.soft_pins = np.flatnonzero(soft).astype(np.int32)
        self.soft_stiffness = float(props.checked(s, "pin_stiffness")) * pins[soft]
        self.pins = np.concatenate([self.hard_pins, self.soft_pins])
        self.matrix = _matrix(ev.matrix_world)
        return _to_world(local, self.matrix)

    def world_positions(self, depsgraph, frame):
        """The evaluated mesh in world space at this frame (its pins'
        motion); sets matrix."""
        ev = self.ob.evaluated_get(depsgraph)
        mesh = ev.to_mesh()
        try:
            if len(mesh.vertices) != self.n:
                raise BakeError(
                    "the modifiers above Wet Cloth on %s change its vertex count at frame %d "
                    "(%d, was %d): a cloth keeps its vertices" % (self.ob.name, frame,
                                                                  len(mesh.vertices), self.n))
            v = _positions(mesh)
        finally:
            ev.to_mesh_clear()
        self.matrix = _matrix(ev.matrix_world)
        return _to_world(v, self.matrix)

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
        if self.hard_pins.size:
            self.cloth.pin(self.hard_pins)
        if self.soft_pins.size:
            self.cloth.pin(self.soft_pins, stiffness=self.soft_stiffness)

    def follow(self, depsgraph, frame):
        """The pins' targets (or the object's transform) at the new frame."""
        if self.pins.size:
            self.cloth.set_pin_targets(self.world_positions(depsgraph, frame)[self.pins])
        else:
            self.matrix = _matrix(self.ob.evaluated_get(depsgraph).matrix_world)

    def apply_fields(self, sampler, gravity_only=False):
        """The force fields at the cloth's particles, for the next frame."""
        air, force = sampler.sample(self.cloth.positions, self.cloth.velocities)
        for key, value, setter in (("air", air, "set_air_velocity"),
                                   ("force", force, "set_external_forces")):
            if value is not None or self.fields_on[key]:
                getattr(self.cloth, setter)(value)
                self.fields_on[key] = value is not None

    # the caches -------------------------------------------------------------------

    def open_caches(self, wetcloth, frame_count, start_frame):
        self.tmp_paths = [cache.temp_path(self.path), cache.temp_path(self.wetness_path)]
        for tmp in self.tmp_paths:
            try:
                self.writers.append(wetcloth.meshio.PC2Writer(tmp, self.n, frame_count,
                                                              start=float(start_frame)))
            except OSError as e:
                raise BakeError("cannot write the cache %s: %s" % (tmp, e.strerror or e))

    def write_frame(self, world_positions, matrix=None):
        local = _to_local(world_positions, self.matrix if matrix is None else _matrix(matrix))
        state = np.zeros((self.n, 3))
        state[:, 0] = self.cloth.wetness
        state[:, 1] = self.cloth.stuck
        self.writers[0].write(local)
        self.writers[1].write(state)

    def take_caches(self):
        """Closes the new caches and puts them in place of the previous
        ones; the previous ones go if they are this object's own."""
        s = self.settings
        for w in self.writers:
            w.close()
        self.writers = []
        previous = stack.referenced_files(self.ob) | {
            bpy.path.abspath(p) for p in (s.cache_file, s.wetness_file) if p}
        for tmp, final in zip(self.tmp_paths, (self.path, self.wetness_path)):
            os.replace(tmp, final)
        self.tmp_paths = []
        new = {os.path.normpath(self.path), os.path.normpath(self.wetness_path)}
        self.replaced = [p for p in previous if os.path.normpath(p) not in new]

    def hook_up(self, start_frame, frame_count, info, inputs):
        """The modifiers and the settings; then the replaced files go."""
        ob, s = self.ob, self.settings
        stack.hook_up(ob, cache.file_setting(self.path), cache.file_setting(self.wetness_path),
                      start_frame)
        s.cache_file = self.path
        s.wetness_file = self.wetness_path
        s.baked_frames = frame_count
        s.baked_start = start_frame
        s.bake_info = info
        s.baked_inputs = "\n".join(sorted(inputs))
        s.outdated = False
        cache.delete_own(self.replaced, ob)
        ob.update_tag()

    def drop_caches(self):
        """Removes what this bake wrote for the object."""
        for w in self.writers:
            try:
                w.file.close()
            except OSError:
                pass
        self.writers = []
        for tmp in getattr(self, "tmp_paths", []):
            if os.path.exists(tmp):
                try:
                    os.remove(tmp)
                except OSError:
                    pass
        self.tmp_paths = []
        self.restore_modifiers()


class Baker:
    """One bake of one or more objects in one world, where they collide with
    each other (those with Cloth Collisions) and share the colliders:
    start(), step() until done, then finish(); abort() at any point leaves
    every object's previous bake as it was. The world's settings (frame
    range, integrator, steps) come from the first object, and the others
    must agree with it. `to_frame` ends the bake at that frame instead of
    the range's end (Bake to Current Frame)."""

    def __init__(self, context, objects, to_frame=None, log=None):
        self.scene = context.scene
        self.view_layer = context.view_layer
        if not isinstance(objects, (list, tuple)):
            objects = [objects]
        self.parts = [_ClothPart(ob) for ob in objects]
        self.ob = objects[0]
        self.settings = self.ob.wet_cloth
        self.to_frame = to_frame
        self.log = log
        self.world = None
        self.frame_before = self.scene.frame_current
        self.done = False
        self.info = ""
        self.warnings = []
        self.started = time.perf_counter()
        self._logged = -1

    @property
    def objects(self):
        return [p.ob for p in self.parts]

    @property
    def temp_files(self):
        return [t for p in self.parts for t in getattr(p, "tmp_paths", [])]

    # setup ------------------------------------------------------------------

    def _check_world_settings(self):
        lead = _world_settings(self.settings, self.scene)
        for p in self.parts[1:]:
            for (name, want), (_n, got) in zip(lead, _world_settings(p.settings, self.scene)):
                if got != want:
                    raise BakeError("objects baked together share one world, so they need the "
                                    "same %s: %s has %s, %s has %s" % (
                                        name, self.ob.name, want, p.ob.name, got))

    def _shared_colliders(self, cloth_objects):
        """Every collider of any of the cloths, once, in the order found."""
        found = []
        for p in self.parts:
            for o in p.find_colliders(self.scene, self.view_layer, cloth_objects):
                if o not in found:
                    found.append(o)
        return found

    def _samplers(self, depsgraph):
        return [fields.FieldSampler(self.scene, self.view_layer, depsgraph,
                                    props.FieldWeights(p.settings), exclude=self.objects)
                for p in self.parts]

    def _check_work(self):
        """Refuses a bake above the Work Limit before it starts, with the
        estimate and what would make it cheaper."""
        if self.settings.substeps_auto:
            stable = self.world.stable_dt()
            steps = 1 if not math.isfinite(stable) else max(1, math.ceil(
                self.frame_dt / (SUBSTEP_SAFETY * stable)))
        else:
            steps = int(self.settings.substeps)
        self.steps_estimate = steps
        vertices = sum(p.n for p in self.parts)
        work = vertices * steps * (self.frame_count - 1)
        limit = float(self.settings.work_limit) * 1e6
        if work > limit:
            advice = []
            if self.settings.integrator == "VERLET":
                advice.append("choose the Semi-Implicit or Strain Limited integrator, which need "
                              "far fewer steps")
            if not self.settings.substeps_auto:
                advice.append("lower the Quality Steps")
            elif self.settings.integrator == "VERLET":
                advice.append("a softer or coarser cloth")
            advice.append("or raise the Work Limit in the Cache panel")
            raise BakeError(
                "this bake would be about %.3g million vertex steps (%d vertices x %d steps per "
                "frame x %d frames), more than the Work Limit of %g million: %s" % (
                    work / 1e6, vertices, steps, self.frame_count - 1,
                    self.settings.work_limit, "; ".join(advice)))

    def start(self, busy=()):
        scene = self.scene
        for p in self.parts:
            p.check(scene, self.to_frame)
        self._check_world_settings()
        self.start_frame, self.end_frame = props.frame_range(self.settings, scene)
        if self.to_frame is not None:
            self.end_frame = self.to_frame
        self.frame_count = self.end_frame - self.start_frame + 1
        self.frame = self.start_frame
        self.frame_dt = scene.render.fps_base / scene.render.fps
        for p in self.parts:
            p.prepare_files(busy)
        seen = {}
        for p in self.parts:
            other = seen.get(p.path)
            if other is not None:
                raise BakeError("%s and %s would write the same cache %s" % (other, p.ob.name,
                                                                              p.path))
            seen[p.path] = p.ob.name

        wetcloth = load_wetcloth()
        self.wetcloth = wetcloth

        # The cloth's rest shape and its own motion (pins) are read from the
        # mesh as the modifiers above Wet Cloth make it.
        for p in self.parts:
            p.hide_modifiers()
        scene.frame_set(self.start_frame)
        depsgraph = self._depsgraph()
        start_world = [p.read_rest(depsgraph) for p in self.parts]
        self.colliders = self._shared_colliders(self.objects)
        samplers = self._samplers(depsgraph)
        for s in samplers:
            self.warnings.extend("field %s (%s) is not supported and was ignored" % (name, kind)
                                 for name, kind in s.ignored)
            self.warnings.extend("field %s (%s): %s" % note for note in s.notes)
        self.inputs = {o.name for o in self.colliders}
        self.inputs.update(e.name for s in samplers for e in s.effectors)

        # alone, a cloth is baked as it always was (collide_with_cloths
        # then changes nothing: a world of one cloth has no group)
        together = len(self.parts) > 1
        try:
            self.world = wetcloth.World(gravity=tuple(samplers[0].gravity(scene)),
                                        integrator=props.integrator_name(self.settings),
                                        implicit_tolerance=float(self.settings.implicit_tolerance),
                                        substep_safety=SUBSTEP_SAFETY,
                                        max_substeps=props.OTHER_RANGES["substeps"][1])
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
        self._check_work()

        for p, positions in zip(self.parts, start_world):
            p.open_caches(wetcloth, self.frame_count, self.start_frame)
            p.write_frame(positions, p.ob.matrix_world)
        self.substeps = 0
        self._log_progress()

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
            for p, sampler in zip(self.parts, self._samplers(depsgraph)):
                p.follow(depsgraph, self.frame)
                p.apply_fields(sampler)
            substeps = 0 if self.settings.substeps_auto else self.settings.substeps
            self.substeps += self.world.advance(self.frame_dt, substeps)
            positions = [p.cloth.positions for p in self.parts]
        except self.wetcloth.WetclothError as e:
            raise BakeError("frame %d: %s" % (self.frame, e)) from None
        for p, x in zip(self.parts, positions):
            p.write_frame(x)
        if self.frame >= self.end_frame:
            self.done = True
        self._log_progress()

    @property
    def progress(self):
        return self.frame - self.start_frame + 1

    def status_text(self):
        elapsed = time.perf_counter() - self.started
        done = self.progress - 1
        left = ""
        if done > 0 and not self.done:
            left = ", about %s left" % _duration(elapsed / done * (self.frame_count - 1 - done))
        return "Wet Cloth: baking %s, frame %d of %d (%d %%)%s" % (
            ", ".join(o.name for o in self.objects), self.frame, self.end_frame,
            100 * done // max(1, self.frame_count - 1), left)

    def _log_progress(self):
        """One line on the log every 5 % (headless bakes)."""
        if self.log is None:
            return
        percent = 100 * (self.progress - 1) // max(1, self.frame_count - 1)
        if percent // 5 > self._logged or self.done:
            self._logged = percent // 5
            self.log(self.status_text())

    # ending -----------------------------------------------------------------

    def finish(self):
        """Puts the new caches in place, then the modifiers."""
        for p in self.parts:
            p.take_caches()
        elapsed = time.perf_counter() - self.started
        frames = self.frame_count - 1
        self.world.close()
        self.info = "%d frames in %.1f s, %.1f steps per frame" % (
            self.frame_count, elapsed, self.substeps / max(1, frames))
        with outdated.suppressed():
            for p in self.parts:
                p.restore_modifiers()
                others = [o.name for o in self.objects if o is not p.ob]
                p.hook_up(self.start_frame, self.frame_count,
                          self.info + (", with " + ", ".join(others) if others else ""),
                          self.inputs)
            self.scene.frame_set(self.frame_before)
            bpy.context.view_layer.update()

    def abort(self):
        """Drops what this bake wrote; the previous bakes stay."""
        with outdated.suppressed():
            for p in self.parts:
                p.drop_caches()
            if self.world is not None:
                self.world.close()
            self.scene.frame_set(self.frame_before)
            bpy.context.view_layer.update()


def _duration(seconds):
    if seconds < 90:
        return "%.0f s" % seconds
    if seconds < 5400:
        return "%.0f min" % (seconds / 60)
    return "%.1f h" % (seconds / 3600)


def bake_all_objects(context):
    """The objects Bake All bakes: every mesh in the view layer with Wet
    Cloth enabled, by name."""
    return sorted((o for o in context.view_layer.objects
                   if o.type == "MESH" and o.wet_cloth.enabled and o.library is None),
                  key=lambda o: o.name)


def is_baked(ob):
    return bool(ob.wet_cloth.cache_file) or bool(stack.referenced_files(ob))


def free_bake(ob):
    """Removes the bake's modifiers and those of its files that are this
    object's own (cache.delete_own). Returns (what was removed, as words;
    files kept, as [(path, why)])."""
    s = ob.wet_cloth
    files = stack.referenced_files(ob) | {
        bpy.path.abspath(p) for p in (s.cache_file, s.wetness_file) if p}
    removed = []
    with outdated.suppressed():
        if stack.remove_bake(ob, keep_cloth_modifier=s.enabled):
            removed.append("modifiers")
        deleted, kept = cache.delete_own(sorted(files), ob)
        if deleted:
            removed.append("cache files")
        s.cache_file = ""
        s.wetness_file = ""
        s.baked_frames = 0
        s.bake_info = ""
        s.baked_inputs = ""
        s.outdated = False
        bpy.context.view_layer.update()
    return removed, kept
