"""The built-in demo scene: the thesis scene wet against dry.

Two 1 m cloths of 20 x 20 particles fall from 0.6 m onto two copies of the
thesis' 114-vertex solid (a UV sphere of 16 segments and 8 rings, radius
0.3 m), one cloth dry, one soaked (wetness 1), for two seconds at 24 fps.
The dry cloth drapes and its edges stand off the solid; the wet one sticks
and wraps it (thesis Fig. 3.2-3.4). Both collide with themselves: the wet
one's folds would otherwise pass through each other at the default
integrator's large steps.
"""

import math

import numpy as np


def uv_sphere(radius=0.3, segments=16, rings=8, center=(0.0, 0.0, 0.0)):
    """(vertices (2 + (rings-1)*segments, 3), triangles (2*segments*(rings-1), 3)),
    outward facing; the same solid as tests/scenes.c's scene_uv_sphere."""
    v = [[0.0, 0.0, radius]]
    for j in range(1, rings):
        polar = math.pi * j / rings
        for i in range(segments):
            azimuth = 2.0 * math.pi * i / segments
            v.append([radius * math.sin(polar) * math.cos(azimuth),
                      radius * math.sin(polar) * math.sin(azimuth), radius * math.cos(polar)])
    v.append([0.0, 0.0, -radius])
    bottom = len(v) - 1
    t = [[0, 1 + i, 1 + (i + 1) % segments] for i in range(segments)]
    for j in range(rings - 2):
        for i in range(segments):
            a, b = 1 + j * segments + i, 1 + j * segments + (i + 1) % segments
            c, d = a + segments, b + segments
            t += [[a, c, b], [b, c, d]]
    base = 1 + (rings - 2) * segments
    t += [[bottom, base + (i + 1) % segments, base + i] for i in range(segments)]
    return np.array(v) + np.asarray(center, dtype=float), np.array(t)


def scene_dict(separation=1.6):
    """The demo as a scene description (the format of docs/scenes.md)."""
    cloths, colliders = [], []
    for name, wetness, x in (("dry", 0.0, -separation / 2), ("wet", 1.0, separation / 2)):
        v, t = uv_sphere(0.3, 16, 8, (x, 0.0, 0.0))
        colliders.append({"type": "mesh", "name": "solid_" + name,
                          "vertices": v.tolist(), "triangles": t.tolist()})
        cloths.append({"name": name, "wetness": wetness, "self_collision": True,
                       "grid": {"nu": 20, "nv": 20, "size": [1.0, 1.0], "center": [x, 0.0, 0.6]}})
    return {"description": "thesis scene (Fig. 3.2-3.4), dry (left) and wet (right)",
            "duration": 2.0, "fps": 24, "cloths": cloths, "colliders": colliders}
