"""The panels, drawn headless into a layout that records what they show:
Blender's habits (presets in the header, the quality in the main panel,
each setting once, units from the properties rather than the labels,
tooltips in plain words), and the Cache panel staying while a bake plays."""

import re
import sys
from types import SimpleNamespace

import bpy
import pytest

from conftest import MODULE
from test_addon import add_cloth, add_sphere, bake


class Recorder:
    """Stands for a UILayout: every call is recorded in a shared list."""

    def __init__(self, calls, panel):
        self._calls, self._panel = calls, panel

    def _record(self, kind, *args, **kw):
        self._calls.append((self._panel, kind, args, kw))

    def prop(self, data, attr, **kw):
        assert hasattr(data, attr), attr
        self._record("prop", data, attr, **kw)

    def prop_search(self, data, attr, search_data, search_attr, **kw):
        assert hasattr(data, attr) and hasattr(search_data, search_attr), attr
        self._record("prop", data, attr, **kw)

    def operator(self, idname, **kw):
        module, name = idname.split(".")
        assert hasattr(getattr(bpy.ops, module), name), idname
        self._record("operator", idname, **kw)
        return SimpleNamespace()

    def label(self, **kw):
        self._record("label", **kw)

    def popover(self, **kw):
        self._record("popover", **kw)

    def separator(self, **_kw):
        pass

    def _child(self, **_kw):
        return Recorder(self._calls, self._panel)

    column = row = box = split = _child


def draw_all(ob):
    """(calls, panels shown) of every Wet Cloth panel for the object."""
    addon = sys.modules[MODULE]
    calls, shown = [], []
    with bpy.context.temp_override(object=ob, active_object=ob):
        context = bpy.context
        for cls in addon.ui.classes:
            if not cls.poll(context):
                continue
            shown.append(cls.bl_label)
            me = SimpleNamespace(layout=Recorder(calls, cls.bl_label))
            if hasattr(cls, "draw_header_preset"):
                cls.draw_header_preset(me, context)
            cls.draw(me, context)
    return calls, shown


def props_drawn(calls):
    return [(panel, args[1]) for panel, kind, args, _kw in calls if kind == "prop"]


@pytest.fixture
def cloth(project):
    add_sphere()
    return add_cloth(z=0.6, cuts=4)


def test_layout_follows_blenders_cloth(cloth):
    calls, shown = draw_all(cloth)
    assert shown == ["Wet Cloth", "Physical Properties", "Shape", "Collisions", "Wetness",
                     "Field Weights", "Cache"]
    drawn = props_drawn(calls)
    names = [attr for _panel, attr in drawn]
    # every setting once (Wetness appeared twice before)
    repeated = {n for n in names if names.count(n) > 1}
    assert not repeated, repeated
    where = dict((attr, panel) for panel, attr in drawn)
    assert where["integrator"] == where["substeps"] == where["substeps_auto"] == "Wet Cloth"
    assert where["density"] == "Physical Properties"
    assert where["pin_stiffness"] == "Shape" and where["pin_group"] == "Shape"
    assert where["thickness"] == "Collisions"
    assert where["wetness"] == "Wetness"
    assert where["field_wind"] == "Field Weights"
    assert where["cache_dir"] == "Cache"
    # the presets are Blender's preset popover in the header
    popovers = [kw for panel, kind, _a, kw in calls if kind == "popover"]
    assert popovers and popovers[0]["panel"] == "WETCLOTH_PT_presets"
    ops = [args[0] for _p, kind, args, _kw in calls if kind == "operator"]
    for op in ("wetcloth.bake", "wetcloth.free_bake", "wetcloth.bake_all",
               "wetcloth.add_wet_material"):
        assert op in ops
    assert ops.count("wetcloth.bake") == 2  # Bake and Bake to Current Frame
    # units come from the properties, not from the labels
    for _panel, kind, args, kw in calls:
        if kind == "prop":
            assert not re.search(r"kg|N/m|N·m|Pa\b|m²|1/s|\bm\b", kw.get("text", "")), kw
    rna = cloth.wet_cloth.bl_rna.properties
    assert rna["thickness"].unit == "LENGTH"
    # an unsaved-file note only where it applies
    labels = [kw.get("text", "") for _p, kind, _a, kw in calls if kind == "label"]
    assert not any("temporary folder" in t for t in labels)
    assert any(t.startswith("Folder: ") and "wetcloth_shot" in t for t in labels)


def test_tooltips_in_plain_words(installed):
    """No file names, document names or thesis symbols in what the artist
    reads."""
    settings = bpy.types.Object.bl_rna.properties["wet_cloth"].fixed_type
    texts = [(p.identifier, p.name + " " + p.description) for p in settings.properties]
    for idname in ("bake", "bake_all", "free_bake", "free_bake_all", "add_wet_material",
                   "preset_add"):
        op = getattr(bpy.types, "WETCLOTH_OT_" + idname)
        texts.append((idname, op.__doc__ or ""))
        for p in op.bl_rna.properties:
            texts.append((idname + "." + p.identifier, p.description))
    bad = re.compile(r"\.md\b|docs/|thesis|\bSPEC\b|\bNOTES\b|\bbeta\b|\bXPBD\b|Choi|\.py\b")
    offending = [(k, t) for k, t in texts if bad.search(t)]
    assert not offending, offending
    # every setting an artist edits has a tooltip
    missing = [p.identifier for p in settings.properties
               if p.identifier not in ("rna_type", "name") and not p.description]
    assert not missing, missing


def test_outdated_and_unticked(cloth):
    assert bake(cloth) == {"FINISHED"}
    calls, _shown = draw_all(cloth)
    labels = [kw.get("text", "") for _p, kind, _a, kw in calls if kind == "label"]
    assert any(t.startswith("Baked: ") for t in labels), labels
    cloth.wet_cloth.stretch = 2000.0
    calls, _shown = draw_all(cloth)
    labels = [kw.get("text", "") for _p, kind, _a, kw in calls if kind == "label"]
    assert any(t.startswith("Outdated") for t in labels), labels
    # unticked: the bake still plays, so the Cache panel (with Free Bake) stays
    cloth.wet_cloth.enabled = False
    calls, shown = draw_all(cloth)
    assert shown == ["Wet Cloth", "Cache"]
    assert "wetcloth.free_bake" in [a[0] for _p, k, a, _kw in calls if k == "operator"]
    assert bpy.ops.wetcloth.free_bake(object=cloth.name) == {"FINISHED"}
    # freed while unticked: the modifier goes too, and with it the panel
    assert "Wet Cloth" not in cloth.modifiers
    _calls, shown = draw_all(cloth)
    assert shown == ["Wet Cloth"]


def test_unsaved_file_says_where_the_bake_goes(empty_scene):
    add_sphere()
    cloth = add_cloth(z=0.6, cuts=4)
    calls, _shown = draw_all(cloth)
    labels = [kw.get("text", "") for _p, kind, _a, kw in calls if kind == "label"]
    assert any("temporary folder" in t for t in labels), labels
    assert any("saving moves them" in t for t in labels), labels
