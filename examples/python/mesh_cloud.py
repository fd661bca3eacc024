#!/usr/bin/env python3
"""Meshes a point cloud file with stratmesh and writes the mesh as a binary PLY.

    python3 examples/python/mesh_cloud.py examples/data/bust.ply bust_mesh.ply --axis z

Reads PLY (ascii or binary little-endian) and XYZ text (x y z first on each line) with
numpy; other formats through Open3D when it is installed. A binary PLY whose x, y, z are
adjacent properties of one type is meshed in place: the points are a strided view of the
file's bytes, however many other properties each vertex has.
"""
import argparse
import io
import sys

import numpy as np

import stratmesh

PLY_TYPES = {
    "char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1",
    "short": "i2", "int16": "i2", "ushort": "u2", "uint16": "u2",
    "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
    "float": "f4", "float32": "f4", "double": "f8", "float64": "f8",
}


def read_ply(path):
    with open(path, "rb") as f:
        if f.readline().strip() != b"ply":
            raise ValueError(f"{path}: not a PLY file")
        fmt, count, fields, in_vertex = None, 0, [], False
        for raw in f:
            words = raw.decode("ascii").split()
            if not words or words[0] in ("comment", "obj_info"):
                continue
            if words[0] == "end_header":
                break
            if words[0] == "format":
                fmt = words[1]
            elif words[0] == "element":
                in_vertex = words[1] == "vertex"
                if in_vertex:
                    count = int(words[2])
            elif words[0] == "property" and in_vertex:
                if words[1] == "list":
                    raise ValueError(f"{path}: a list property in the vertex element")
                fields.append((words[2], "<" + PLY_TYPES[words[1]]))
        names = [name for name, _ in fields]
        if not {"x", "y", "z"} <= set(names):
            raise ValueError(f"{path}: the vertices have no x, y, z")
        if fmt == "ascii":
            text = io.TextIOWrapper(f, encoding="ascii")
            table = np.loadtxt(text, max_rows=count, ndmin=2)
            return table[:, [names.index(c) for c in "xyz"]]
        if fmt != "binary_little_endian":
            raise ValueError(f"{path}: format {fmt} (ascii or binary_little_endian only)")
        record = np.dtype(fields)
        raw = f.read(count * record.itemsize)
    x = names.index("x")
    scalar = record.fields["x"][0]
    if names[x:x + 3] == ["x", "y", "z"] and all(record.fields[c][0] == scalar for c in "yz"):
        # x, y, z side by side: a strided view of the file's bytes, no copy.
        return np.ndarray((count, 3), dtype=scalar, buffer=raw,
                          offset=record.fields["x"][1], strides=(record.itemsize, scalar.itemsize))
    vertices = np.frombuffer(raw, dtype=record, count=count)
    return np.stack([vertices[c] for c in "xyz"], axis=1)


def read_cloud(path):
    if path.lower().endswith(".ply"):
        return read_ply(path)
    if path.lower().endswith((".xyz", ".txt")):
        return np.loadtxt(path, usecols=(0, 1, 2), ndmin=2)
    try:
        import open3d
    except ImportError:
        sys.exit(f"{path}: only .ply and .xyz are read without Open3D")
    return np.asarray(open3d.io.read_point_cloud(path).points)


def write_ply(path, points, triangles):
    header = (f"ply\nformat binary_little_endian 1.0\ncomment made by stratmesh\n"
              f"element vertex {len(points)}\nproperty float x\nproperty float y\n"
              f"property float z\nelement face {len(triangles)}\n"
              f"property list uchar uint vertex_indices\nend_header\n")
    faces = np.empty(len(triangles), dtype=[("n", "u1"), ("v", "<u4", 3)])
    faces["n"] = 3
    faces["v"] = triangles
    with open(path, "wb") as f:
        f.write(header.encode("ascii"))
        f.write(np.asarray(points, dtype="<f4").tobytes())
        f.write(faces.tobytes())


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("cloud")
    parser.add_argument("mesh")
    parser.add_argument("--axis", default="auto", help="auto, x, y or z")
    parser.add_argument("--layers", type=int, default=0, help="equal layers (0: automatic)")
    parser.add_argument("--layer-height", type=float, default=0.0)
    parser.add_argument("--cap", action="store_true", help="close the ends")
    parser.add_argument("--surface-flips", action="store_true")
    parser.add_argument("--threads", type=int, default=0, help="0: one per core")
    args = parser.parse_args()

    points = read_cloud(args.cloud)
    try:
        triangles, report = stratmesh.reconstruct(
            points, axis=args.axis, layers=args.layers, layer_height=args.layer_height,
            cap=args.cap, surface_flips=args.surface_flips, threads=args.threads,
            skip_invalid=True)
    except stratmesh.Error as e:
        sys.exit(f"{args.cloud}: {e}")
    write_ply(args.mesh, points, triangles)
    print(f"{args.mesh}: {len(triangles)} triangles over {report.points.used_count} of "
          f"{len(points)} points, {report.layers.used_count} layers")


if __name__ == "__main__":
    main()
