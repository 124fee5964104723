"""Scenes of the measurement suite, built with the wetcloth binding.

Python holds no physics here: these functions only place cloths and
colliders; every number comes from libwetcloth.
"""
import math

import numpy as np

import wetcloth

FRAME = 1.0 / 24


def uv_sphere(radius=0.3, segments=16, rings=8):
    """The thesis' solid: 2 + (rings - 1) * segments vertices (114 for 16 x 8)."""
    v = [(0.0, 0.0, radius)]
    for j in range(1, rings):
        polar = math.pi * j / rings
        for i in range(segments):
            az = 2.0 * math.pi * i / segments
            v.append((radius * math.sin(polar) * math.cos(az),
                      radius * math.sin(polar) * math.sin(az), radius * math.cos(polar)))
    v.append((0.0, 0.0, -radius))
    bottom = len(v) - 1
    t = [(0, 1 + i, 1 + (i + 1) % segments) for i in range(segments)]
    for j in range(rings - 2):
        for i in range(segments):
            a = 1 + j * segments + i
            b = 1 + j * segments + (i + 1) % segments
            t += [(a, a + segments, b), (b, a + segments, b + segments)]
    base = 1 + (rings - 2) * segments
    t += [(bottom, base + (i + 1) % segments, base + i) for i in range(segments)]
    return np.array(v, float), np.array(t, np.int32)


def drape(n, integrator="verlet", wet=False, self_collision=False, threads=1, smooth=False,
          adapt_threads=True):
    """The thesis drape: n x n grid cloth, 1 m, 0.6 m above the 114-vertex
    UV sphere of radius 0.3 m (Table 3.2's scene); wet = soaked (w = 1).
    smooth: the analytic sphere of the same radius (a convex collider)
    instead of the mesh, the control for the mesh's facets."""
    w = wetcloth.World(integrator=integrator, threads=threads, adapt_threads=adapt_threads)
    if smooth:
        w.add_sphere((0.0, 0.0, 0.0), 0.3)
    else:
        v, t = uv_sphere()
        w.add_mesh_collider(v, t)
    c = w.add_grid_cloth(n, n, center=(0.0, 0.0, 0.6), wetness=1.0 if wet else 0.0,
                         self_collision=self_collision)
    return w, c


def hanging(n, integrator="verlet", threads=1):
    """An n x n 1 m cloth pinned at two corners, swinging down from level."""
    w = wetcloth.World(integrator=integrator, threads=threads)
    c = w.add_grid_cloth(n, n)
    c.pin([n * (n - 1), n * n - 1])
    return w, c


def resting(n, self_collision, threads):
    """An n x n cloth of link length 1/63 m lying on a ground plate (every
    particle in contact): bench_collide's cost-per-particle-step scene."""
    w = wetcloth.World(threads=threads)
    size = (n - 1) / 63.0
    h = size
    w.add_mesh_collider(np.array([[-h, -h, 0], [h, -h, 0], [h, h, 0], [-h, h, 0]], float),
                        np.array([[0, 1, 2], [0, 2, 3]], np.int32))
    c = w.add_grid_cloth(n, n, size=(size, size), center=(0.0, 0.0, 0.00505),
                         self_collision=self_collision)
    return w, c


SCENES = {
    "drape_dry": lambda n, integ: drape(n, integ, wet=False),
    "drape_wet": lambda n, integ: drape(n, integ, wet=True),
    "hanging": lambda n, integ: hanging(n, integ),
    "drape_dry_smooth": lambda n, integ: drape(n, integ, wet=False, smooth=True),
}
"""Scenes of the speed-against-error section; the last is a control (Verlet
only): the dry drape onto the analytic sphere instead of the mesh."""
CONTROLS = ("drape_dry_smooth",)
