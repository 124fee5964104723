"""The "outdated" flag of a bake, and the handlers that keep the bakes
right across edits and saves.

A bake is outdated when anything that affects its result changed after it:
a Wet Cloth setting (each setting's update marks it, props.py), the cloth
object's transform, mesh or modifiers, or a collider or force field the bake
used (seen here in the depsgraph's updates). The flag is conservative: an
edit that does not change the result (a modifier below Wet Cloth, say) sets
it too. Playing the animation changes nothing and sets nothing.

The add-on's own changes to an object (a bake hooking up its modifiers)
run inside suppressed() and flush the depsgraph before leaving it, so they
never mark anything. The same handler keeps the wetness modifiers with the
Wet Cloth modifier when the artist hides, moves or removes it
(stack.sync).
"""

import contextlib

import bpy

from . import cache, stack

_suppress = 0


@contextlib.contextmanager
def suppressed():
    global _suppress
    _suppress += 1
    try:
        yield
    finally:
        _suppress -= 1


def _baked_cloths():
    return [o for o in bpy.data.objects
            if o.type == "MESH" and o.library is None and o.wet_cloth.cache_file]


@bpy.app.handlers.persistent
def on_depsgraph_update(_scene, depsgraph):
    if _suppress:
        return
    changed = set()
    for update in depsgraph.updates:
        ob = update.id.original if update.id is not None else None
        if isinstance(ob, bpy.types.Object) and (update.is_updated_transform or
                                                 update.is_updated_geometry):
            changed.add(ob.name)
            if ob.type == "MESH" and ob.library is None and update.is_updated_geometry:
                with suppressed():
                    stack.sync(ob)  # the artist hid, moved or removed Wet Cloth
    if not changed:
        return
    for cloth in _baked_cloths():
        s = cloth.wet_cloth
        if s.outdated:
            continue
        if cloth.name in changed or changed & set(s.baked_inputs.split("\n")):
            s.outdated = True


@bpy.app.handlers.persistent
def on_save_pre(filepath, *_args):
    """Bakes of an unsaved file move next to the file it is saved as."""
    if filepath:
        with suppressed():
            cache.move_unsaved_bakes(filepath)


def register():
    bpy.app.handlers.depsgraph_update_post.append(on_depsgraph_update)
    bpy.app.handlers.save_pre.append(on_save_pre)


def unregister():
    for handlers, fn in ((bpy.app.handlers.depsgraph_update_post, on_depsgraph_update),
                         (bpy.app.handlers.save_pre, on_save_pre)):
        while fn in handlers:
            handlers.remove(fn)
