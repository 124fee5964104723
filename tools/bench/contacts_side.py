"""The contact stage measured side by side in one run: this build, another
build of the library (the commit before the contact stage), and Blender's
cloth through bpy, on the scenes of tools/bench_contacts.c.

Run it with the Python that has bpy (4.5):

    /work/main/.venv-blender/bin/python tools/bench/contacts_side.py \\
        --build build --base ../wt-contacts-base/build [--reps 2] \\
        [--scenes thesis,sphere64+xpbd12,...] [--frames 24] [--sweep 2,5,10,20] [--json out.json]

A scene name takes flags after "+": wet (soaked), self (self-collision),
xpbd12 (both builds with XPBD at 12 steps per frame instead of each one's
default), carry (from the run's middle frame on the collider moves along x
at CARRY m/s, carrying the cloth that rests on it: bench_contacts carry=;
in Blender the collider object's location, set by a frame-change handler;
the base build does not run these).

Ours: build/tools/bench_contacts with this build's library, and the base
build's own tools/bench_contacts with its library (built from that commit,
so that the structs it passes have that library's layout; a base build
without the program runs this one against its library, through
LD_LIBRARY_PATH), each at its library's default integrator and steps,
alternated --reps times; figures are given as ranges over the repetitions. Collider
thickness 0.02 m (Blender's Collision modifier default, which the add-on
passes on), friction 0.5, 1 thread. This build also runs at the default
thread count (threads=0: every core, the world's adaptive count on, as a
user gets it), once per repetition, so that the figure a user sees stands
next to the 1-thread one (the base build and the references run on 1).

Blender: the same geometry (the collider from the same vertex arrays, the
cloth the same grid of quads), the Cloth modifier's defaults and quality 5,
Collision modifier thickness_outer 0.02, self-collision as ours; the
deforming cylinder gets its vertices every frame from a frame-change
handler, as ours gets them from wc_collider_set_vertices. Blender runs on
its own thread pool on the same cores.

Error (the project's protocol): RMS over particles and frames of the
distance to a reference of the same method, / the cloth's width. Ours:
against this build at 8x the default's steps per frame. Blender: quality q
against quality --reference-quality (40). "x Blender at equal error" divides
the time of the cheapest swept quality whose error is at most ours by our
time. Where none reached our error, Blender needs a quality above those
swept, which takes longer than the slowest swept one: its time divided by
ours is given as a lower bound ("more than").
"""
import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time

os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp(prefix="wc-bench-blender-"))

import numpy as np  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
FRAME = 1.0 / 24
CARRY = 0.5  # m/s, the +carry scenes' collider speed

# name: (cloth particles per side, width m, start height m, collider maker, deforming)
SCENES = {
    "thesis": (20, 1.0, 0.6, ("sphere", 16, 8, 0.3), False),
    "sphere64": (50, 1.0, 0.6, ("sphere", 64, 32, 0.3), False),
    "sphere176": (50, 1.0, 0.6, ("sphere", 176, 88, 0.3), False),
    "soaked": (50, 2.0, 1.0, ("sphere", 176, 88, 0.5), False),
    "cylinder": (33, 1.0, 0.35, ("tube", 96, 154, 0.15), True),
}


def uv_sphere(segments, rings, radius):
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


def tube(segments, rings, radius, length=1.2):
    j, i = np.meshgrid(np.arange(rings), np.arange(segments), indexing="ij")
    a = 2.0 * math.pi * i / segments
    v = np.stack([-0.5 * length + length * j / (rings - 1), radius * np.cos(a),
                  radius * np.sin(a)], axis=-1).reshape(-1, 3)
    t = []
    for jj in range(rings - 1):
        for ii in range(segments):
            p = jj * segments + ii
            q = jj * segments + (ii + 1) % segments
            t += [(p, q, p + segments), (q, q + segments, p + segments)]
    return v, np.array(t, np.int32)


def bent(rest, s):
    """bench_contacts.c's bend_tube: the tube's ends rise over the run."""
    ease = 0.5 - 0.5 * math.cos(math.pi * s)
    out = rest.copy()
    out[:, 2] += 0.25 * ease * (rest[:, 0] / 0.6) ** 2
    return out


def collider(spec):
    return uv_sphere(*spec[1:]) if spec[0] == "sphere" else tube(*spec[1:])


def grid(n, width, z):
    a = (np.arange(n) / (n - 1) - 0.5) * width
    x, y = np.meshgrid(a, a)
    v = np.c_[x.ravel(), y.ravel(), np.full(n * n, z)]
    q = [(j * n + i, j * n + i + 1, (j + 1) * n + i + 1, (j + 1) * n + i)
         for j in range(n - 1) for i in range(n - 1)]
    return v, q


# ---------------------------------------------------------------------------
# Ours


def ours(program, library, scene, frames, extra=(), out=None):
    env = dict(os.environ)
    if library:
        env["LD_LIBRARY_PATH"] = library
    cmd = [program, f"scene={scene}", f"frames={frames}"] + list(extra)
    if out:
        cmd.append(f"out={out}")
    r = subprocess.run(cmd, env=env, capture_output=True, text=True)
    line = r.stdout.strip().splitlines()[-1] if r.stdout.strip() else "{}"
    row = json.loads(line)
    row["rc"] = r.returncode
    if r.returncode not in (0, 3):
        raise SystemExit(f"{' '.join(cmd)} failed ({r.returncode}):\n{r.stderr[-2000:]}")
    return row


def base_library_dir(program, base):
    """A folder in which the base build's library answers to the name the
    program was linked against: the SONAME carries the minor version
    (libwetcloth.so.0.2), which the build before the contact stage does not
    have. The program uses only functions and struct fields that both have."""
    real = os.path.realpath(os.path.join(base, "libwetcloth.so"))
    needed = subprocess.run(["readelf", "-d", program], capture_output=True, text=True).stdout
    names = {"libwetcloth.so"} | {w.strip("[]") for w in needed.split() if w.startswith("[libwetcloth")}
    folder = tempfile.mkdtemp(prefix="wc-base-lib-")
    for name in names:
        os.symlink(real, os.path.join(folder, name))
    return folder


def base_runner(program, base):
    """The program and library folder for the base build: its own
    bench_contacts where it has one (built against its own header, so that
    the structs it passes have that library's layout: wc_material has grown
    since), else this build's program with the base's library."""
    own = os.path.join(base, "tools", "bench_contacts")
    if os.path.isfile(own):
        return own, os.path.abspath(base)
    return program, base_library_dir(program, base)


def read_positions(path, n):
    a = np.fromfile(path, dtype=np.float64)
    return a.reshape(-1, n, 3)


def rms(a, b, width):
    f = min(len(a), len(b))
    d = np.linalg.norm(a[:f] - b[:f], axis=2)
    return float(np.sqrt(np.mean(d * d))) / width


# ---------------------------------------------------------------------------
# Blender


def carried(frame_index, frames, speed):
    """bench_contacts.c's carry: the collider's shift along x before the
    advance from frame `frame_index` (0-based) to the next."""
    k = frame_index + 1 - frames // 2
    return speed * k / 24.0 if k > 0 else 0.0


def blender_run(scene, frames, quality, self_collision, thickness=0.02, carry=0.0):
    import bpy
    n, width, height, spec, deforming = SCENES[scene]
    bpy.ops.wm.read_homefile(use_empty=True)
    sc = bpy.context.scene
    sc.render.fps = 24
    sc.frame_start = 1
    sc.frame_end = frames + 1
    cv, ct = collider(spec)
    me = bpy.data.meshes.new("collider")
    me.from_pydata(cv.tolist(), [], ct.tolist())
    me.update()
    ob = bpy.data.objects.new("collider", me)
    sc.collection.objects.link(ob)
    ob.modifiers.new("Collision", "COLLISION")
    ob.collision.thickness_outer = thickness
    v, q = grid(n, width, height)
    cm = bpy.data.meshes.new("cloth")
    cm.from_pydata(v.tolist(), [], q)
    cm.update()
    cloth = bpy.data.objects.new("cloth", cm)
    sc.collection.objects.link(cloth)
    mod = cloth.modifiers.new("Cloth", "CLOTH")
    mod.settings.quality = quality
    mod.collision_settings.use_self_collision = self_collision
    mod.point_cache.frame_start = 1
    mod.point_cache.frame_end = frames + 1
    handler = None
    if deforming or carry:
        def handler(s, depsgraph=None):
            f = s.frame_current
            if deforming:
                pos = bent(cv, min(1.0, max(0.0, (f - 1) / frames)))
                me.vertices.foreach_set("co", pos.ravel())
                me.update()
            # frame f ends our advance from frame index f - 2
            ob.location.x = carried(f - 2, frames, carry) if f >= 2 else 0.0
        bpy.app.handlers.frame_change_pre.append(handler)
    sc.frame_set(1)
    out = np.empty((frames, n * n, 3))
    buf = np.empty(3 * n * n)
    wall = 0.0
    for f in range(2, frames + 2):
        t0 = time.perf_counter()
        sc.frame_set(f)
        dg = bpy.context.evaluated_depsgraph_get()
        ev = cloth.evaluated_get(dg)
        m = ev.to_mesh()
        wall += time.perf_counter() - t0
        m.vertices.foreach_get("co", buf)
        ev.to_mesh_clear()
        out[f - 2] = buf.reshape(-1, 3)
    if handler:
        bpy.app.handlers.frame_change_pre.remove(handler)
    bpy.ops.wm.read_homefile(use_empty=True)
    return wall / frames, out


def stability(pos, height, links):
    """Highest particle after the first frame below the start height by more
    than 1 mm (landing), and the longest link over the run / rest."""
    a, b = links[:, 0], links[:, 1]
    rest = np.linalg.norm(pos[0, a] - pos[0, b], axis=1)  # frame 1: nearly flat
    longest = max(float((np.linalg.norm(p[a] - p[b], axis=1) / rest).max()) for p in pos)
    return float(pos[:, :, 2].max()), longest


def grid_links(n):
    idx = np.arange(n * n).reshape(n, n)
    return np.concatenate([np.c_[idx[:, :-1].ravel(), idx[:, 1:].ravel()],
                           np.c_[idx[:-1, :].ravel(), idx[1:, :].ravel()]])


# ---------------------------------------------------------------------------


def span(values, fmt="{:.3g}"):
    values = [v for v in values if v is not None]
    if not values:
        return "-"
    lo, hi = min(values), max(values)
    return fmt.format(lo) if lo == hi else (fmt.format(lo) + "-" + fmt.format(hi))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build")
    ap.add_argument("--base", help="build folder of the commit before (its libwetcloth.so)")
    ap.add_argument("--scenes", default="thesis,thesis+self,sphere64,sphere64+xpbd12,sphere176,"
                                        "sphere176+xpbd12,soaked,soaked+wet,cylinder,cylinder+wet,"
                                        "sphere64+carry,sphere176+carry")
    ap.add_argument("--frames", type=int, default=24)
    ap.add_argument("--reps", type=int, default=2)
    ap.add_argument("--sweep", default="2,5,10,20", help="Blender qualities for the error sweep")
    ap.add_argument("--reference-quality", type=int, default=40)
    ap.add_argument("--no-blender", action="store_true")
    ap.add_argument("--no-error", action="store_true", help="skip our 8x reference runs")
    ap.add_argument("--base-frames", type=int, help="frames for the base build (slow scenes)")
    ap.add_argument("--json")
    a = ap.parse_args()
    program = os.path.join(a.build, "tools", "bench_contacts")
    build_lib = os.path.abspath(a.build)
    base_program, base_lib = base_runner(program, a.base) if a.base else (None, None)
    sweep = [int(q) for q in a.sweep.split(",") if q]
    tmp = tempfile.mkdtemp(prefix="wc-contacts-")
    print(f"load average before: {' '.join(open('/proc/loadavg').read().split()[:3])}")
    rows = []
    blender_cache = {}
    for item in a.scenes.split(","):
        scene, *flags = item.split("+")
        wet, self_c = int("wet" in flags), int("self" in flags)
        carry = CARRY if "carry" in flags else 0.0
        n, width, height, spec, deforming = SCENES[scene]
        extra = [f"wet={wet}", f"self={self_c}", "thickness=0.02", "friction=0.5", "threads=1"]
        # +xpbd12: both builds at the same setting (XPBD, 12 steps per frame),
        # so that the collision cost compares like with like
        if "xpbd12" in flags:
            extra += ["integrator=xpbd", "steps=12"]
        if carry:
            extra.append(f"carry={carry}")
        new_runs, base_runs, default_runs = [], [], []
        for rep in range(a.reps):
            if base_lib and not carry:
                bf = a.base_frames or a.frames
                base_runs.append(ours(base_program, base_lib, scene, bf, extra))
            new_runs.append(ours(program, build_lib, scene, a.frames, extra,
                                 out=os.path.join(tmp, "new.bin") if rep == 0 else None))
            default_runs.append(ours(program, build_lib, scene, a.frames,
                                     [e for e in extra if not e.startswith("threads=")] + ["threads=0"]))
        err = None
        if not a.no_error:
            steps = int(round(new_runs[0]["substeps_per_frame"]))
            ref = ours(program, build_lib, scene, a.frames, extra + [f"steps={8 * steps}"],
                       out=os.path.join(tmp, "ref.bin"))
            # the reference must be the same method: with the default integrator the
            # library's choice per cloth does not depend on the step count
            err = rms(read_positions(os.path.join(tmp, "new.bin"), n * n),
                      read_positions(os.path.join(tmp, "ref.bin"), n * n), width)
            ref_ok = ref["finite"]
        row = {"scene": item, "ours": new_runs, "base": base_runs, "default_threads": default_runs,
               "error": err}
        if not a.no_blender:
            key = (scene, self_c, carry)
            if key not in blender_cache:
                b5 = [blender_run(scene, a.frames, 5, bool(self_c), carry=carry) for _ in range(max(1, a.reps))]
                qs = {}
                if sweep:
                    ref_wall, ref_pos = blender_run(scene, a.frames, a.reference_quality, bool(self_c),
                                                    carry=carry)
                    for q in sweep:
                        w_, p_ = (b5[0] if q == 5 else blender_run(scene, a.frames, q, bool(self_c), carry=carry))
                        qs[q] = (w_, rms(p_, ref_pos, width))
                hi, longest = stability(b5[0][1], height, grid_links(n))
                blender_cache[key] = {"q5_s": [b[0] for b in b5], "sweep": qs,
                                      "highest": hi, "longest": longest}
            row["blender"] = blender_cache[key]
        rows.append(row)
        ms = [r["ms_per_frame"] for r in new_runs]
        line = (f"{item}: ours {span(ms)} ms/frame (collide {span([r['collide_ms_per_frame'] for r in new_runs])}), "
                f"{new_runs[0]['substeps_per_frame']:.3g} steps/frame, error {err if err is None else f'{err:.2e}'}, "
                f"intersections {new_runs[0]['intersections_last']}, highest {new_runs[0]['highest_after_landing']:.3f}"
                f"/{new_runs[0]['start_height']:.3f}, longest link {new_runs[0]['longest_link']:.3f}; "
                f"default threads {span([r['ms_per_frame'] for r in default_runs])} ms/frame")
        if base_runs:
            line += (f"; base {span([r['ms_per_frame'] for r in base_runs])} ms/frame (collide "
                     f"{span([r['collide_ms_per_frame'] for r in base_runs])}), {base_runs[0]['substeps_per_frame']:.3g} "
                     f"steps, intersections {base_runs[0]['intersections_last']}, longest link "
                     f"{base_runs[0]['longest_link']:.3f}")
        if "blender" in row:
            b = row["blender"]
            line += f"; Blender q5 {span([1e3 * s for s in b['q5_s']])} ms/frame"
            if b["sweep"]:
                line += " sweep " + ", ".join(f"q{q} {1e3 * w:.3g} ms {e:.2e}" for q, (w, e) in b["sweep"].items())
        print(line, flush=True)
    print()
    print("| scene | ours ms/frame | ours collide ms | steps/frame | our error | before ms/frame "
          "| before collide ms | collide before / ours | Blender q5 ms | Blender q5 / ours "
          "| Blender at equal error / ours | ours ms/frame, default threads "
          "| Blender q5 / ours, default threads | intersections ours, before | highest / start, ours "
          "| longest link ours, before, Blender |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for row in rows:
        o, b = row["ours"], row["base"]
        oms = [r["ms_per_frame"] for r in o]
        ocol = [r["collide_ms_per_frame"] for r in o]
        bms = [r["ms_per_frame"] for r in b]
        bcol = [r["collide_ms_per_frame"] for r in b]
        ratio_collide = span([x / y for x in bcol for y in ocol], "{:.2f}") if b else "-"
        bl = row.get("blender")
        q5 = span([1e3 * s for s in bl["q5_s"]]) if bl else "-"
        q5r = span([1e3 * s / y for s in bl["q5_s"] for y in oms], "{:.2f}") if bl else "-"
        dms = [r["ms_per_frame"] for r in row["default_threads"]]
        q5d = span([1e3 * s / y for s in bl["q5_s"] for y in dms], "{:.2f}") if bl else "-"
        eq = "-"
        if bl and bl["sweep"] and row["error"] is not None:
            ok = [(w, q) for q, (w, e) in bl["sweep"].items() if e <= row["error"]]
            if ok:
                w, q = min(ok)
                eq = span([1e3 * w / y for y in oms], "{:.2f}") + f" (q{q})"
            else:
                # every swept quality is less accurate than ours: the one that
                # comes nearest bounds Blender's time at equal error from below
                # (a higher quality takes longer)
                w_top, q_top = max((w, q) for q, (w, _) in bl["sweep"].items())
                eq = (f"more than {span([1e3 * w_top / y for y in oms], '{:.2f}')} (q{q_top}, the "
                      f"slowest swept, {bl['sweep'][q_top][1]:.2e}: no swept quality reached ours)")
        error_text = "-" if row["error"] is None else f"{row['error']:.2e}"
        print(f"| {row['scene']} | {span(oms)} | {span(ocol)} | {o[0]['substeps_per_frame']:.3g} | "
              f"{error_text} | "
              f"{span(bms)} | {span(bcol)} | {ratio_collide} | {q5} | {q5r} | {eq} | {span(dms)} | {q5d} | "
              f"{o[0]['intersections_last']}, {b[0]['intersections_last'] if b else '-'} | "
              f"{o[0]['highest_after_landing']:.3f} / {o[0]['start_height']:.3f} | "
              f"{o[0]['longest_link']:.2f}, {format(b[0]['longest_link'], '.2f') if b else '-'}, "
              f"{format(bl['longest'], '.2f') if bl else '-'} |")
    print()
    print(f"load average after: {' '.join(open('/proc/loadavg').read().split()[:3])}")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(rows, f, indent=1, default=float)


if __name__ == "__main__":
    main()
