"""Command line: python -m wetcloth run SCENE.json --out DIR | demo --out DIR.

Exit status: 0 done; 2 bad scene file or arguments (nothing written);
1 the simulation or writing the output failed (nothing written).
"""

import argparse
import os
import sys

from . import __version__, demo, scene


def _parser():
    p = argparse.ArgumentParser(
        prog="python -m wetcloth",
        description="Runs libwetcloth scenes. Writes, into the output folder: <cloth>.pc2 "
                    "(point cache of every frame, the start included), <cloth>.obj (last "
                    "frame), stats.json and preview.png.")
    p.add_argument("--version", action="version", version="wetcloth " + __version__)
    sub = p.add_subparsers(dest="command", required=True)

    def common(sp):
        sp.add_argument("--out", required=True, metavar="DIR",
                        help="output folder (created; files in it with the same names "
                             "are replaced when the run succeeds)")
        sp.add_argument("--threads", type=int, default=None, metavar="N",
                        help="OpenMP threads (default: the scene's 'threads', 0 = OpenMP's "
                             "default)")
        sp.add_argument("--frames", type=int, default=None, metavar="N",
                        help="simulate only the first N frames")
        sp.add_argument("--check", choices=("every", "final", "none"), default="every",
                        help="when to count intersections with the independent checker "
                             "(default: every frame)")
        sp.add_argument("--no-progress", action="store_true", help="no progress bar")

    run = sub.add_parser("run", help="run a scene file (docs/scenes.md)")
    run.add_argument("scene", metavar="SCENE.json")
    common(run)
    d = sub.add_parser("demo", help="run the built-in wet-versus-dry thesis scene")
    common(d)
    return p


def main(argv=None):
    args = _parser().parse_args(argv)
    if args.frames is not None and args.frames < 1:
        _parser().error("--frames must be at least 1")
    if args.threads is not None and args.threads < 0:
        _parser().error("--threads must be at least 0")
    try:
        if args.command == "demo":
            s = scene.from_dict(demo.scene_dict(), "demo", os.getcwd())
        else:
            s = scene.load(args.scene)
        stats = scene.run(s, args.out, progress=not args.no_progress, check=args.check,
                          threads=args.threads, frames=args.frames)
    except scene.SceneError as e:
        print("wetcloth: error: %s" % e, file=sys.stderr)
        return 2
    except scene.RunError as e:
        print("wetcloth: error: the simulation failed at %s" % e, file=sys.stderr)
        return 1
    except OSError as e:
        print("wetcloth: error: cannot write the output: %s" % e, file=sys.stderr)
        return 1
    stuck = ", ".join("%s %d/%d stuck" % (c["name"], c["stuck_final"], c["particles"])
                      for c in stats["cloths"])
    inter = stats["intersections"]
    print("wetcloth: %d frames, %d steps in %.2f s (%.1f ms/frame); %s; intersections: %s; "
          "wrote %s" % (stats["frames"], stats["steps"], stats["seconds"]["simulation"],
                        1e3 * stats["seconds"]["simulation_per_frame_mean"], stuck,
                        "not checked" if inter["checked"] == "none" else
                        "%d of %d frames" % (inter["frames_with_intersections"],
                                             inter["frames_checked"]),
                        os.path.abspath(args.out)))
    return 0
