"""Operators: wetcloth.bake and wetcloth.free_bake."""

import time
import traceback

import bpy
from bpy.props import StringProperty

from . import bake

# Objects being baked interactively right now (one bake per object).
_running = set()


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


class WETCLOTH_OT_bake(bpy.types.Operator):
    """Bake the wet cloth simulation of the object into a PC2 cache played back by a Mesh Cache
modifier (Esc cancels and keeps the previous bake)"""
    bl_idname = "wetcloth.bake"
    bl_label = "Bake Wet Cloth"
    bl_options = {"REGISTER"}

    object: StringProperty(name="Object", default="", options={"SKIP_SAVE"},
                           description="Object to bake (default: the active object)")

    _timer = None
    _baker = None

    # synchronous (scripts, headless Blender) --------------------------------

    def execute(self, context):
        try:
            ob = _target(self, context)
        except bake.BakeError as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        if ob.name in _running:
            self.report({"ERROR"}, "%s is being baked already" % ob.name)
            return {"CANCELLED"}
        baker = bake.Baker(context, ob)
        wm = context.window_manager
        progress = False
        try:
            baker.start()
            wm.progress_begin(0, baker.frame_count)
            progress = True
            while not baker.done:
                baker.step()
                wm.progress_update(baker.progress)
            baker.finish()
        except Exception as e:  # reported to the user, previous bake kept
            baker.abort()
            self.report({"ERROR"}, "Wet Cloth bake of %s failed: %s" % (ob.name,
                                                                       _failure_text(e)))
            return {"CANCELLED"}
        finally:
            if progress:
                wm.progress_end()
        self.report({"INFO"}, "Wet Cloth: baked %s, %s" % (ob.name, ob.wet_cloth.bake_info))
        return {"FINISHED"}

    # interactive: modal, cancellable -----------------------------------------

    def invoke(self, context, event):
        if bpy.app.background or context.window is None:
            return self.execute(context)
        try:
            ob = _target(self, context)
        except bake.BakeError as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        if ob.name in _running:
            self.report({"ERROR"}, "%s is being baked already" % ob.name)
            return {"CANCELLED"}
        baker = bake.Baker(context, ob)
        try:
            baker.start()
        except Exception as e:
            baker.abort()
            self.report({"ERROR"}, "Wet Cloth bake of %s failed: %s" % (ob.name,
                                                                       _failure_text(e)))
            return {"CANCELLED"}
        self._baker = baker
        _running.add(ob.name)
        wm = context.window_manager
        wm.progress_begin(0, baker.frame_count)
        self._timer = wm.event_timer_add(0.01, window=context.window)
        wm.modal_handler_add(self)
        self._status(context)
        return {"RUNNING_MODAL"}

    def _status(self, context):
        b = self._baker
        text = "Wet Cloth: baking %s, frame %d of %d (Esc to cancel)" % (
            b.ob.name, b.progress, b.frame_count)
        if context.workspace is not None:
            context.workspace.status_text_set(text)

    def _end(self, context):
        wm = context.window_manager
        if self._timer is not None:
            wm.event_timer_remove(self._timer)
            self._timer = None
        wm.progress_end()
        if context.workspace is not None:
            context.workspace.status_text_set(None)
        _running.discard(self._baker.ob.name)

    def modal(self, context, event):
        b = self._baker
        if event.type == "ESC":
            b.abort()
            self._end(context)
            self.report({"WARNING"}, "Wet Cloth bake of %s cancelled; the previous bake is "
                                     "kept" % b.ob.name)
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
                self.report({"INFO"}, "Wet Cloth: baked %s, %s" % (b.ob.name,
                                                                   b.ob.wet_cloth.bake_info))
                return {"FINISHED"}
        except Exception as e:
            b.abort()
            self._end(context)
            self.report({"ERROR"}, "Wet Cloth bake of %s failed: %s" % (b.ob.name,
                                                                       _failure_text(e)))
            return {"CANCELLED"}
        context.window_manager.progress_update(b.progress)
        self._status(context)
        return {"RUNNING_MODAL"}


class WETCLOTH_OT_free_bake(bpy.types.Operator):
    """Remove the baked cache, its Mesh Cache modifier and the wetness attributes"""
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
            removed = bake.free_bake(ob)
        except bake.BakeError as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        if removed:
            self.report({"INFO"}, "Wet Cloth: freed the bake of %s (%s)" % (
                ob.name, ", ".join(removed)))
        else:
            self.report({"INFO"}, "Wet Cloth: %s has no bake to free" % ob.name)
        return {"FINISHED"}


classes = (WETCLOTH_OT_bake, WETCLOTH_OT_free_bake)


def register():
    for c in classes:
        bpy.utils.register_class(c)


def unregister():
    for c in reversed(classes):
        bpy.utils.unregister_class(c)
