"""Preview image of a scene's current state (matplotlib, no display needed):
the cloths over the colliders, coloured by state: dry grey, wet blue (the
darker, the wetter), stuck orange."""

import math

import numpy as np

DRY = np.array([0.80, 0.80, 0.78])
WET = np.array([0.12, 0.35, 0.80])
STUCK = np.array([0.95, 0.50, 0.10])
COLLIDER = (0.45, 0.45, 0.45, 0.25)


def _sphere(center, radius, n=16):
    u, v = np.meshgrid(np.linspace(0, 2 * math.pi, 2 * n + 1), np.linspace(0, math.pi, n + 1))
    xyz = np.stack([np.cos(u) * np.sin(v), np.sin(u) * np.sin(v), np.cos(v)], -1) * radius
    return _grid_quads(xyz + center)


def _grid_quads(xyz):
    a = xyz[:-1, :-1]
    b = xyz[:-1, 1:]
    c = xyz[1:, 1:]
    d = xyz[1:, :-1]
    return np.stack([a, b, c, d], axis=2).reshape(-1, 4, 3)


def _rotate(q, p):
    w, x, y, z = np.asarray(q, dtype=float) / np.linalg.norm(q)
    r = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                  [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                  [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
    return p @ r.T


def _box(center, half, rotation):
    corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)],
                       dtype=float) * half
    faces = [[0, 1, 3, 2], [4, 5, 7, 6], [0, 1, 5, 4], [2, 3, 7, 6], [0, 2, 6, 4],
             [1, 3, 7, 5]]
    p = _rotate(rotation, corners) + center
    return p[np.array(faces)]


def _capsule(position, rotation, radius, half_height, n=16):
    u, v = np.meshgrid(np.linspace(0, 2 * math.pi, 2 * n + 1), np.linspace(0, math.pi, n + 1))
    xyz = np.stack([np.cos(u) * np.sin(v), np.sin(u) * np.sin(v), np.cos(v)], -1) * radius
    xyz[..., 2] += np.where(xyz[..., 2] >= 0, half_height, -half_height)
    return _grid_quads(_rotate(rotation, xyz.reshape(-1, 3)).reshape(xyz.shape) + position)


def collider_polygons(col):
    """Polygons (k, m, 3) that draw a collider as it is now."""
    if col.kind == "mesh":
        return col.vertices[col.triangles]
    p = col.params
    if col.kind == "sphere":
        return _sphere(col.position, p["radius"])
    if col.kind == "box":
        return _box(col.position, np.array(p["half_extents"]), col.rotation)
    if col.kind == "capsule":
        return _capsule(col.position, col.rotation, p["radius"], p["half_height"])
    return None  # a hull: drawn as its points


def face_colours(wetness, stuck, faces):
    """RGB per face: stuck when most of its particles are stuck, else dry
    to wet by its mean wetness."""
    idx = np.where(faces >= 0, faces, faces[:, :1])
    w = wetness[idx].mean(axis=1)
    s = stuck[idx].mean(axis=1) > 0.5
    rgb = DRY[None, :] * (1 - w[:, None]) + WET[None, :] * w[:, None]
    rgb[s] = STUCK
    return rgb


def render(built, path, title=""):
    """Writes a PNG of the built scene's current state to path."""
    import matplotlib
    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt
    from matplotlib.patches import Patch
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    fig = plt.figure(figsize=(8, 6), dpi=100)
    ax = fig.add_subplot(projection="3d")
    points = []
    for _, col, _ in built.colliders:
        polys = collider_polygons(col)
        if polys is None:
            pts = _rotate(col.rotation, col.params["points"]) + col.position
            ax.scatter(pts[:, 0], pts[:, 1], pts[:, 2], color=COLLIDER[:3], s=6)
            points.append(pts)
            continue
        ax.add_collection3d(Poly3DCollection(list(polys), facecolors=COLLIDER,
                                             edgecolors=(0.3, 0.3, 0.3, 0.15), linewidths=0.3))
        points.append(polys.reshape(-1, 3))
    cloth_points = []
    for spec, cloth, _ in built.cloths:
        p = cloth.positions
        faces = cloth.faces
        polys = [p[[k for k in f if k >= 0]] for f in faces]
        ax.add_collection3d(Poly3DCollection(
            polys, facecolors=face_colours(cloth.wetness, cloth.stuck, faces),
            edgecolors=(0.1, 0.1, 0.1, 0.25), linewidths=0.2))
        cloth_points.append(p)
    # frame the cloths, and the colliders near them
    cp = np.concatenate(cloth_points)
    lo, hi = cp.min(axis=0), cp.max(axis=0)
    margin = 0.25 * max(float(np.max(hi - lo)), 1e-3)
    for pts in points:
        near = pts[np.all((pts > lo - margin) & (pts < hi + margin), axis=1)]
        if len(near):
            lo, hi = np.minimum(lo, near.min(axis=0)), np.maximum(hi, near.max(axis=0))
    centre = (lo + hi) / 2
    half = np.maximum((hi - lo) / 2, 0.05 * max(float(np.max(hi - lo)), 1e-3)) * 1.05
    ax.set_xlim(centre[0] - half[0], centre[0] + half[0])
    ax.set_ylim(centre[1] - half[1], centre[1] + half[1])
    ax.set_zlim(centre[2] - half[2], centre[2] + half[2])
    ax.set_box_aspect(tuple(half / half.max()), zoom=1.1)
    ax.view_init(elev=22, azim=-60)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_zlabel("z (m)")
    ax.legend(handles=[Patch(color=DRY, label="dry"), Patch(color=WET, label="wet"),
                       Patch(color=STUCK, label="stuck")], loc="upper left")
    if title:
        ax.set_title(title)
    fig.savefig(path, format="png")
    plt.close(fig)
