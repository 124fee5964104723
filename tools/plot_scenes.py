#!/usr/bin/env python3
"""Draws the thesis' wet-cloth scenes into docs/images/ (docs/wetness.md shows them).

    .venv/bin/python tools/plot_scenes.py [--build BUILD_DIR] [--out docs/images]

Runs BUILD_DIR/tools/wet_scenes (default build/) into a temporary folder and
plots what it wrote: every figure is a state the library computed in this
run, drawn as it is (wire grid of the cloth, stuck particles in blue).
"""
import argparse
import csv
import os
import subprocess
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

STUCK = "#1f5fbf"
FREE = "#999999"


def load(folder, name):
    with open(os.path.join(folder, name), newline="") as f:
        rows = list(csv.DictReader(f))
    xyz = np.array([[float(r["x"]), float(r["y"]), float(r["z"])] for r in rows])
    stuck = np.array([int(r["stuck"]) for r in rows], dtype=bool)
    return xyz, stuck


def wire(ax, xyz, nu, nv, a, b, color="#444444"):
    """Grid lines of an nu x nv cloth projected on axes a, b."""
    g = xyz.reshape(nv, nu, 3)
    for j in range(nv):
        ax.plot(g[j, :, a], g[j, :, b], color=color, lw=0.6)
    for i in range(nu):
        ax.plot(g[:, i, a], g[:, i, b], color=color, lw=0.6)


def dots(ax, xyz, stuck, a, b, size=8):
    ax.scatter(xyz[~stuck, a], xyz[~stuck, b], s=size, c=FREE, zorder=3, label="free")
    ax.scatter(xyz[stuck, a], xyz[stuck, b], s=size, c=STUCK, zorder=4, label="stuck")


def wrap(folder, out):
    fig = plt.figure(figsize=(9, 5))
    u, v = np.meshgrid(np.linspace(0, 2 * np.pi, 17), np.linspace(0, np.pi, 9))
    for k, name in enumerate(["dry", "wet"]):
        ax = fig.add_subplot(1, 2, k + 1, projection="3d")
        xyz, stuck = load(folder, f"wrap_{name}.csv")
        # the faceted sphere: 16 segments x 8 rings, as the collider
        ax.plot_surface(0.3 * np.sin(v) * np.cos(u), 0.3 * np.sin(v) * np.sin(u), 0.3 * np.cos(v),
                        color="#e8d9b0", linewidth=0, shade=True, alpha=0.9)
        g = xyz.reshape(20, 20, 3)
        ax.plot_wireframe(g[:, :, 0], g[:, :, 1], g[:, :, 2], color="#444444", linewidth=0.5)
        ax.scatter(xyz[stuck, 0], xyz[stuck, 1], xyz[stuck, 2], s=5, c=STUCK, depthshade=False)
        ax.view_init(elev=12, azim=-60)
        ax.set_box_aspect((1, 1, 1))
        for setter in (ax.set_xlim, ax.set_ylim):
            setter(-0.33, 0.33)
        ax.set_zlim(-0.36, 0.3)
        ax.set_axis_off()
        ax.set_title(f"{name}: {int(stuck.sum())} of 400 stuck (blue)", fontsize=10)
    fig.suptitle("Wrap (thesis Fig. 3.2-3.4): 20 x 20 cotton cloth dropped on the 114-vertex sphere, after 2 s;\n"
                 "the dry cloth's edges hang straight down from the equator, the wet ones tuck under it",
                 fontsize=10)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "wrap.png"), dpi=110)
    plt.close(fig)


def spreading(folder, out):
    with open(os.path.join(folder, "spreading.csv"), newline="") as f:
        rows = list(csv.reader(f))
    header, data = rows[0], np.array(rows[1:], dtype=float)
    fig, axes = plt.subplots(1, 4, figsize=(13, 3.6), gridspec_kw={"width_ratios": [1.6, 1, 1, 1]})
    ax = axes[0]
    for k in range(1, len(header)):
        ax.plot(data[:, 0] / 24, data[:, k], label=header[k])
    ax.set_xlabel("time (s)")
    ax.set_ylabel("stuck particles (of 441)")
    ax.legend(fontsize=7)
    ax.set_title("stuck count over time")
    for ax, frame in zip(axes[1:], (6, 24, 72)):
        xyz, stuck = load(folder, f"spreading_{frame}.csv")
        wire(ax, xyz, 21, 21, 0, 1, "#cccccc")
        dots(ax, xyz, stuck, 0, 1, 6)
        ax.add_patch(plt.Circle((0, 0), 0.3, fill=False, ls="--", color="#b08a30"))
        ax.set_aspect("equal")
        ax.set_title(f"t = {frame / 24:.2f} s: {int(stuck.sum())} stuck", fontsize=9)
        ax.set_xticks([])
        ax.set_yticks([])
    fig.suptitle("Spreading (thesis Fig. 3.5): no gravity, a flat cloth touching a smooth sphere at its centre; "
                 "top views of the 40 Pa / 5e-2 N m run", fontsize=10)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "spreading.png"), dpi=110)
    plt.close(fig)


def slack(folder, out):
    alpha = np.radians(20.0)
    # coordinates in the wall: x across, s up along the wall
    fig, axes = plt.subplots(1, 2, figsize=(9, 4.4), sharey=True)
    for ax, name in zip(axes, ["dry", "wet"]):
        for when, color in (("before", "#bbbbbb"), ("after", "#333333")):
            xyz, stuck = load(folder, f"slack_{name}_{when}.csv")
            s = -xyz[:, 1] * np.sin(alpha) + xyz[:, 2] * np.cos(alpha)
            flat = np.column_stack([xyz[:, 0], s, xyz[:, 2]])
            wire(ax, flat, 16, 16, 0, 1, color)
            if when == "after":
                dots(ax, flat, stuck, 0, 1, 8)
        ax.set_aspect("equal")
        ax.set_title(f"{name}: grey before, black after", fontsize=10)
        ax.set_xlabel("x (m)")
    axes[0].set_ylabel("up the wall (m)")
    axes[1].legend(loc="upper left", fontsize=8)
    fig.suptitle("Slack (thesis Fig. 3.6): the pinned top row moves 0.15 m sideways; the stuck wet lower part\n"
                 "stays and the cloth shears above it, the dry cloth slides along (seen facing the wall)", fontsize=10)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "slack.png"), dpi=110)
    plt.close(fig)


def side_by_side(folder, out, stem, nu, nv, title, filename, ylim):
    fig, axes = plt.subplots(2, 1, figsize=(9, 4.6), sharex=True)
    for ax, name in zip(axes, ["dry", "wet"]):
        xyz, stuck = load(folder, f"{stem}_{name}.csv")
        g = xyz.reshape(nv, nu, 3)
        ax.plot(g[nv // 2, :, 0], g[nv // 2, :, 2], color="#444444", lw=0.8)
        dots(ax, g[nv // 2], stuck.reshape(nv, nu)[nv // 2], 0, 2, 14)
        ax.axhline(0.0, color="#b08a30", lw=1)
        ax.set_ylim(*ylim)
        ax.set_aspect("equal")
        ax.set_ylabel(f"{name}\nz (m)")
    axes[1].set_xlabel("x (m)")
    axes[1].legend(loc="upper right", fontsize=8)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(os.path.join(out, filename), dpi=110)
    plt.close(fig)


def main():
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--build", default=os.path.join(root, "build"))
    p.add_argument("--out", default=os.path.join(root, "docs", "images"))
    args = p.parse_args()
    exe = os.path.join(args.build, "tools", "wet_scenes")
    if not os.access(exe, os.X_OK):
        sys.exit(f"plot_scenes: {exe} not found; build it first (cmake --build {args.build} --target wet_scenes)")
    os.makedirs(args.out, exist_ok=True)
    with tempfile.TemporaryDirectory() as folder:
        subprocess.run([exe, folder], check=True)
        wrap(folder, args.out)
        spreading(folder, args.out)
        slack(folder, args.out)
        side_by_side(folder, args.out, "fold", 21, 5,
                     "Fold (thesis Fig. 3.7): the two floor plates slide 0.1 m together under a stiff strip "
                     "(bending 5e-2 N m);\nthe wet ends ride with them and the surplus rises, the dry strip "
                     "slips and stays flat (middle row, side view)", "fold.png", (-0.02, 0.25))
        side_by_side(folder, args.out, "self", 21, 5,
                     "Self-adhesion: a strip folded onto itself, lower half pinned, pulled up by 1 g for 0.5 s;\n"
                     "the wet layers stay together, the dry upper layer lifts off (middle row, side view)",
                     "self_adhesion.png", (-0.02, 0.25))
    print(f"wrote wrap.png, spreading.png, slack.png, fold.png, self_adhesion.png to {args.out}")


if __name__ == "__main__":
    main()
