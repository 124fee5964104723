"""Writes the thesis scenes of this folder (JSON scene files and their OBJ
meshes; format in docs/scenes.md). The files are committed; run this only
to change them:

    PYTHONPATH=build/python .venv/bin/python tools/scenes/make_scenes.py

Each reproduces a figure of the thesis (chapter 3, its wet scenes) with the setup of
the matching test in tests/test_wet.c.
"""

import json
import math
import os

import numpy as np

from wetcloth.demo import uv_sphere
from wetcloth.meshio import write_obj

HERE = os.path.dirname(os.path.abspath(__file__))


def save(name, scene):
    with open(os.path.join(HERE, name), "w", encoding="utf-8") as f:
        json.dump(scene, f, indent=2)
        f.write("\n")


def r(v):
    return [round(float(x), 12) for x in v]


def main():
    # the thesis' 114-vertex solid
    v, t = uv_sphere(0.3, 16, 8)
    write_obj(os.path.join(HERE, "sphere114.obj"), v, t, "sphere114",
              comment="UV sphere, 16 segments x 8 rings, radius 0.3 m: the thesis' 114-vertex "
                      "solid")
    for wetness, name in ((1.0, "wet"), (0.0, "dry")):
        save("thesis_wrap_%s.json" % name, {
            "description": "Thesis Fig. 3.2-3.4: a 1 m cloth of 20 x 20 particles falls 0.6 m "
                           "onto the 114-vertex solid, %s. Dry, its edges stand off the solid; "
                           "wet, it wraps it." % name,
            "duration": 2.0, "fps": 24,
            "cloths": [{"name": name, "wetness": wetness,
                        "grid": {"nu": 20, "nv": 20, "size": [1.0, 1.0],
                                 "center": [0.0, 0.0, 0.6]}}],
            "colliders": [{"type": "mesh", "name": "solid", "obj": "sphere114.obj"}]})

    # slack (Fig. 3.6): a wall leaning back 20 degrees, the top row pinned,
    # pulled 0.15 m off the wall over 1 s, held 1 s, moved 0.15 m sideways
    # over 0.5 s, held 1 s
    a = math.radians(20.0)
    normal = np.array([0.0, math.cos(a), math.sin(a)])
    u, vv = np.array([1.0, 0.0, 0.0]), np.array([0.0, -math.sin(a), math.cos(a)])
    corners = [2.0 * (su * u + sv * vv) for su, sv in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
    n = 16
    keys = [{"time": 0.0, "translate": [0.0, 0.0, 0.0]},
            {"time": 1.0, "translate": r(0.15 * normal)},
            {"time": 2.0, "translate": r(0.15 * normal)},
            {"time": 2.5, "translate": r(0.15 * normal + [0.15, 0.0, 0.0])}]
    save("thesis_slack.json", {
        "description": "Thesis Fig. 3.6: wet cloth on a wall leaning back 20 degrees, top row "
                       "pinned. The pins pull the top 0.15 m off the wall, then move 0.15 m "
                       "sideways: the stuck lower part stays and slack forms (set wetness 0 "
                       "to see dry cloth slide instead).",
        "duration": 3.5, "fps": 24,
        "cloths": [{"name": "cloth", "wetness": 1.0,
                    "grid": {"nu": n, "nv": n, "size": [1.0, 1.0],
                             "center": r(0.004 * normal), "axis_v": r(vv)},
                    "pins": [(n - 1) * n + i for i in range(n)],
                    "pin_keyframes": keys}],
        "colliders": [{"type": "mesh", "name": "wall", "vertices": [r(c) for c in corners],
                       "triangles": [[0, 1, 2], [0, 2, 3]]}]})

    # fold (Fig. 3.7): a stiff strip across two floor plates that slide
    # 0.1 m toward each other over 0.5 s; its middle starts in a 2 cm bump
    nu, nv = 21, 5
    verts = []
    for j in range(nv):
        for i in range(nu):
            x, y = (i / (nu - 1) - 0.5) * 1.0, (j / (nv - 1) - 0.5) * 0.2
            z = 0.004 + (0.01 * (1.0 + math.cos(math.pi * x / 0.15)) if abs(x) < 0.15 else 0.0)
            verts.append([x, y, z])
    quads = [[j * nu + i, j * nu + i + 1, (j + 1) * nu + i + 1, (j + 1) * nu + i]
             for j in range(nv - 1) for i in range(nu - 1)]
    write_obj(os.path.join(HERE, "fold_strip.obj"), verts, quads, "strip",
              comment="1 m x 0.2 m strip, 21 x 5 particles, 2 cm cosine bump in its middle")
    plates = []
    for k, (cx, dx) in enumerate(((-1.0, 0.1), (1.0, -0.1))):
        plates.append({"type": "mesh", "name": "plate%d" % k,
                       "vertices": [[cx - 1, -1, 0], [cx + 1, -1, 0], [cx + 1, 1, 0],
                                    [cx - 1, 1, 0]],
                       "triangles": [[0, 1, 2], [0, 2, 3]],
                       "keyframes": [{"time": 0.0, "translate": [0, 0, 0]},
                                     {"time": 0.5, "translate": [dx, 0, 0]}]})
    save("thesis_fold.json", {
        "description": "Thesis Fig. 3.7: a stiff wet strip lies across two plates that slide "
                       "0.1 m toward each other; its ends stick and ride with the plates, and "
                       "the surplus between them stands up in a fold.",
        "duration": 1.0, "fps": 24,
        "cloths": [{"name": "strip", "wetness": 1.0, "obj": "fold_strip.obj",
                    "material": {"bend": 0.05}}],
        "colliders": plates})


if __name__ == "__main__":
    main()
