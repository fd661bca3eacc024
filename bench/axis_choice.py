#!/usr/bin/python3
"""axis_choice.py - the automatic axis against the best explicit one, cloud by cloud.

    MESH_CHECKER=PATH bench/axis_choice.py [--stratmesh PATH] CLOUD:REF [CLOUD:REF ...]

For each cloud (PLY or XYZ) and its reference surface REF (any mesh the checker reads),
runs the stratmesh tool with no options (the automatic axis) and with each explicit
candidate: x, y, z and the cloud's three principal directions, the other options left at
their defaults. Each mesh is measured by the mesh-quality checker
(CHECKER --mesh MESH --ref REF --no-si, one JSON object with mean_out_to_ref, the mean
distance from the mesh to REF relative to REF's bounding-box diagonal, and area_ratio, the
mesh's area over REF's). Prints one JSON line per cloud: the automatic axis's distance and
area, the best explicit axis (by distance) with its figures, the ratio of the automatic
distance to the best (1.0: as good), and the share of the automatic run's reconstruction
time spent before the layers are made (the report's seconds.phases.validate over
seconds.reconstruct: checking the cloud, choosing the axis and searching for branches).

Needs Debian's python3 with numpy (for the principal directions) and a built tool
(default build/examples/cli/stratmesh).
"""
import json
import os
import subprocess
import sys
import tempfile

import numpy as np


def read_points(path):
    """The x, y, z columns of an XYZ file or of a PLY's vertex element (ascii or binary)."""
    raw = open(path, "rb").read()
    if not raw.startswith(b"ply"):
        return np.loadtxt(path, comments="#")[:, :3]
    end = raw.index(b"end_header") + len(b"end_header")
    end = raw.index(b"\n", end) + 1
    header = raw[:end].decode("ascii").splitlines()
    count, props, in_vertex = 0, [], False
    for line in header:
        words = line.split()
        if words[:2] == ["element", "vertex"]:
            count, in_vertex = int(words[2]), True
        elif words and words[0] == "element":
            in_vertex = False
        elif in_vertex and words[:1] == ["property"]:
            props.append((words[2], words[1]))
    names = [name for name, _ in props]
    if "format ascii 1.0" in header:
        rows = raw[end:].decode("ascii").split("\n")[:count]
        table = np.array([[float(v) for v in row.split()] for row in rows])
        return table[:, [names.index(axis) for axis in "xyz"]]
    types = {"float": "f4", "float32": "f4", "double": "f8", "float64": "f8",
             "uchar": "u1", "uint8": "u1", "char": "i1", "int8": "i1",
             "ushort": "u2", "uint16": "u2", "short": "i2", "int16": "i2",
             "uint": "u4", "uint32": "u4", "int": "i4", "int32": "i4"}
    order = "<" if "binary_little_endian" in " ".join(header) else ">"
    dtype = np.dtype([(name, order + types[kind]) for name, kind in props])
    records = np.frombuffer(raw, dtype=dtype, count=count, offset=end)
    return np.stack([records[axis].astype(float) for axis in "xyz"], axis=1)


def principal_directions(points):
    centred = points - points.mean(axis=0)
    _, vectors = np.linalg.eigh(centred.T @ centred)
    return [vectors[:, i] for i in (2, 1, 0)]


def measure(tool, checker, cloud, ref, axis_args, work, tag):
    mesh = os.path.join(work, tag + ".ply")
    report = os.path.join(work, tag + ".json")
    run = subprocess.run([tool, cloud, "-o", mesh, "--report", report, "-q"] + axis_args,
                         capture_output=True, text=True)
    if run.returncode not in (0, 5):
        return None
    seconds = json.load(open(report))["seconds"]
    quality = json.loads(subprocess.run([checker, "--mesh", mesh, "--ref", ref, "--no-si"],
                                        capture_output=True, text=True).stdout)
    return {"mean": quality["mean_out_to_ref"], "area": quality["area_ratio"],
            "before_layers_share": seconds["phases"]["validate"] / max(seconds["reconstruct"], 1e-12)}


def main(argv):
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    tool = os.path.join(root, "build", "examples", "cli", "stratmesh")
    if argv[:1] == ["--stratmesh"]:
        tool, argv = argv[1], argv[2:]
    checker = os.environ.get("MESH_CHECKER")
    if not checker or not argv:
        sys.stderr.write(__doc__)
        return 2
    with tempfile.TemporaryDirectory() as work:
        for pair in argv:
            cloud, ref = pair.split(":")
            name = os.path.splitext(os.path.basename(cloud))[0]
            automatic = measure(tool, checker, cloud, ref, [], work, "automatic")
            candidates = {"x": ["--axis", "x"], "y": ["--axis", "y"], "z": ["--axis", "z"]}
            for k, v in enumerate(principal_directions(read_points(cloud))):
                candidates["principal%d" % k] = ["--axis", ",".join("%.17g" % c for c in v)]
            explicit = {}
            for label, args in candidates.items():
                figures = measure(tool, checker, cloud, ref, args, work, label)
                if figures:
                    explicit[label] = figures
            line = {"cloud": name, "automatic": automatic}
            if explicit and automatic:
                best = min(explicit, key=lambda label: explicit[label]["mean"])
                line.update(best=best, best_mean=explicit[best]["mean"],
                            best_area=explicit[best]["area"],
                            ratio=automatic["mean"] / explicit[best]["mean"])
            print(json.dumps(line), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
