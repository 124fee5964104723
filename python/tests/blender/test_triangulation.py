"""The triangles the add-on hands the library depend on the shape alone.

bpy 4.5's UV-sphere operator orders the polygons and loops of the same
sphere differently in each process, so Blender's loop triangles came in a
different order, and the order is part of the library's input: two bakes of
one scene differed by up to 2.7 cm. bake.loop_triangles (colliders, and a
cloth's n-gons) orders the triangles by their vertices; this test runs it in
fresh processes. (A cloth's triangles and quads keep the mesh's own order and
first corners: they are the cloth's topology, a quad is split from its first
corner.)"""

import json
import subprocess
import sys

from conftest import ROOT

SCRIPT = r"""
import hashlib, json, sys
sys.path.insert(0, sys.argv[1])
import bpy
import numpy as np
from blender_addon import bake

bpy.ops.wm.read_homefile(use_empty=True)
bpy.ops.mesh.primitive_uv_sphere_add(segments=16, ring_count=8, radius=0.3)
sphere = bpy.context.object.data
bpy.ops.mesh.primitive_circle_add(vertices=12, fill_type="NGON")
ngon = bpy.context.object.data
out = {}
for name, mesh in (("sphere", sphere), ("ngon", ngon)):
    t, poly = bake.loop_triangles(mesh)
    mesh.calc_loop_triangles()
    blender = np.empty(3 * len(mesh.loop_triangles), dtype=np.int32)
    mesh.loop_triangles.foreach_get("vertices", blender)
    # the same triangles with the same winding: compare each rotated to
    # start at its lowest vertex, as sets
    def canon(a):
        a = a.reshape(-1, 3)
        k = np.argmin(a, axis=1)
        return sorted(tuple(int(x) for x in np.roll(r, -i)) for r, i in zip(a, k))
    out[name] = {"md5": hashlib.md5(t.tobytes()).hexdigest(),
                 "blender_md5": hashlib.md5(blender.tobytes()).hexdigest(),
                 "same_triangles": canon(t) == canon(blender), "count": int(t.shape[0])}
print("RESULT " + json.dumps(out))
"""


def _run_once():
    r = subprocess.run([sys.executable, "-c", SCRIPT, ROOT], capture_output=True, text=True,
                       timeout=300)
    assert r.returncode == 0, r.stdout + r.stderr
    line = [x for x in r.stdout.splitlines() if x.startswith("RESULT ")][-1]
    return json.loads(line[len("RESULT "):])


def test_loop_triangles_are_the_same_in_every_process():
    runs = [_run_once() for _ in range(3)]
    for name, count in (("sphere", 2 * 16 * 7), ("ngon", 10)):
        assert all(r[name]["same_triangles"] for r in runs), name
        assert all(r[name]["count"] == count for r in runs), (name, [r[name] for r in runs])
        assert len({r[name]["md5"] for r in runs}) == 1, (name, [r[name] for r in runs])
    # (Blender's own order differs between these processes in bpy 4.5:
    # printed, not asserted, since a later Blender may fix it.)
    print("Blender's own order, sphere:", sorted({r["sphere"]["blender_md5"] for r in runs}))
