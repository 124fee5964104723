#!/usr/bin/env python3
"""Draws a picture of the Wet Cloth panels for docs/blender.md.

    .venv-blender/bin/python tools/blender_panel_picture.py
        [--image docs/images/blender_panel.png]

Headless Blender has no user interface to take a screenshot of, so this
runs the panels' own draw code (blender_addon/ui.py) into a layout that
records what it shows, on a cloth that was baked and then edited, and
draws the record with matplotlib (in .venv/'s Python, which has it): the
panels, their order, each setting with its value as Blender formats it, the
buttons and the status lines are the add-on's; the look is only Blender's
in spirit.
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


# ---------------------------------------------------------------------------
# inside bpy: the record


class _Recorder:
    def __init__(self, rows, depth=0, heading=None):
        self.rows, self.depth, self.heading = rows, depth, heading

    def _value(self, data, attr):
        import bpy
        p = data.bl_rna.properties[attr]
        v = getattr(data, attr)
        if p.type == "BOOLEAN":
            return "[x]" if v else "[ ]"
        if p.type == "ENUM":
            return p.enum_items[v].name
        if p.type == "POINTER":
            return v.name if v is not None else ""
        if p.type == "FLOAT":
            if p.unit == "LENGTH":
                return bpy.utils.units.to_string("METRIC", "LENGTH", v, precision=4)
            return "%.6g" % v
        if p.type == "STRING":
            return v or "(none)"
        return str(v)

    def prop(self, data, attr, text=None, **_kw):
        p = data.bl_rna.properties[attr]
        label, value = p.name if text is None else text, self._value(data, attr)
        if self.heading is not None and p.type == "BOOLEAN":
            # a heading shows beside a column's first checkbox, as in Blender
            value = "%s %s" % (value, label)
            label, self.heading = self.heading, None
        self.rows.append(("prop", self.depth, label, value))

    def prop_search(self, data, attr, _search_data, _search_attr, text=None, **_kw):
        self.prop(data, attr, text=text)

    def operator(self, idname, text=None, **_kw):
        import bpy
        if text is None:
            module, name = idname.split(".")
            text = getattr(getattr(bpy.ops, module), name).get_rna_type().name
        self.rows.append(("button", self.depth, text, ""))
        return type("Props", (), {})()

    def label(self, text="", **_kw):
        self.rows.append(("label", self.depth, text, ""))

    def popover(self, **_kw):
        self.rows.append(("preset", self.depth, "Presets", ""))

    def separator(self, **_kw):
        pass

    def _child(self, heading=None, **_kw):
        return _Recorder(self.rows, self.depth, heading)

    column = row = split = _child

    def box(self, **_kw):
        return _Recorder(self.rows, self.depth + 1)


def record(json_path):
    user = tempfile.mkdtemp(prefix="wetcloth-blender-user-")
    os.environ["BLENDER_USER_RESOURCES"] = user
    python = os.path.join(ROOT, ".venv", "bin", "python")
    r = subprocess.run([python, os.path.join(ROOT, "tools", "build_blender_addon.py"),
                        "--out", os.path.join(user, "dist")], capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(r.stdout + r.stderr)
    import bpy  # after BLENDER_USER_RESOURCES

    bpy.ops.extensions.package_install_files(filepath=r.stdout.strip().splitlines()[-1],
                                             repo="user_default", enable_on_install=True)
    module = "bl_ext.user_default.wetcloth"
    try:
        addon = sys.modules[module]
        bpy.ops.wm.read_homefile(use_empty=True)
        bpy.ops.wm.save_as_mainfile(filepath=os.path.join(user, "shot.blend"))
        scene = bpy.context.scene
        scene.frame_start, scene.frame_end = 1, 12
        bpy.ops.mesh.primitive_uv_sphere_add(radius=0.3)
        bpy.context.object.modifiers.new("Collision", "COLLISION")
        bpy.ops.mesh.primitive_plane_add(size=1.0, location=(0.0, 0.0, 0.6))
        cloth = bpy.context.object
        cloth.name = "Sheet"
        bpy.ops.object.mode_set(mode="EDIT")
        bpy.ops.mesh.subdivide(number_cuts=8)
        bpy.ops.object.mode_set(mode="OBJECT")
        cloth.vertex_groups.new(name="Pins")
        s = cloth.wet_cloth
        s.enabled = True
        s.pin_group = "Pins"
        s.integrator = "IMPLICIT"
        with bpy.context.temp_override(active_object=cloth, object=cloth):
            bpy.ops.wetcloth.bake()
        s.adhesion = 40.0  # an edit after the bake: Outdated
        panels = []
        with bpy.context.temp_override(object=cloth, active_object=cloth):
            for cls in addon.ui.classes:
                if not cls.poll(bpy.context):
                    continue
                rows = []
                me = type("Panel", (), {})()
                me.layout = _Recorder(rows)
                if hasattr(cls, "draw_header_preset"):
                    cls.draw_header_preset(me, bpy.context)
                cls.draw(me, bpy.context)
                # the folder line names a temporary folder: keep its end
                rows = [(k, d, t.replace(os.path.dirname(bpy.data.filepath), "…"), v)
                        for k, d, t, v in rows]
                panels.append({"label": cls.bl_label,
                               "sub": getattr(cls, "bl_parent_id", "") != "",
                               "rows": rows})
        with open(json_path, "w") as f:
            json.dump(panels, f, indent=1)
    finally:
        bpy.ops.preferences.addon_disable(module=module)


# ---------------------------------------------------------------------------
# in .venv: the drawing


def draw(json_path, image):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import FancyBboxPatch

    with open(json_path) as f:
        panels = json.load(f)
    # two columns of panels, split where the rows balance
    heights = [1.6 + 0.62 * len(p["rows"]) for p in panels]
    total, acc, split = sum(heights), 0.0, len(panels)
    for i, h in enumerate(heights):
        if acc + h / 2 > total / 2:
            split = i
            break
        acc += h
    columns = [panels[:split], panels[split:]]
    rows_high = max(sum(heights[:split]), sum(heights[split:]))
    fig = plt.figure(figsize=(13.0, rows_high * 0.24 + 0.5), dpi=110)
    fig.patch.set_facecolor("#303030")
    ax = fig.add_axes([0, 0, 1, 1])
    ax.set_xlim(0, 26)
    ax.set_ylim(-rows_high - 0.5, 0.5)
    ax.axis("off")
    text = dict(color="#e6e6e6", fontsize=8.5, va="center", family="DejaVu Sans")
    for c, column in enumerate(columns):
        x0, y = 0.3 + 13.0 * c, 0.0
        for p in column:
            h = 1.2 + 0.62 * len(p["rows"])
            ax.add_patch(FancyBboxPatch((x0, y - h), 12.4, h, boxstyle="round,pad=0.02,rounding_size=0.2",
                                        fc="#3d3d3d", ec="#262626"))
            ax.text(x0 + 0.3, y - 0.55, ("▾ " if p["sub"] else "▼ ") + p["label"],
                    fontweight="bold", **text)
            yy = y - 1.25
            for kind, depth, label, value in p["rows"]:
                xi = x0 + 0.4 + 0.5 * depth
                if kind == "prop":
                    ax.text(xi + 4.6, yy, label, ha="right", **dict(text, color="#bdbdbd"))
                    ax.add_patch(FancyBboxPatch((xi + 4.9, yy - 0.24), 6.6 - 0.5 * depth, 0.48,
                                                boxstyle="round,pad=0.01,rounding_size=0.12",
                                                fc="#545454", ec="#2a2a2a"))
                    ax.text(xi + 5.1, yy, value[:52], **text)
                elif kind == "button":
                    ax.add_patch(FancyBboxPatch((xi, yy - 0.24), 11.5 - 0.5 * depth, 0.48,
                                                boxstyle="round,pad=0.01,rounding_size=0.12",
                                                fc="#595959", ec="#2a2a2a"))
                    ax.text(xi + (11.5 - 0.5 * depth) / 2, yy, label, ha="center", **text)
                elif kind == "preset":
                    ax.text(x0 + 11.6, y - 0.55, "☰", ha="right", **text)
                    continue
                else:
                    ax.text(xi, yy, label[:80], **dict(text, color="#d9c27a"
                                                       if "Outdated" in label else "#cfcfcf"))
                yy -= 0.62
            y -= h + 0.3
    os.makedirs(os.path.dirname(os.path.abspath(image)), exist_ok=True)
    fig.savefig(image, facecolor=fig.get_facecolor())
    print("panel picture: wrote %s" % image)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--image", default=os.path.join(ROOT, "docs", "images", "blender_panel.png"))
    ap.add_argument("--draw", metavar="JSON", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.draw:
        draw(args.draw, args.image)
        return
    with tempfile.TemporaryDirectory(prefix="wetcloth-panel-") as tmp:
        json_path = os.path.join(tmp, "panels.json")
        record(json_path)
        r = subprocess.run([os.path.join(ROOT, ".venv", "bin", "python"), os.path.abspath(__file__),
                            "--draw", json_path, "--image", args.image])
        sys.exit(r.returncode)


if __name__ == "__main__":
    main()
