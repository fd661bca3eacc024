#!/usr/bin/env python3
"""cap_crops.py - how many boundary loops the stratmesh tool's caps leave open on sparse,
ragged crops of a cloud.

    bench/cap_crops.py CLOUD.ply [--stratmesh PATH] [--quick]

Crops the cloud (x, y, z of the vertex element) along z to the part below 20%, 30% and 50%
of its height, draws 150, 250, 400, 800 and 1,600 of those points at random (seeds 0 to 5;
a crop with fewer points is taken whole), each as read and rounded to a multiple of 0.18716
(a 2000th of the bundled bust's bounding box diagonal), stores the coordinates as float32
values, and runs the tool with `--axis z --cap` and 1 and 3 layers on each: 360 runs on
which each surface has a loop at the crop's bottom and a ragged one where it was cut.
Prints one line per run that leaves a loop open, then one JSON line: the runs, the loops
closed and left open, the runs whose caps flipped wall edges under fins and those edges,
and the runs whose status was not ok. --quick runs the first seed
only (60 runs). On the bundled bust:

    bench/cap_crops.py examples/data/bust.ply

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

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from order_probe import read_ply, write_cloud  # noqa: E402


def as_float32(v):
    return struct.unpack("<f", struct.pack("<f", v))[0]


def main(argv):
    tool = os.environ.get("STRATMESH")
    if tool is None:
        root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
        tool = os.path.join(root, "build", "examples", "cli", "stratmesh")
    quick = "--quick" in argv
    argv = [a for a in argv if a != "--quick"]
    if "--stratmesh" in argv:
        i = argv.index("--stratmesh")
        if i + 1 >= len(argv):
            argv = []
        else:
            tool = argv[i + 1]
            argv = argv[:i] + argv[i + 2:]
    if len(argv) != 1:
        print(__doc__.split("\n\n")[1], file=sys.stderr)
        return 2
    points, _ = read_ply(argv[0])
    z0, z1 = min(p[2] for p in points), max(p[2] for p in points)
    totals = {"runs": 0, "closed": 0, "left_open": 0, "runs_with_wall_flips": 0,
              "wall_flips": 0, "failed": 0}
    with tempfile.TemporaryDirectory() as work:
        cloud_path = os.path.join(work, "crop.ply")
        mesh_path = os.path.join(work, "mesh.ply")
        report_path = os.path.join(work, "report.json")
        for step in (None, 0.18716):
            for count in (150, 250, 400, 800, 1600):
                for seed in range(1 if quick else 6):
                    for fraction in (0.2, 0.3, 0.5):
                        crop = [p for p in points if p[2] < z0 + fraction * (z1 - z0)]
                        rng = random.Random(seed)
                        if len(crop) > count:
                            crop = rng.sample(crop, count)
                        if step is not None:
                            crop = [tuple(round(c / step) * step for c in p) for p in crop]
                        write_cloud(cloud_path, [tuple(as_float32(c) for c in p) for p in crop])
                        for layers in (1, 3):
                            run = subprocess.run(
                                [tool, cloud_path, "-o", mesh_path, "--axis", "z", "--layers",
                                 str(layers), "--cap", "--report", report_path, "-q"],
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
                            totals["runs"] += 1
                            report = json.load(open(report_path)) if run.returncode == 0 else {}
                            if report.get("status") != "ok":
                                totals["failed"] += 1
                                continue
                            caps = report["caps"]
                            totals["closed"] += caps["closed"]
                            totals["left_open"] += caps["left_open"]
                            flips = caps.get("wall_flips", 0)  # older tools lack it
                            totals["wall_flips"] += flips
                            totals["runs_with_wall_flips"] += flips > 0
                            if caps["left_open"]:
                                print("round %s, %d points, seed %d, below %.0f%%, %d layers: "
                                      "%d loop(s) left open" % (step, len(crop), seed,
                                                                100 * fraction, layers,
                                                                caps["left_open"]))
    print(json.dumps(totals))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
