"""Where a bake's files live, and which of them an object may replace or
delete.

* **One folder per .blend file**, as Blender's own `blendcache_<file>`: the
  bakes of shot_v1.blend are in `wetcloth_shot_v1/` next to it (or in the
  Cache Folder when one is set), so a copy saved as shot_v2.blend bakes into
  `wetcloth_shot_v2/` and never touches shot_v1's files. An unsaved file
  bakes into Blender's temporary folder; saving the file moves its bakes
  next to it (move_unsaved_bakes, a save_pre handler).
* **Files named by the object's cache identity**: a random id kept on the
  object (`wet_cloth.cache_id`), with the readable name beside it
  (`Sheet.001.5f0c29e1a7b34d12.pc2`), so that names that clean up to the
  same text (Sheet.001, Sheet_001) and renames cannot make two objects share
  a file. A copy of an object (Shift D, Alt D, or a copied .blend) carries
  the id along; the first bake of the copy gives it an id of its own
  (claim_identity).
* **Only this object's files are replaced or deleted**: a file whose name
  carries the object's id, in the folder of this .blend (or the temporary
  folder), that no other object plays (deletable). Anything else is left
  where it is.
* **Nothing half-written**: a bake writes `.<file>.<pid>.tmp` and renames it
  over the old file only when the bake has finished; a bake that was killed
  leaves its temporary files behind, and the object's next bake removes
  those of a process that no longer runs.
"""

import os
import shutil

import bpy

from . import props, stack

FOLDER_PREFIX = "wetcloth_"
UNSAVED_FOLDER = "wetcloth_unsaved"
POSITIONS_SUFFIX = ".pc2"
WETNESS_SUFFIX = ".wetness.pc2"


class CacheError(Exception):
    pass


def _blend_name():
    """The .blend file's name without its extension, or None if unsaved."""
    if not bpy.data.filepath:
        return None
    return os.path.splitext(os.path.basename(bpy.data.filepath))[0]


def unsaved_folder():
    return os.path.join(bpy.app.tempdir or os.path.join(os.path.sep, "tmp"), UNSAVED_FOLDER)


def folder_for(settings, blend_path=None):
    """(absolute folder, how to show it) of a bake of an object with these
    settings in the .blend at blend_path (default: the current one)."""
    blend_path = bpy.data.filepath if blend_path is None else blend_path
    if not blend_path:
        return unsaved_folder(), "the temporary folder (saving the file moves it next to it)"
    name = os.path.splitext(os.path.basename(blend_path))[0]
    base = settings.cache_dir.strip()
    if not base:
        base = "//"
    if base.startswith("//"):
        base = os.path.join(os.path.dirname(blend_path), base[2:])
    folder = os.path.normpath(os.path.join(os.path.abspath(base), FOLDER_PREFIX + name))
    return folder, folder


def file_setting(path, blend_path=None):
    """The path as a modifier should keep it: "//" relative when it is
    inside the .blend file's folder."""
    blend_path = bpy.data.filepath if blend_path is None else blend_path
    if blend_path:
        base = os.path.dirname(blend_path)
        rel = os.path.relpath(path, base)
        if not rel.startswith(os.pardir):
            return "//" + rel.replace(os.sep, "/")
    return path


def claim_identity(ob):
    """Gives the object an id of its own if it has none, or if another object
    has the same one and this is not the object that id was first used for
    (a copy). Returns the id."""
    s = ob.wet_cloth
    others = [o for o in bpy.data.objects
              if o is not ob and o.type == "MESH" and o.wet_cloth.cache_id == s.cache_id]
    if not s.cache_id or (others and s.cache_owner != ob.name):
        s.cache_id = props.new_cache_id()
    s.cache_owner = ob.name
    return s.cache_id


def file_names(ob):
    """(positions, wetness) file names of the object's next bake."""
    stem = "%s.%s" % (bpy.path.clean_name(ob.name), ob.wet_cloth.cache_id)
    return stem + POSITIONS_SUFFIX, stem + WETNESS_SUFFIX


def temp_path(final):
    folder, name = os.path.split(final)
    return os.path.join(folder, ".%s.%d.tmp" % (name, os.getpid()))


def _process_alive(pid):
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OSError):
        return True
    return True


def remove_stale_temps(folder, cache_id, busy=()):
    """Removes this id's temporary files left by a bake that no longer runs
    (a killed Blender, or a failed bake of this session that could not
    clean up); `busy` are the temporary files of bakes running now."""
    marker = ".%s." % cache_id
    removed = []
    try:
        names = os.listdir(folder)
    except OSError:
        return removed
    for name in names:
        if not (name.startswith(".") and name.endswith(".tmp") and marker in name):
            continue
        path = os.path.join(folder, name)
        try:
            pid = int(name[:-4].rsplit(".", 1)[1])
        except (IndexError, ValueError):
            continue
        if path in busy or (pid != os.getpid() and _process_alive(pid)):
            continue
        try:
            os.remove(path)
            removed.append(path)
        except OSError:
            pass
    return removed


def _played_by_others(path, ob):
    path = os.path.normpath(path)
    for o in bpy.data.objects:
        if o is ob or o.type != "MESH":
            continue
        played = {os.path.normpath(p) for p in stack.referenced_files(o)}
        for own in (o.wet_cloth.cache_file, o.wet_cloth.wetness_file):
            if own:
                played.add(os.path.normpath(bpy.path.abspath(own)))
        if path in played:
            return o
    return None


def why_not_deletable(path, ob):
    """None if the file is this object's own to delete, else why not."""
    s = ob.wet_cloth
    name = os.path.basename(path)
    if not s.cache_id or (".%s." % s.cache_id) not in name:
        return "it was not written by this object's bakes"
    folder = os.path.normpath(os.path.dirname(path))
    own = {os.path.normpath(folder_for(s)[0]), os.path.normpath(unsaved_folder())}
    if folder not in own:
        return "it belongs to another .blend file's bakes"
    other = _played_by_others(path, ob)
    if other is not None:
        return "%s plays it too" % other.name
    return None


def delete_own(paths, ob):
    """Deletes those of `paths` that are this object's own; returns
    (deleted, kept as [(path, why)])."""
    deleted, kept = [], []
    for path in paths:
        if not path or not os.path.exists(path):
            continue
        why = why_not_deletable(path, ob)
        if why:
            kept.append((path, why))
            continue
        try:
            os.remove(path)
            deleted.append(path)
        except OSError as e:
            kept.append((path, e.strerror or str(e)))
    return deleted, kept


def ensure_folder(folder):
    try:
        os.makedirs(folder, exist_ok=True)
    except OSError as e:
        raise CacheError("cannot create the cache folder %s: %s" % (folder, e.strerror or e))
    if not os.access(folder, os.W_OK | os.X_OK):
        raise CacheError("cannot write into the cache folder %s" % folder)


# ---------------------------------------------------------------------------
# Saving an unsaved file


def _unsaved_files(ob):
    """The object's bake files in the temporary folder."""
    s, tmp = ob.wet_cloth, os.path.normpath(unsaved_folder())
    out = []
    for attr in ("cache_file", "wetness_file"):
        path = getattr(s, attr)
        if path and os.path.normpath(os.path.dirname(bpy.path.abspath(path))) == tmp:
            out.append((attr, bpy.path.abspath(path)))
    return out


def move_unsaved_bakes(blend_path):
    """Moves the bakes made while the file was unsaved into the folder of
    the file it is being saved as, and points the modifiers there (called
    before Blender writes the file, so the file keeps the new paths).
    Returns the moved paths. A file already there is never overwritten: the
    bake then stays where it is."""
    moved = []
    for ob in bpy.data.objects:
        if ob.type != "MESH" or ob.library is not None:
            continue
        files = _unsaved_files(ob)
        if not files:
            continue
        folder = folder_for(ob.wet_cloth, blend_path)[0]
        try:
            ensure_folder(folder)
        except CacheError as e:
            print("Wet Cloth: %s; the bake of %s stays in %s" % (e, ob.name, unsaved_folder()))
            continue
        targets = [(attr, src, os.path.join(folder, os.path.basename(src))) for attr, src in files]
        if any(os.path.exists(dst) for _a, _s, dst in targets):
            print("Wet Cloth: %s already has files named as %s's bake; it stays in %s"
                  % (folder, ob.name, unsaved_folder()))
            continue
        for attr, src, dst in targets:
            if not os.path.exists(src):
                continue
            shutil.move(src, dst)
            setattr(ob.wet_cloth, attr, dst)
            for m in ob.modifiers:
                if m.type == "MESH_CACHE" and m.filepath and \
                        os.path.normpath(bpy.path.abspath(m.filepath)) == os.path.normpath(src):
                    m.filepath = dst
            moved.append(dst)
    return moved
