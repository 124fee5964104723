"""Fuzz target for the scene-file loader: wetcloth.scene.load and
wetcloth.scene.build may raise SceneError, with a non-empty message, and
nothing else, whatever the file holds.

Each input is one of three kinds (its first byte picks):
  * raw bytes as the scene file (broken JSON, bad UTF-8, any value);
  * a valid base scene (grid and OBJ cloths, every collider type,
    keyframes, pins, a wetness map) with values replaced at fuzzed paths by
    fuzzed JSON values: wrong types, NaN, infinities, huge and negative
    numbers, booleans for numbers, empty and nested containers, strings;
  * the base scene with the OBJ files (cloth and collider) replaced by
    fuzzed text (faces out of range, negative and zero indices, missing
    coordinates, 'nan', quads and polygons).
A scene that loads is also built into a World (the library's own checks
then answer through SceneError), unless it is large (more than 20000
particles or 4096 collider vertices), which would only be slow.

Run with atheris (libFuzzer's flags: -max_total_time=S, -runs=N, corpus
folders) when it is installed; without it, the same harness runs on
seeded random mutations of the corpus for -max_total_time seconds.
"""

import json
import math
import os
import random
import sys
import tempfile
import time

scene_mod = None  # wetcloth.scene, imported in main() (under atheris: instrumented)

TMP = tempfile.mkdtemp(prefix="wetcloth-fuzz-scene-")
SCENE = os.path.join(TMP, "scene.json")
CLOTH_OBJ = os.path.join(TMP, "cloth.obj")
COLLIDER_OBJ = os.path.join(TMP, "floor.obj")

GOOD_CLOTH_OBJ = "v 0 0 0.5\nv 0.3 0 0.5\nv 0.3 0.3 0.5\nv 0 0.3 0.5\nv 0.15 0.45 0.5\nf 1 2 3 4\nf 4 3 5\n"
GOOD_COLLIDER_OBJ = "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3\nf 1 3 4\n"

BASE = {
    "description": "fuzz base",
    "duration": 0.1,
    "fps": 24,
    "substeps": 2,
    "gravity": [0, 0, -9.81],
    "integrator": "verlet",
    "cloths": [
        {"name": "sheet",
         "grid": {"nu": 4, "nv": 3, "size": [0.5, 0.4], "center": [0, 0, 0.6],
                  "axis_u": [1, 0, 0], "axis_v": [0, 1, 0]},
         "material": {"density": 0.15, "stretch": 1000, "bend": 1e-5, "adhesion": 40,
                      "wicking": 0.01, "drying": 0.1},
         "wetness": [1, 0, 0.5, 1, 0, 0.5, 1, 0, 0.5, 1, 0, 0.5],
         "pins": [0, 3],
         "pin_keyframes": [{"time": 0, "translate": [0, 0, 0]},
                           {"time": 1, "translate": [0, 0, 0.3]}],
         "self_collision": True},
        {"name": "patch", "obj": "cloth.obj", "wetness": 0.5},
    ],
    "colliders": [
        {"type": "sphere", "center": [0, 0, 0], "radius": 0.3,
         "keyframes": [{"time": 0, "translate": [0, 0, 0]}, {"time": 2, "translate": [0, 0.1, 0]}]},
        {"type": "box", "center": [0.5, 0, 0], "half_extents": [0.1, 0.1, 0.1],
         "rotation": [1, 0, 0, 0], "thickness": 0.01, "friction": 0.5},
        {"type": "capsule", "a": [0, 0.5, 0], "b": [0, 0.7, 0], "radius": 0.05},
        {"type": "convex", "points": [[0, 0, 0], [0.1, 0, 0], [0, 0.1, 0], [0, 0, 0.1]]},
        {"type": "mesh", "obj": "floor.obj", "name": "floor"},
        {"type": "mesh", "vertices": [[0, 0, -1], [1, 0, -1], [0, 1, -1]], "triangles": [[0, 1, 2]]},
    ],
}

AWKWARD = [None, True, False, 0, -1, 1, 2, 3, 2 ** 31, -2 ** 31, 2 ** 63, 10 ** 400, 0.5, -0.5,
           1e308, -1e308, 1e-320, float("nan"), float("inf"), float("-inf"), "", "8", "x" * 300,
           "nan", "verlet", "mesh", "sphere", "cloth.obj", "../../etc/passwd", "/", "/dev/zero",
           "\u00e9\x00", "a\x00.obj", "\ud800",
           [], {}, [0], [0, 0], [0, 0, 0], [0, 0, 0, 0], [[0, 0, 0]], [1e308, 1e308, 1e308],
           [float("nan")] * 3, {"nu": 2}, {"time": 0}, [[]], [{}], [None]]

OBJ_LINES = ["v 0 0 0", "v 1 0 0", "v 0 1 0", "v 1 1 nan", "v inf 0 0", "v 1e308 1e308 0", "v 1",
             "v", "v a b c", "f 1 2 3", "f 1 2 3 4", "f 1 2 3 4 5 6", "f 1 1 1", "f 0 1 2",
             "f -1 -2 -3", "f 1 2 99", "f 1/1/1 2/2/2 3/3/3", "f 1//1 2//2 3//3", "f", "f 1 2",
             "f 2147483648 1 2", "vt 0 0", "vn 0 0 1", "# comment", "o thing", "g group", "s off",
             "usemtl x", "", "\t", "f 1 2 3\\", "v 0 0 0 1", "l 1 2"]


class Budget(Exception):
    pass


def particles(scene):
    total = 0
    for c in scene.cloths:
        g = c.get("grid") if isinstance(c, dict) else None
        if g:
            total += int(g.get("nu", 0)) * int(g.get("nv", 0))
        else:
            v = c.get("vertices") if isinstance(c, dict) else None
            total += len(v) if v is not None else 0
    return total


def collider_vertices(scene):
    total = 0
    for c in scene.colliders:
        v = c.get("vertices") if isinstance(c, dict) else None
        total += len(v) if v is not None else 0
    return total


def check(text_bytes, cloth_obj, collider_obj):
    with open(SCENE, "wb") as f:
        f.write(text_bytes)
    with open(CLOTH_OBJ, "w", encoding="utf-8", errors="surrogatepass") as f:
        f.write(cloth_obj)
    with open(COLLIDER_OBJ, "w", encoding="utf-8", errors="surrogatepass") as f:
        f.write(collider_obj)
    try:
        s = scene_mod.load(SCENE)
        try:
            big = particles(s) > 20000 or collider_vertices(s) > 4096
        except (TypeError, ValueError, AttributeError, OverflowError):
            big = False
        if not big:
            built = scene_mod.build(s, threads=1)
            built.set_targets(0.05)
    except scene_mod.SceneError as e:
        if not str(e).strip() or not e.message:
            raise AssertionError("SceneError without a message") from e


def mutate_value(value, pick):
    """Replaces one value somewhere in a JSON tree (pick(n) gives 0..n-1)."""
    if isinstance(value, dict) and value and pick(4):
        keys = sorted(value)
        k = keys[pick(len(keys))]
        value = dict(value)
        if pick(8) == 0:
            del value[k]
        else:
            value[k] = mutate_value(value[k], pick)
        return value
    if isinstance(value, list) and value and pick(4):
        i = pick(len(value))
        value = list(value)
        if pick(8) == 0:
            del value[i]
        elif pick(8) == 0:
            value.append(value[i])
        else:
            value[i] = mutate_value(value[i], pick)
        return value
    if pick(6) == 0 and isinstance(value, (int, float)) and not isinstance(value, bool):
        factor = [-1, 2, 1000, 1e-6, 0.5][pick(5)]
        try:
            return value * factor
        except OverflowError:
            return -value
    if pick(10) == 0:
        return {"unknown_field": 1}
    return AWKWARD[pick(len(AWKWARD))]


def dumps(data):
    try:
        return json.dumps(data, allow_nan=True).encode("utf-8", "surrogatepass")
    except (ValueError, OverflowError):
        return b"{}"


def one_input(data, pick):
    kind = data[0] % 3 if data else 1
    if kind == 0:
        check(bytes(data[1:]), GOOD_CLOTH_OBJ, GOOD_COLLIDER_OBJ)
    elif kind == 1:
        scene = BASE
        for _ in range(1 + pick(4)):
            scene = mutate_value(scene, pick)
        check(dumps(scene), GOOD_CLOTH_OBJ, GOOD_COLLIDER_OBJ)
    else:
        lines = [OBJ_LINES[pick(len(OBJ_LINES))] for _ in range(pick(12))]
        text = "\n".join(lines)
        if pick(2):
            check(dumps(BASE), text, GOOD_COLLIDER_OBJ)
        else:
            check(dumps(BASE), GOOD_CLOTH_OBJ, text)


def picker_from(data):
    """pick(n) from the input's bytes after the first (zeros when they run out)."""
    state = {"at": 1}

    def pick(n):
        if n <= 1:
            return 0
        at = state["at"]
        if at + 2 > len(data):
            return 0
        state["at"] = at + 2
        return (data[at] | data[at + 1] << 8) % n
    return pick


def test_one_input(data):
    one_input(data, picker_from(data))


def fallback(argv):
    """Random mutation without atheris: -max_total_time=S and -runs=N are
    honoured, corpus folders are read as seeds."""
    seconds, runs = 20.0, None
    seeds = []
    for a in argv:
        if a.startswith("-max_total_time="):
            seconds = float(a.split("=", 1)[1])
        elif a.startswith("-runs="):
            runs = int(a.split("=", 1)[1])
        elif not a.startswith("-") and os.path.isdir(a):
            for name in sorted(os.listdir(a)):
                with open(os.path.join(a, name), "rb") as f:
                    seeds.append(f.read())
    seeds = seeds or [b"\x01"]
    rng = random.Random(12345)
    end = time.time() + seconds
    n = 0
    while time.time() < end and (runs is None or n < runs):
        data = bytearray(rng.choice(seeds))
        for _ in range(rng.randrange(1, 8)):
            op = rng.randrange(3)
            if op == 0 or not data:
                data.insert(rng.randrange(len(data) + 1), rng.randrange(256))
            elif op == 1:
                data[rng.randrange(len(data))] = rng.randrange(256)
            elif len(data) > 1:
                del data[rng.randrange(len(data))]
        test_one_input(bytes(data))
        n += 1
    print("fuzz_scene (no atheris: random mutations): %d runs in %.0f s, 0 failures" %
          (n, seconds))


def main():
    global scene_mod
    try:
        import atheris
    except ImportError:
        from wetcloth import scene as scene_mod
        fallback(sys.argv[1:])
        return
    with atheris.instrument_imports(include=["wetcloth"]):
        from wetcloth import scene as scene_mod
    atheris.Setup(sys.argv, test_one_input)
    atheris.Fuzz()


if __name__ == "__main__":
    main()
