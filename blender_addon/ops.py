"""Operators: wetcloth.bake (the active object; to_current_frame for Bake to
Current Frame), wetcloth.bake_all (every Wet Cloth object together, in one
world), wetcloth.free_bake, wetcloth.free_bake_all and
wetcloth.add_wet_material."""

import time
import traceback

import bpy
from bpy.props import BoolProperty, StringProperty

from . import bake, material

# Objects being baked interactively right now (one bake at a time per object),
# and their bakes (whose temporary files are not stale).
_running = set()
_bakers = []


def _busy_files():
    return {t for b in _bakers for t in b.temp_files}


def _log(line):
    print(line, flush=True)


def _target(op, context):
    if op.object:
        ob = bpy.data.objects.get(op.object)
        if ob is None:
            raise bake.BakeError("there is no object named %r" % op.object)
        return ob
    ob = context.object
    if ob is None:
        raise bake.BakeError("no active object: select the cloth mesh")
    return ob


def _failure_text(e):
    if isinstance(e, bake.BakeError):
        return str(e)
    # Anything unexpected: one line for the user, the traceback on the console.
    traceback.print_exc()
    return "%s: %s (details on the console)" % (type(e).__name__, e)


def _names(objects):
    return ", ".join(o.name for o in objects)


class _BakeOperator:
    """Bakes the objects of _objects() together in one world: synchronously
    from scripts and headless Blender, in the background of the UI with a
    progress bar (Esc cancels) when invoked there."""

    _timer = None
    _baker = None

    def _objects(self, context):
        raise NotImplementedError

    def _prepare(self, context):
        """A Baker for the objects, or None after reporting why not."""
        try:
            objects = self._objects(context)
        except bake.BakeError as e:
            self.report({"ERROR"}, str(e))
            return None
        busy = [o.name for o in objects if o.name in _running]
        if busy:
            self.report({"ERROR"}, "%s is being baked already" % ", ".join(busy))
            return None
        to_frame = context.scene.frame_current if getattr(self, "to_current_frame", False) \
            else None
        return bake.Baker(context, objects, to_frame=to_frame,
                          log=_log if bpy.app.background else None)

    def _failed(self, baker, e):
        baker.abort()
        self.report({"ERROR"}, "Wet Cloth bake of %s failed: %s" % (_names(baker.objects),
                                                                   _failure_text(e)))
        return {"CANCELLED"}

    def _baked(self, baker):
        for w in baker.warnings:
            self.report({"WARNING"}, "Wet Cloth: " + w)
        self.report({"INFO"}, "Wet Cloth: baked %s, %s" % (_names(baker.objects), baker.info))
        return {"FINISHED"}

    # synchronous (scripts, headless Blender) --------------------------------

    def execute(self, context):
        baker = self._prepare(context)
        if baker is None:
            return {"CANCELLED"}
        wm = context.window_manager
        progress = False
        try:
            baker.start(_busy_files())
            wm.progress_begin(0, baker.frame_count)
            progress = True
            while not baker.done:
                baker.step()
                wm.progress_update(baker.progress)
            baker.finish()
        except Exception as e:  # reported to the user, previous bakes kept
            return self._failed(baker, e)
        finally:
            if progress:
                wm.progress_end()
        return self._baked(baker)

    # interactive: modal, cancellable -----------------------------------------

    def invoke(self, context, event):
        if bpy.app.background or context.window is None:
            return self.execute(context)
        result = self._begin_modal(context)
        if result != {"RUNNING_MODAL"}:
            return result
        wm = context.window_manager
        self._timer = wm.event_timer_add(0.01, window=context.window)
        wm.modal_handler_add(self)
        return result

    def _begin_modal(self, context):
        """Starts the bake that modal() then steps: {"RUNNING_MODAL"}, or
        {"CANCELLED"} after reporting why not. Apart from the timer and the
        modal handler, which need a window, this is all of the interactive
        start (the tests drive modal() from here headless)."""
        baker = self._prepare(context)
        if baker is None:
            return {"CANCELLED"}
        try:
            baker.start(_busy_files())
        except Exception as e:
            return self._failed(baker, e)
        self._baker = baker
        _bakers.append(baker)
        _running.update(o.name for o in baker.objects)
        context.window_manager.progress_begin(0, baker.frame_count)
        self._status(context)
        return {"RUNNING_MODAL"}

    def _status(self, context):
        text = self._baker.status_text() + " (Esc to cancel)"
        if context.workspace is not None and context.window is not None:
            context.workspace.status_text_set(text)

    def _end(self, context):
        wm = context.window_manager
        if self._timer is not None:
            wm.event_timer_remove(self._timer)
            self._timer = None
        wm.progress_end()
        if context.workspace is not None and context.window is not None:
            context.workspace.status_text_set(None)
        _running.difference_update(o.name for o in self._baker.objects)
        if self._baker in _bakers:
            _bakers.remove(self._baker)

    def modal(self, context, event):
        b = self._baker
        if event.type == "ESC":
            b.abort()
            self._end(context)
            self.report({"WARNING"}, "Wet Cloth bake of %s cancelled; the previous bake is "
                                     "kept" % _names(b.objects))
            return {"CANCELLED"}
        if event.type != "TIMER":
            return {"PASS_THROUGH"}
        try:
            t0 = time.perf_counter()
            while not b.done and time.perf_counter() - t0 < 0.1:
                b.step()
            if b.done:
                b.finish()
                self._end(context)
                return self._baked(b)
        except Exception as e:
            self._end(context)
            return self._failed(b, e)
        context.window_manager.progress_update(b.progress)
        self._status(context)
        return {"RUNNING_MODAL"}


class WETCLOTH_OT_bake(_BakeOperator, bpy.types.Operator):
    """Bake the wet cloth simulation of the object (Esc cancels and keeps the previous bake)"""
    bl_idname = "wetcloth.bake"
    bl_label = "Bake Wet Cloth"
    bl_options = {"REGISTER"}

    object: StringProperty(name="Object", default="", options={"SKIP_SAVE"},
                           description="Object to bake (default: the active object)")
    to_current_frame: BoolProperty(
        name="To Current Frame", default=False, options={"SKIP_SAVE"},
        description="Bake from the start frame to the scene's current frame only")

    def _objects(self, context):
        return [_target(self, context)]


class WETCLOTH_OT_bake_all(_BakeOperator, bpy.types.Operator):
    """Bake every Wet Cloth object of the view layer together, in one simulation, so that they
collide with each other (and stick where wet); each gets its own cache (Esc cancels and keeps
the previous bakes)"""
    bl_idname = "wetcloth.bake_all"
    bl_label = "Bake All Wet Cloth"
    bl_options = {"REGISTER"}

    def _objects(self, context):
        objects = bake.bake_all_objects(context)
        if not objects:
            raise bake.BakeError("no mesh in the view layer has Wet Cloth enabled")
        # the active object's world settings lead, when it is one of them
        active = context.object
        if active in objects:
            objects.remove(active)
            objects.insert(0, active)
        return objects


class WETCLOTH_OT_free_bake(bpy.types.Operator):
    """Remove the bake: its modifiers, and its cache files (files another object or .blend file
plays are kept)"""
    bl_idname = "wetcloth.free_bake"
    bl_label = "Free Wet Cloth Bake"
    bl_options = {"REGISTER", "UNDO"}

    object: StringProperty(name="Object", default="", options={"SKIP_SAVE"},
                           description="Object whose bake to free (default: the active object)")

    def execute(self, context):
        try:
            ob = _target(self, context)
            if ob.name in _running:
                raise bake.BakeError("%s is being baked: cancel the bake first" % ob.name)
            removed, kept = bake.free_bake(ob)
        except bake.BakeError as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        _report_kept(self, kept)
        if removed:
            self.report({"INFO"}, "Wet Cloth: freed the bake of %s (%s)" % (
                ob.name, ", ".join(removed)))
        else:
            self.report({"INFO"}, "Wet Cloth: %s has no bake to free" % ob.name)
        return {"FINISHED"}


class WETCLOTH_OT_free_bake_all(bpy.types.Operator):
    """Remove the bakes of every Wet Cloth object of the view layer (files another object or
.blend file plays are kept)"""
    bl_idname = "wetcloth.free_bake_all"
    bl_label = "Free All Wet Cloth Bakes"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        objects = bake.bake_all_objects(context)
        busy = [o.name for o in objects if o.name in _running]
        if busy:
            self.report({"ERROR"}, "%s is being baked: cancel the bake first" % ", ".join(busy))
            return {"CANCELLED"}
        freed = []
        try:
            for ob in objects:
                removed, kept = bake.free_bake(ob)
                _report_kept(self, kept)
                if removed:
                    freed.append(ob.name)
        except bake.BakeError as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        self.report({"INFO"}, "Wet Cloth: freed the bakes of %s" % ", ".join(freed) if freed
                    else "Wet Cloth: no bake to free")
        return {"FINISHED"}


def _report_kept(op, kept):
    for path, why in kept:
        op.report({"INFO"}, "Wet Cloth: kept %s: %s" % (path, why))


class WETCLOTH_OT_add_wet_material(bpy.types.Operator):
    """Make the active material darken and shine where the baked cloth is wet (a new material
if the object has none)"""
    bl_idname = "wetcloth.add_wet_material"
    bl_label = "Add Wet Material"
    bl_options = {"REGISTER", "UNDO"}

    object: StringProperty(name="Object", default="", options={"SKIP_SAVE"},
                           description="Object whose material to set up (default: the active "
                                       "object)")

    def execute(self, context):
        try:
            ob = _target(self, context)
            if ob.type != "MESH":
                raise bake.BakeError("%s is not a mesh" % ob.name)
            mat, added = material.add_wet_shading(ob)
        except (bake.BakeError, ValueError) as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        self.report({"INFO"}, "Wet Cloth: %s %s" % (
            mat.name, "now shows the baked wetness" if added else "already shows the wetness"))
        return {"FINISHED"}


classes = (WETCLOTH_OT_bake, WETCLOTH_OT_bake_all, WETCLOTH_OT_free_bake,
           WETCLOTH_OT_free_bake_all, WETCLOTH_OT_add_wet_material)


def register():
    for c in classes:
        bpy.utils.register_class(c)


def unregister():
    for c in reversed(classes):
        bpy.utils.unregister_class(c)
