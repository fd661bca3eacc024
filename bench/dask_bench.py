#!/usr/bin/env python3
"""Throughput of stratmesh.dask on a local cluster of 1 and 2 worker processes, beside one
stream and one reconstruct() in this process, and the quantities docs/dask.md's model uses.

    python3 bench/dask_bench.py --points 4000000 --partitions 8 --workers 1,2

The cloud is a bumpy tube (r = 1 + 0.25 sin(5 theta) cos(z), height 2 pi, random order)
saved as --partitions .npy files, which the workers read themselves. Each worker is one
process with one thread, and meshes --ranges-per-worker ranges of whole layers. The time
of a cluster run is plan() (a pass over the files) plus
mesh(...).compute(), the triangles gathered here; the cluster's start is not counted.
Prints one JSON line per run.
"""
import argparse
import json
import os
import tempfile
import time

import numpy as np

import distributed
import stratmesh
import stratmesh.dask as smd


def bumpy_tube(n, seed):
    rng = np.random.default_rng(seed)
    theta = rng.uniform(0, 2 * np.pi, n)
    z = rng.uniform(0, 2 * np.pi, n)
    r = 1 + 0.25 * np.sin(5 * theta) * np.cos(z)
    return np.stack([r * np.cos(theta), r * np.sin(theta), z], axis=1)


def report(**fields):
    print(json.dumps(fields), flush=True)


def one_stream(cloud, plan):
    """The whole cloud through one stream, layer by layer; the points held at most."""
    layer = smd.layer_of(cloud, plan)
    order = np.argsort(layer, kind="stable")
    starts = np.searchsorted(layer[order], np.arange(plan.layer_count + 1))
    largest = int(np.diff(starts).max())
    stream = stratmesh.Stream(axis=plan.axis, max_points=3 * largest, origin=plan.origin)
    count = 0
    for j in range(plan.layer_count):
        top = plan.cuts[j] if j < len(plan.cuts) else plan.height_max
        count += len(stream.push(cloud[order[starts[j]:starts[j + 1]]], top))
    count += len(stream.close())
    return count, stream.report.points.held_count, largest


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=4_000_000)
    parser.add_argument("--partitions", type=int, default=8)
    parser.add_argument("--layer-height", type=float, default=0.25)
    parser.add_argument("--workers", default="1,2")
    parser.add_argument("--ranges-per-worker", type=int, default=2)
    args = parser.parse_args()

    cloud = bumpy_tube(args.points, seed=2)
    with tempfile.TemporaryDirectory() as tmp:
        paths = []
        for i, part in enumerate(np.array_split(cloud, args.partitions)):
            paths.append(os.path.join(tmp, f"part{i:03d}.npy"))
            np.save(paths[-1], part)

        plan = smd.plan(paths, axis="z", layer_height=args.layer_height)
        start = time.perf_counter()
        triangles, held, largest = one_stream(cloud, plan)
        seconds = time.perf_counter() - start
        report(run="one stream", points=args.points, layers=plan.layer_count,
               seconds=round(seconds, 3), points_per_second=round(args.points / seconds),
               triangles=triangles, held_points=held, largest_layer=largest,
               workspace_bytes_per_held_point=round(
                   stratmesh.stream_workspace_size(3 * largest) / (3 * largest), 1))
        start = time.perf_counter()
        whole, _ = stratmesh.reconstruct(cloud, axis="z", cuts=plan.cuts, origin=plan.origin)
        seconds = time.perf_counter() - start
        report(run="reconstruct", points=args.points, seconds=round(seconds, 3),
               points_per_second=round(args.points / seconds), triangles=len(whole))
        del whole

        for workers in (int(w) for w in args.workers.split(",")):
            with distributed.LocalCluster(n_workers=workers, threads_per_worker=1,
                                          processes=True, dashboard_address=None) as cluster, \
                    distributed.Client(cluster):
                start = time.perf_counter()
                plan = smd.plan(paths, axis="z", layer_height=args.layer_height,
                                ranges=args.ranges_per_worker * workers)
                planned = time.perf_counter()
                triangles = smd.mesh(paths, plan).compute()
                done = time.perf_counter()
            ranges = len(plan.bounds) - 1
            own = plan.layer_count
            # Each range also pushes one layer beyond each edge it has.
            extra = 2 * (ranges - 1)
            report(run="dask", workers=workers, points=args.points, partitions=args.partitions,
                   ranges=ranges, layers=own, plan_seconds=round(planned - start, 3),
                   mesh_seconds=round(done - planned, 3), seconds=round(done - start, 3),
                   points_per_second=round(args.points / (done - start)),
                   triangles=len(triangles), band_duplication=round(extra / own, 3))


if __name__ == "__main__":
    main()
