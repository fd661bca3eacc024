#!/usr/bin/env python3
"""branch_split.py - how close separate tubes per branch come, before any junction.

    bench/branch_split.py CLOUD.ply HEIGHT|auto OUT.ply [--below] [--gap D]
                          [--stratmesh PATH] [--piece-options "OPTIONS"]
                          [-- TRUNK_OPTIONS...]

An experiment on branches meshed as tubes of their own, without the library's junction:
splits the cloud (x, y, z of the vertex element) at HEIGHT along z into the
trunk below and the pieces above it (with --below: the trunk above and the pieces below),
pieces being the connected parts of those points when points closer than D join (single
linkage; D defaults to 4 times the median distance from a point to its nearest
neighbour, over a sample of 200 points); runs the stratmesh tool on the trunk with
TRUNK_OPTIONS (for example --axis z --layers 8) and on each piece of at least 20 points
with the tool's automatic axis and layers, or with OPTIONS (split at spaces:
--piece-options "--axis z" meshes the pieces along the trunk's axis, which suits short
pieces such as the femur's condyles, where a long horn wants its own); and writes
OUT.ply, one mesh over every point of the cloud in its order, with the triangles of all
those runs: the branches as tubes of their own, not joined to the trunk (each junction
leaves a gap and two loops). Prints one JSON line: the pieces' point counts, each run's
status, layers and folds. Measure it with a mesh-quality checker (the one
quality_vs_afr.sh takes as MESH_CHECKER), against a reference made as bench/README.md
describes, e.g. on the horned bust (horned_bust.py; its horns leave the skull's section at
z = 2.85):

    bench/branch_split.py horned.ply 2.85 split.ply -- --axis z --layers 8
    "$MESH_CHECKER" --mesh split.ply --ref horned_reference.off --cloud horned.ply

HEIGHT auto takes the cut, and the gap unless --gap is given, from the library's
find_parting (the tool's --branches along z): the lowest cut above which the cloud parts,
or with --below the highest below which it does; none found is an error (exit 1).

The tool is build/examples/cli/stratmesh (relative to the source tree) unless --stratmesh
or the environment variable STRATMESH says otherwise. Needs python3 only.
"""
import json
import math
import os
import random
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from order_probe import read_ply, write_cloud  # noqa: E402

SMALLEST_PIECE = 20


def median_spacing(points):
    sample = random.Random(1).sample(points, min(200, len(points)))
    nearest = []
    for p in sample:
        best = math.inf
        for q in points:
            d = (p[0] - q[0]) ** 2 + (p[1] - q[1]) ** 2 + (p[2] - q[2]) ** 2
            if 0 < d < best:
                best = d
        nearest.append(math.sqrt(best))
    nearest.sort()
    return nearest[len(nearest) // 2]


def pieces_of(points, gap):
    """Single-linkage pieces of the points at distance gap: lists of indices."""
    parent = list(range(len(points)))

    def root(i):
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    cells = {}
    for i, p in enumerate(points):
        cells.setdefault(tuple(int(math.floor(c / gap)) for c in p), []).append(i)
    for (cx, cy, cz), members in cells.items():
        for dx in (-1, 0, 1):
            for dy in (-1, 0, 1):
                for dz in (-1, 0, 1):
                    for j in cells.get((cx + dx, cy + dy, cz + dz), ()):
                        for i in members:
                            if i < j and math.dist(points[i], points[j]) < gap:
                                parent[root(i)] = root(j)
    groups = {}
    for i in range(len(points)):
        groups.setdefault(root(i), []).append(i)
    return sorted(groups.values(), key=len, reverse=True)


def write_mesh(path, points, faces):
    with open(path, "w") as f:
        f.write("ply\nformat ascii 1.0\nelement vertex %d\nproperty double x\n"
                "property double y\nproperty double z\nelement face %d\n"
                "property list uchar int vertex_indices\nend_header\n"
                % (len(points), len(faces)))
        for p in points:
            f.write("%.17g %.17g %.17g\n" % p)
        for t in faces:
            f.write("3 %d %d %d\n" % t)


def library_parting(tool, cloud_path, below):
    """(cut, gap) of the tool's --branches along z on one side, or None where it finds none."""
    with tempfile.TemporaryDirectory() as work:
        report_path = os.path.join(work, "report.json")
        run = subprocess.run([tool, cloud_path, "-o", os.path.join(work, "mesh.ply"), "--axis",
                              "z", "--branches", "--report", report_path, "-q"],
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        if run.returncode != 0:
            raise SystemExit("the tool could not mesh %s" % cloud_path)
        branches = json.load(open(report_path))["branches"]
    side = branches["below" if below else "above"]
    return None if side is None else (side["cut"], branches["gap"])


def main(argv):
    tool = os.environ.get("STRATMESH") or os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "..", "build", "examples", "cli", "stratmesh")
    trunk_options = []
    if "--" in argv:
        trunk_options = argv[argv.index("--") + 1:]
        argv = argv[:argv.index("--")]
    gap = None
    below_first = "--below" in argv
    if below_first:
        argv.remove("--below")
    piece_options = []
    for flag in ("--gap", "--stratmesh", "--piece-options"):
        if flag in argv:
            i = argv.index(flag)
            if i + 1 >= len(argv):
                print(__doc__.split("\n\n")[1], file=sys.stderr)
                return 2
            if flag == "--gap":
                gap = float(argv[i + 1])
            elif flag == "--piece-options":
                piece_options = argv[i + 1].split()
            else:
                tool = argv[i + 1]
            argv = argv[:i] + argv[i + 2:]
    if len(argv) != 3:
        print(__doc__.split("\n\n")[1], file=sys.stderr)
        return 2
    points, _ = read_ply(argv[0])
    out_path = argv[2]
    if argv[1] == "auto":
        found = library_parting(tool, argv[0], below_first)
        if found is None:
            print("branch_split.py: the library finds no parting %s any cut"
                  % ("below" if below_first else "above"), file=sys.stderr)
            return 1
        height = found[0]
        gap = gap or found[1]
    else:
        height = float(argv[1])
    if gap is None:
        gap = 4 * median_spacing(points)
    trunk = [i for i, p in enumerate(points) if (p[2] >= height) == below_first]
    branches = [i for i, p in enumerate(points) if (p[2] >= height) != below_first]
    parts = [("trunk", trunk, trunk_options)]
    small = 0
    for k, piece in enumerate(pieces_of([points[i] for i in branches], gap)):
        if len(piece) < SMALLEST_PIECE:
            small += len(piece)
            continue
        parts.append(("piece %d" % k, [branches[i] for i in piece], piece_options))
    summary = {"height": height, "gap": gap, "points": len(points), "left_out_in_small_pieces": small, "runs": []}
    faces = []
    with tempfile.TemporaryDirectory() as work:
        for name, indices, options in parts:
            cloud_path = os.path.join(work, "part.ply")
            mesh_path = os.path.join(work, "part_mesh.ply")
            report_path = os.path.join(work, "report.json")
            write_cloud(cloud_path, [points[i] for i in indices])
            run = subprocess.run([tool, cloud_path, "-o", mesh_path, "--ascii", "--report",
                                  report_path, "-q"] + options,
                                 stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            report = json.load(open(report_path)) if run.returncode == 0 else {}
            summary["runs"].append({"part": name, "points": len(indices),
                                    "status": report.get("status", "failed"),
                                    "layers": report.get("layer_count"),
                                    "folds": report.get("folds")})
            if run.returncode != 0:
                continue
            vertices, part_faces = read_ply(mesh_path)
            if len(vertices) != len(indices):
                raise SystemExit("the tool wrote %d vertices for %d points"
                                 % (len(vertices), len(indices)))
            faces.extend(tuple(indices[c] for c in face) for face in part_faces)
    write_mesh(out_path, points, faces)
    print(json.dumps(summary))
    return 0 if all(r["status"] == "ok" for r in summary["runs"]) else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
