"""Blender's cloth and libwetcloth side by side, in one process.

Run by report.py under the Python that has bpy 4.5 (.venv-blender), with
PYTHONPATH giving the wetcloth package (and cffi) and WETCLOTH_LIBRARY the
library. Prints a markdown section; --json writes the figures.

Scene (the thesis' Table 3.2): an n x n grid cloth 1 m wide, 0.6 m above
the 114-vertex UV sphere (16 x 8, radius 0.3 m), 24 fps. Blender: the Cloth
modifier with its defaults and quality 5 (5 steps per frame), the sphere with
a Collision modifier, self-collision on or off; the frames are evaluated in
order with scene.frame_set. Ours: the same geometry with the default
material and the default integrator at automatic substeps, World()'s
defaults. Both in this process, one after the other: ours on 1 thread, and
again with the default thread count (0: every core, adapt_threads on), which
is what a user gets; Blender uses its own thread pool on the same cores. The
materials are not the same (Blender's defaults against our cotton): the
ratio compares what a user gets from each with default settings on this
scene.

Frames: 48 up to 20 x 20, 24 up to 60 x 60, 12 beyond (0.5 s: the cloth
reaches the sphere at 0.25 s and drapes); what makes the large sizes slow is
Blender with self-collision and our error's reference (8x our substeps).

Reported: wall time per simulated frame of each and their ratio; our error
(RMS over particles and frames of the distance to our reference, Verlet at
8x our automatic substeps, / 1 m); intersections at the last frame on both
sides, counted by libwetcloth's independent checker (Blender's final mesh is
loaded into a checker-only world).
"""
import argparse
import inspect
import json
import os
import sys
import tempfile
import time

os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp(prefix="wc-bench-blender-"))

import bpy  # noqa: E402
import numpy as np  # noqa: E402

import wetcloth  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import scenes  # noqa: E402


# What World() gives without choosing (scenes.drape's own default is Verlet,
# the thesis' reference).
DEFAULT_INTEGRATOR = inspect.signature(wetcloth.World).parameters["integrator"].default


def grid(n, z=0.6):
    a = np.arange(n) / (n - 1) - 0.5
    x, y = np.meshgrid(a, a)
    v = np.c_[x.ravel(), y.ravel(), np.full(n * n, z)]
    q = [(j * n + i, j * n + i + 1, (j + 1) * n + i + 1, (j + 1) * n + i)
         for j in range(n - 1) for i in range(n - 1)]
    return v, np.array(q, np.int32)


def blender_run(n, self_collision, frames):
    bpy.ops.wm.read_homefile(use_empty=True)
    scene = bpy.context.scene
    scene.render.fps = 24
    scene.frame_start = 1
    scene.frame_end = frames + 1
    sv, st = scenes.uv_sphere()
    me = bpy.data.meshes.new("sphere")
    me.from_pydata(sv.tolist(), [], st.tolist())
    me.update()
    sphere = bpy.data.objects.new("sphere", me)
    scene.collection.objects.link(sphere)
    sphere.modifiers.new("Collision", "COLLISION")
    v, q = grid(n)
    me = bpy.data.meshes.new("cloth")
    me.from_pydata(v.tolist(), [], q.tolist())
    me.update()
    cloth = bpy.data.objects.new("cloth", me)
    scene.collection.objects.link(cloth)
    mod = cloth.modifiers.new("Cloth", "CLOTH")
    mod.settings.quality = 5
    mod.collision_settings.use_self_collision = self_collision
    mod.point_cache.frame_start = 1
    mod.point_cache.frame_end = frames + 1
    scene.frame_set(1)
    t0 = time.perf_counter()
    for f in range(2, frames + 2):
        scene.frame_set(f)
    wall = (time.perf_counter() - t0) / frames
    dg = bpy.context.evaluated_depsgraph_get()
    ev = cloth.evaluated_get(dg)
    m = ev.to_mesh()
    pos = np.empty(3 * len(m.vertices))
    m.vertices.foreach_get("co", pos)
    ev.to_mesh_clear()
    pos = pos.reshape(-1, 3)
    # Blender's result in our independent checker (no step is taken)
    w = wetcloth.World(threads=1)
    w.add_mesh_collider(sv, st)
    w.add_cloth(pos, q)
    k = w.count_intersections()
    w.close()
    bpy.ops.wm.read_homefile(use_empty=True)
    return wall, k, bool(np.all(np.isfinite(pos)))


def ours(n, self_collision, frames, substeps=0, threads=1, adapt=True):
    """Our run: wall s per frame, positions per frame, intersections at the
    end, substeps per frame, and its fastest particle at any frame's end,
    m/s (a sanity figure for the reference). threads=0: the default count
    (every core, adapt_threads on); adapt=False runs exactly `threads`; the
    positions are the same bits for any count."""
    w, c = scenes.drape(n, DEFAULT_INTEGRATOR, self_collision=self_collision, threads=threads,
                        adapt_threads=adapt)
    out, wall, fastest = [], 0.0, 0.0
    for _ in range(frames):
        t0 = time.perf_counter()
        used = w.advance(scenes.FRAME, substeps)
        wall += time.perf_counter() - t0
        out.append(c.positions)
        fastest = max(fastest, float(np.linalg.norm(c.velocities, axis=1).max()))
    k = w.count_intersections()
    w.close()
    return wall / frames, np.array(out), k, used, fastest


def frames_for(n):
    """Frames of the run for an n x n cloth (see the module's docstring)."""
    return 48 if n <= 20 else 24 if n <= 60 else 12


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--json")
    ap.add_argument("--sizes", default="10,15,20,51,101",
                    help="grid sizes n of the full run (48 frames up to 20, 24 up to 60, else 12)")
    a = ap.parse_args()
    cases = [(10, 12)] if a.quick else [(n, frames_for(n)) for n in map(int, a.sizes.split(","))]
    print(f"bpy {bpy.app.version_string}, libwetcloth {wetcloth.__version__}; load average "
          f"before: {' '.join(open('/proc/loadavg').read().split()[:3])}.")
    print()
    cores = os.cpu_count()
    print(f"Ours at World()'s defaults ({DEFAULT_INTEGRATOR} integrator, automatic substeps) on 1 "
          f"thread, with the default thread count (every core: {cores} here, adapt_threads on: "
          f"the world starts on one and tries more after a few steps), and on exactly {cores} "
          "threads (adapt_threads off); Blender on its own thread pool.")
    print()
    print("| particles | self-collision | frames | Blender ms/frame | ours ms/frame, 1 thread "
          "| Blender / ours, 1 thread | ours ms/frame, default threads | Blender / ours, default threads "
          f"| ours ms/frame, {cores} threads | Blender / ours, {cores} threads "
          "| our substeps/frame | our error / size | intersections ours (cloth-cloth, cloth-sphere) "
          "| intersections Blender | lowest point at the end, ours / reference, m "
          "| fastest particle, ours / reference, m/s |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    rows = []
    for n, frames in cases:
        for self_c in (True, False):
            bw, bk, bfinite = blender_run(n, self_c, frames)
            ow, opos, ok, sub, ofast = ours(n, self_c, frames)
            tw, tpos, _, _, _ = ours(n, self_c, frames, threads=0)
            fw, fpos, _, _, _ = ours(n, self_c, frames, threads=cores, adapt=False)
            if not (np.array_equal(tpos, opos) and np.array_equal(fpos, opos)):
                raise SystemExit(f"{n}: positions differ between thread counts")
            _, rpos, _, _, rfast = ours(n, self_c, frames, 8 * sub, threads=0)
            d = np.linalg.norm(opos - rpos, axis=2)
            err = float(np.sqrt(np.mean(d * d)))
            row = {"particles": n * n, "self": self_c, "frames": frames, "blender_s": bw,
                   "ours_s": ow, "ratio": bw / ow, "ours_default_threads_s": tw,
                   "ratio_default_threads": bw / tw, "ours_all_cores_s": fw,
                   "ratio_all_cores": bw / fw, "substeps": sub, "error": err,
                   "ours_intersections": ok, "blender_intersections": bk,
                   "blender_finite": bfinite, "lowest": float(opos[-1, :, 2].min()),
                   "reference_lowest": float(rpos[-1, :, 2].min()), "fastest": ofast,
                   "reference_fastest": rfast}
            rows.append(row)
            print(f"| {n * n} | {'on' if self_c else 'off'} | {frames} | {1e3 * bw:.3g} | "
                  f"{1e3 * ow:.3g} | {bw / ow:.2f} | {1e3 * tw:.3g} | {bw / tw:.2f} | "
                  f"{1e3 * fw:.3g} | {bw / fw:.2f} | {sub} | "
                  f"{err:.2e} | "
                  f"{ok['cloth_cloth']}, {ok['cloth_collider']} | "
                  f"{bk['cloth_cloth']}, {bk['cloth_collider']} | {row['lowest']:.3f} / "
                  f"{row['reference_lowest']:.3f} | {ofast:.3g} / {rfast:.3g} |", flush=True)
    print()
    print("Our error is against our own reference (8x the substeps). The last two columns are "
          "there to judge the reference: a cloth draped over the sphere (radius 0.3 m, centre at "
          "0) ends with its lowest point below the equator (z < 0), and its corners whip at up "
          "to about three times the 3.4 m/s of a free fall from 0.6 m. A reference whose cloth "
          "ends above the sphere, or whose particles move several times faster than our run's, "
          "has gone wrong, and the error of that row measures the reference, not our default "
          "run.")
    print()
    print(f"Load average after: {' '.join(open('/proc/loadavg').read().split()[:3])}.")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
