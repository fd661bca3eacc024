#!/usr/bin/env python3
"""order_probe.py - how much the stratmesh tool's mesh depends on the order of the points.

    bench/order_probe.py CLOUD.ply [--seed N] [--round STEP] [--stratmesh PATH]
                         [-- STRATMESH_OPTIONS...]

Writes the cloud's points (x, y, z of the vertex element, as doubles) twice, in the order
read and shuffled (seed N, default 1), runs the stratmesh tool on both with
STRATMESH_OPTIONS (plus -o, --ascii and --report), and compares the two meshes' triangles
by their corners' coordinates, each triangle turned to start at its smallest corner, so
the comparison does not depend on the indices. With --round STEP every coordinate is first
rounded to a multiple of STEP (as a scanner storing integer units gives), the same in both
copies. Prints one JSON line: the triangle counts, how many triangles of each mesh the
other lacks, that share of the first, and the first run's report fields status, folds and
caps. Exit status 0 when both runs succeeded (however different), 1 when a run failed, 2
on a usage error. For example:

    bench/order_probe.py examples/data/bust.ply -- --axis z --layers 8
    bench/order_probe.py examples/data/bust.ply --round 0.18716 -- --axis z --layers 8 --cap

The tool is build/examples/cli/stratmesh (relative to the source tree) unless --stratmesh
or the environment variable STRATMESH says otherwise. Needs python3 only.
"""
import json
import os
import random
import struct
import subprocess
import sys
import tempfile

SCALARS = {
    "char": "b", "int8": "b", "uchar": "B", "uint8": "B", "short": "h", "int16": "h",
    "ushort": "H", "uint16": "H", "int": "i", "int32": "i", "uint": "I", "uint32": "I",
    "float": "f", "float32": "f", "double": "d", "float64": "d",
}


def read_header(data):
    end = data.index(b"end_header") + len(b"end_header")
    end = data.index(b"\n", end) + 1
    lines = data[:end].decode("ascii", "replace").splitlines()
    form = next(l.split()[1] for l in lines if l.startswith("format"))
    elements = []
    for line in lines:
        words = line.split()
        if words[:1] == ["element"]:
            elements.append((words[1], int(words[2]), []))
        elif words[:1] == ["property"] and elements:
            elements[-1][2].append(words[1:])
    return form, elements, end


def read_ply(path):
    """The vertices' (x, y, z) and the faces' corner lists of a PLY file."""
    data = open(path, "rb").read()
    form, elements, offset = read_header(data)
    points, faces = [], []
    if form == "ascii":
        rows = data[offset:].decode().split("\n")
        row = 0
        for name, count, props in elements:
            for _ in range(count):
                values = rows[row].split()
                row += 1
                if name == "vertex":
                    names = [p[-1] for p in props]
                    points.append(tuple(float(values[names.index(c)]) for c in "xyz"))
                elif name == "face":
                    faces.append(tuple(int(v) for v in values[1:1 + int(values[0])]))
        return points, faces
    order = "<" if form == "binary_little_endian" else ">"
    for name, count, props in elements:
        if props and props[0][0] == "list":
            count_code, index_code = SCALARS[props[0][1]], SCALARS[props[0][2]]
            for _ in range(count):
                (n,) = struct.unpack_from(order + count_code, data, offset)
                offset += struct.calcsize(count_code)
                face = struct.unpack_from(order + index_code * n, data, offset)
                offset += n * struct.calcsize(index_code)
                if name == "face":
                    faces.append(face)
            continue
        row = order + "".join(SCALARS[p[0]] for p in props)
        size = struct.calcsize(row)
        names = [p[-1] for p in props]
        for i in range(count):
            values = struct.unpack_from(row, data, offset + i * size)
            if name == "vertex":
                points.append(tuple(float(values[names.index(c)]) for c in "xyz"))
        offset += count * size
    return points, faces


def write_cloud(path, points):
    with open(path, "wb") as f:
        f.write(("ply\nformat binary_little_endian 1.0\nelement vertex %d\n"
                 "property double x\nproperty double y\nproperty double z\nend_header\n"
                 % len(points)).encode())
        for p in points:
            f.write(struct.pack("<3d", *p))


def triangle_set(points, faces):
    out = set()
    for face in faces:
        corners = [points[i] for i in face]
        first = corners.index(min(corners))
        out.add(tuple(corners[first:] + corners[:first]))
    return out


def main(argv):
    seed, step, tool = 1, None, os.environ.get("STRATMESH")
    if tool is None:
        root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
        tool = os.path.join(root, "build", "examples", "cli", "stratmesh")
    options = []
    if "--" in argv:
        options = argv[argv.index("--") + 1:]
        argv = argv[:argv.index("--")]
    args = []
    i = 0
    try:
        while i < len(argv):
            if argv[i] in ("--seed", "--round", "--stratmesh"):
                value = argv[i + 1]
                if argv[i] == "--seed":
                    seed = int(value)
                elif argv[i] == "--round":
                    step = float(value)
                else:
                    tool = value
                i += 2
            else:
                args.append(argv[i])
                i += 1
    except (IndexError, ValueError):
        args = []
    if len(args) != 1 or (step is not None and not step > 0):
        print(__doc__.split("\n\n")[1], file=sys.stderr)
        return 2
    points, _ = read_ply(args[0])
    if step is not None:
        points = [tuple(round(c / step) * step for c in p) for p in points]
    shuffled = list(points)
    random.Random(seed).shuffle(shuffled)
    with tempfile.TemporaryDirectory() as work:
        meshes, reports = [], []
        for k, cloud in enumerate((points, shuffled)):
            cloud_path = os.path.join(work, "cloud%d.ply" % k)
            mesh_path = os.path.join(work, "mesh%d.ply" % k)
            report_path = os.path.join(work, "report%d.json" % k)
            write_cloud(cloud_path, cloud)
            run = subprocess.run([tool, cloud_path, "-o", mesh_path, "--ascii",
                                  "--report", report_path] + options,
                                 stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
            if run.returncode != 0:
                print(json.dumps({"run": k, "failed": run.stderr.strip()}))
                return 1
            mesh_points, faces = read_ply(mesh_path)
            meshes.append(triangle_set(mesh_points, faces))
            reports.append(json.load(open(report_path)))
    first, second = meshes
    report = reports[0]
    print(json.dumps({
        "triangles": [len(first), len(second)],
        "only_in_input_order": len(first - second),
        "only_in_shuffled": len(second - first),
        "share_differing": round(len(first - second) / max(len(first), 1), 4),
        "status": report.get("status"),
        "folds": report.get("folds"),
        "caps": report.get("caps"),
    }))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
