#!/usr/bin/env python3
"""The Python binding's cost over the C++ call: stratmesh.reconstruct() against
stratmesh_bench's timing of stratmesh::reconstruct on the same cloud with the same options.

    cmake -S . -B build-bench -DSTRATMESH_BUILD_BENCH=ON -DCMAKE_BUILD_TYPE=Release \
      -DSTRATMESH_BUILD_TESTS=OFF -DSTRATMESH_BUILD_EXAMPLES=OFF
    cmake --build build-bench --target stratmesh_bench
    python3 bench/python_overhead.py --bench build-bench/bench/stratmesh_bench

The cloud (a bumpy tube of --points points, float64) goes to the C++ program as a binary
PLY that it reads in place; both mesh it along z in --layers layers on one thread. The C++
figure is the library call alone (its workspace allocated and touched beforehand); the
Python one is everything stratmesh.reconstruct() does: the workspace's allocation, the
call, the report's conversion and the triangle array's shrinking; and again with a
stratmesh.Workspace kept between calls, as the C++ timing keeps its workspace. Rounds alternate the two,
so a loaded machine slows both alike. Prints one JSON line.
"""
import argparse
import json
import os
import statistics
import subprocess
import tempfile
import time

import numpy as np

import stratmesh


def bumpy_tube(n, seed):
    rng = np.random.default_rng(seed)
    theta = rng.uniform(0, 2 * np.pi, n)
    z = rng.uniform(0, 2 * np.pi, n)
    r = 1 + 0.25 * np.sin(5 * theta) * np.cos(z)
    return np.stack([r * np.cos(theta), r * np.sin(theta), z], axis=1)


def write_ply(path, points):
    with open(path, "wb") as f:
        f.write(f"ply\nformat binary_little_endian 1.0\nelement vertex {len(points)}\n"
                "property double x\nproperty double y\nproperty double z\nend_header\n"
                .encode("ascii"))
        f.write(points.astype("<f8").tobytes())


def cpp_seconds(bench, path, layers, runs):
    out = subprocess.run([bench, "--cloud", path, "--axis", "z", "--layers", str(layers),
                          "--runs", str(runs), "--no-cgal"],
                         check=True, capture_output=True, text=True).stdout
    line = json.loads(out.strip().splitlines()[-1])
    assert line["status"] == "ok" and line["in_place"], line
    return line["seconds"], line["min_seconds"], line["triangles"]


def python_seconds(points, layers, runs, workspace=None):
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        triangles, _ = stratmesh.reconstruct(points, axis="z", layers=layers,
                                             workspace=workspace)
        times.append(time.perf_counter() - start)
    return times, triangles


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bench", required=True, help="the stratmesh_bench program")
    parser.add_argument("--points", type=int, default=1_000_000)
    parser.add_argument("--layers", type=int, default=8)
    parser.add_argument("--runs", type=int, default=5, help="runs per round")
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()

    points = bumpy_tube(args.points, seed=1)
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "tube.ply")
        write_ply(path, points)
        cpp, cpp_min, py, kept = [], [], [], []
        workspace = stratmesh.Workspace()
        for _ in range(args.rounds):
            median, fastest, cpp_triangles = cpp_seconds(args.bench, path, args.layers, args.runs)
            cpp.append(median)
            cpp_min.append(fastest)
            times, triangles = python_seconds(points, args.layers, args.runs)
            py.extend(times)
            kept.extend(python_seconds(points, args.layers, args.runs, workspace)[0])
    assert len(triangles) == cpp_triangles
    start = time.perf_counter()
    triangles.copy()
    copy_seconds = time.perf_counter() - start
    cpp_median, py_median = statistics.median(cpp), statistics.median(py)
    kept_median = statistics.median(kept)
    print(json.dumps({
        "points": args.points, "layers": args.layers, "triangles": len(triangles),
        "cpp_seconds": round(cpp_median, 4), "cpp_min_seconds": round(min(cpp_min), 4),
        "python_seconds": round(py_median, 4), "python_min_seconds": round(min(py), 4),
        "overhead_median": round(py_median / cpp_median - 1, 4),
        "overhead_min": round(min(py) / min(cpp_min) - 1, 4),
        "kept_workspace_seconds": round(kept_median, 4),
        "kept_workspace_min_seconds": round(min(kept), 4),
        "kept_overhead_median": round(kept_median / cpp_median - 1, 4),
        "kept_overhead_min": round(min(kept) / min(cpp_min) - 1, 4),
        "output_copy_seconds": round(copy_seconds, 4),
    }))


if __name__ == "__main__":
    main()
