"""The thesis drape frame by frame: how far its links stretch, and whether
cloth crosses the sphere, for one integrator and steps per frame.

    PYTHONPATH=build/python .venv/bin/python tools/bench/drape_stretch.py \
        --size 101 --integrator implicit --steps 10 --frames 12 [--sphere mesh|exact] \
        [--friction 0.3]

Per frame: the longest link as a multiple of its rest length (every link
of the cloth's triangles, structural and diagonal), the particle at its
end nearest the sphere's pole (the cloth's top), the particles in contact,
the fail-safe's particles over the frame's steps, the conjugate-gradient
iterations (implicit only) and the checker's cloth-collider intersecting
triangle pairs. It only reads the library's state; docs/model.md quotes
its figures."""
import argparse
import sys

import numpy as np

import wetcloth
from wetcloth.demo import uv_sphere


def _at_least(low):
    """An argparse type: an integer >= low, else an error naming both."""
    def parse(text):
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError("must be an integer >= %d, got %r" % (low, text))
        if value < low:
            raise argparse.ArgumentTypeError("must be at least %d, got %d" % (low, value))
        return value
    return parse


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--size", type=_at_least(2), default=101, help="particles per side (n x n)")
    ap.add_argument("--integrator", default="implicit", choices=sorted(wetcloth.World.INTEGRATORS))
    ap.add_argument("--steps", type=_at_least(1), default=10, help="steps per frame of 1/24 s")
    ap.add_argument("--frames", type=_at_least(1), default=12)
    ap.add_argument("--sphere", default="mesh", choices=("mesh", "exact"),
                    help="the 114-vertex UV sphere, or libccd's exact sphere")
    ap.add_argument("--friction", type=float, default=0.3, help="the sphere's friction, [0, 10]")
    ap.add_argument("--threads", type=_at_least(0), default=1, help="0 = OpenMP's default")
    a = ap.parse_args(argv)
    try:
        return run(a)
    except wetcloth.WetclothError as e:
        ap.error(str(e))


def run(a):
    """The drape with the parsed arguments `a`, its table on stdout."""
    w = wetcloth.World(integrator=a.integrator, threads=a.threads)
    if a.sphere == "mesh":
        v, t = uv_sphere()
        w.add_mesh_collider(v, t, friction=a.friction)
    else:
        w.add_sphere((0.0, 0.0, 0.0), 0.3, friction=a.friction)
    cloth = w.add_grid_cloth(a.size, a.size, center=(0.0, 0.0, 0.6))
    tris = cloth.triangles
    links = np.unique(np.sort(np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]]),
                              axis=1), axis=0)
    p = cloth.positions
    rest = np.linalg.norm(p[links[:, 0]] - p[links[:, 1]], axis=1)
    print("frame  longest link / rest  at (height m)  in contact  fail-safe  cg  cloth-collider")
    for f in range(a.frames):
        failsafe = solver = 0
        for _ in range(a.steps):
            w.step(1.0 / 24.0 / a.steps)
            s = w.stats
            failsafe += s["failsafe_particles"]
            solver += s["solver_iterations"]
        p = cloth.positions
        ratio = np.linalg.norm(p[links[:, 0]] - p[links[:, 1]], axis=1) / rest
        k = int(np.argmax(ratio))
        top = max(p[links[k, 0], 2], p[links[k, 1], 2])
        crossing = w.count_intersections()["cloth_collider"]
        print("%5d  %19.2f  %13.3f  %10d  %9d  %6d  %14d" % (
            f, ratio[k], top, int(cloth.in_contact.sum()), failsafe, solver, crossing))
    return 0


if __name__ == "__main__":
    sys.exit(main())
