"""Wavefront OBJ reading and writing, and the PC2 point cache.

Reading is strict: a malformed line or an index out of range is a
MeshError naming the file and the line.
"""

import os
import stat
import struct

import numpy as np


class MeshError(Exception):
    """A mesh file that cannot be used; the message names file and line."""


def read_obj(path):
    """(vertices (n, 3) float64, faces list of index lists, 0-based).

    Understands v and f lines (f with v, v/vt, v//vn or v/vt/vn, negative
    = relative indices); vt, vn, o, g, s, usemtl, mtllib, l and comments
    are ignored."""
    try:
        with open(path, encoding="utf-8") as f:
            # a device (/dev/zero) or a pipe would be read forever
            if not stat.S_ISREG(os.fstat(f.fileno()).st_mode):
                raise MeshError("cannot read %s: not a regular file" % path)
            lines = f.read().splitlines()
    except (OSError, UnicodeDecodeError, ValueError) as e:  # ValueError: a NUL in the path
        raise MeshError("cannot read %s: %s" % (path, getattr(e, "strerror", None) or e)) from None
    vertices, faces, face_lines = [], [], []
    for number, line in enumerate(lines, 1):
        parts = line.split("#", 1)[0].split()
        if not parts:
            continue
        tag, args = parts[0], parts[1:]
        where = "%s:%d" % (path, number)
        if tag == "v":
            if len(args) not in (3, 4):
                raise MeshError("%s: a vertex needs 3 coordinates, found %d" % (where, len(args)))
            try:
                xyz = [float(a) for a in args[:3]]
            except ValueError:
                raise MeshError("%s: a vertex coordinate is not a number: %r" %
                                (where, line.strip())) from None
            if not all(np.isfinite(xyz)):
                raise MeshError("%s: a vertex coordinate is not finite: %r" % (where, line.strip()))
            vertices.append(xyz)
        elif tag == "f":
            if len(args) < 3:
                raise MeshError("%s: a face needs at least 3 vertices, found %d" %
                                (where, len(args)))
            face = []
            for a in args:
                try:
                    k = int(a.split("/", 1)[0])
                except ValueError:
                    raise MeshError("%s: face vertex %r is not an index" % (where, a)) from None
                if k == 0:
                    raise MeshError("%s: face vertex index 0 (OBJ indices start at 1)" % where)
                face.append(k - 1 if k > 0 else len(vertices) + k)
                if face[-1] < 0:
                    raise MeshError("%s: relative face index %d reaches before the first vertex"
                                    % (where, k))
            faces.append(face)
            face_lines.append(number)
        elif tag in ("vt", "vn", "vp", "o", "g", "s", "usemtl", "mtllib", "l"):
            continue
        else:
            raise MeshError("%s: unknown OBJ statement %r" % (where, tag))
    n = len(vertices)
    for face, number in zip(faces, face_lines):
        for k in face:
            if k >= n:
                raise MeshError("%s:%d: face uses vertex %d, but the file has %d vertices" %
                                (path, number, k + 1, n))
    if not faces:
        raise MeshError("%s: no faces" % path)
    return np.array(vertices, dtype=np.float64).reshape(-1, 3), faces


def cloth_faces(faces, path):
    """OBJ faces as a cloth's (F, 3) or (F, 4) array: triangles and quads
    only (a triangle among quads gets -1 as its fourth index)."""
    sizes = {len(f) for f in faces}
    if not sizes <= {3, 4}:
        raise MeshError("%s: cloth faces must be triangles or quads, found a face of %d vertices"
                        % (path, max(sizes)))
    if sizes == {3}:
        return np.array(faces, dtype=np.int64)
    return np.array([f + [-1] * (4 - len(f)) for f in faces], dtype=np.int64)


def triangulate(faces):
    """Fan-triangulates polygons: (T, 3) array."""
    tris = [[f[0], f[k], f[k + 1]] for f in faces for k in range(1, len(f) - 1)]
    return np.array(tris, dtype=np.int64).reshape(-1, 3)


def write_obj(path, vertices, faces, name="cloth", comment=None):
    """Writes vertices and faces (rows of indices, -1 = unused) as OBJ."""
    with open(path, "w", encoding="utf-8") as f:
        if comment:
            for line in comment.splitlines():
                f.write("# %s\n" % line)
        f.write("o %s\n" % name)
        for x, y, z in vertices:
            f.write("v %.17g %.17g %.17g\n" % (x, y, z))  # exact round trip
        for face in np.asarray(faces):
            f.write("f " + " ".join(str(int(k) + 1) for k in face if k >= 0) + "\n")


class PC2Writer:
    """A PC2 point cache written frame by frame (what Blender's Mesh Cache
    modifier reads): 32-byte header, then frames x vertices x 3 float32,
    little-endian."""

    def __init__(self, path, vertex_count, frame_count, start=1.0, sampling=1.0):
        self.path = path
        self.vertex_count = vertex_count
        self.frame_count = frame_count
        self.written = 0
        self.file = open(path, "wb")
        self.file.write(struct.pack("<12siiffi", b"POINTCACHE2\0", 1, vertex_count,
                                    float(start), float(sampling), frame_count))

    def write(self, positions):
        p = np.asarray(positions, dtype="<f4")
        assert p.shape == (self.vertex_count, 3)
        self.file.write(p.tobytes())
        self.written += 1

    def close(self):
        self.file.close()
        if self.written != self.frame_count:
            raise RuntimeError("%s: wrote %d frames, the header says %d" %
                               (self.path, self.written, self.frame_count))


def read_pc2(path):
    """(header dict, frames (F, n, 3) float32)."""
    with open(path, "rb") as f:
        data = f.read()
    magic, version, n, start, sampling, frames = struct.unpack("<12siiffi", data[:32])
    body = np.frombuffer(data[32:], dtype="<f4")
    header = {"magic": magic, "version": version, "vertex_count": n, "start": start,
              "sampling": sampling, "frame_count": frames}
    if body.size != frames * n * 3:
        raise MeshError("%s: %d floats after the header, expected %d" %
                        (path, body.size, frames * n * 3))
    return header, body.reshape(frames, n, 3)


def replace_into(tmp_dir, out_dir):
    """Moves every file of tmp_dir into out_dir (each an atomic rename),
    then removes tmp_dir."""
    if not os.path.exists(out_dir):
        os.rename(tmp_dir, out_dir)
        return
    for name in sorted(os.listdir(tmp_dir)):
        os.replace(os.path.join(tmp_dir, name), os.path.join(out_dir, name))
    os.rmdir(tmp_dir)
