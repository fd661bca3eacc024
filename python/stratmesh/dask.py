"""Meshing a cloud larger than one machine on a Dask cluster, with stratmesh's stream.

    plan = stratmesh.dask.plan(points, axis="z", layer_height=0.05)
    triangles = stratmesh.dask.mesh(points, plan).compute()

points is a dask array of shape (n, 3) chunked along its rows only, or a list of
partitions: numpy arrays or paths of .npy files (read on the workers, memory-mapped). The
global index of a point is its position in the partitions taken in order, one after the
other. The layers are cut at fixed heights along the axis; ranges of whole layers are
meshed on the workers, each by one stream; the union of the triangles they keep is, as a
set, what one stream over the whole cloud gives with the same layers and origin
(docs/dask.md gives the rule and the conditions).
"""
from dataclasses import dataclass

import dask
import dask.array as da
import numpy as np

from . import STATUSES, Error, Stream

_UNIT = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0)}
_CLOSED_BOTTOM, _CLOSED_TOP = 1, 2  # the header's ClosedEnd bits in LayerInfo::closed_ends
_LEAST_HELD = 16                    # a stream's workspace holds at least this many points


@dataclass(frozen=True)
class Plan:
    """What every worker needs to mesh its range in the same frame as the others."""

    axis: object            # as given to the stream: "x", "y", "z" or a 3-vector
    unit: tuple             # the unit axis the heights are measured along
    origin: tuple           # the shared frame origin (the cloud's centroid)
    cuts: np.ndarray        # heights between layers: layer j lies in [cuts[j-1], cuts[j])
    height_min: float       # the lowest point's height
    height_max: float       # the highest point's height: the last layer's top
    bounds: tuple           # range k holds layers bounds[k] <= j < bounds[k + 1]
    offsets: tuple          # global index of each partition's first point, then the count
    options: dict           # stream keywords: skip_invalid, surface_flips, open_ends

    @property
    def layer_count(self):
        return len(self.cuts) + 1

    @property
    def count(self):
        return self.offsets[-1]

    @property
    def index_dtype(self):
        """uint32 while every global index fits in it, else uint64."""
        return np.uint32 if self.count < 2**32 else np.uint64


def _unit(axis):
    if isinstance(axis, str):
        if axis not in _UNIT:
            raise Error("invalid_axis", STATUSES["invalid_axis"],
                        f"the stream needs axis 'x', 'y', 'z' or a 3-vector, not {axis!r}")
        return np.array(_UNIT[axis])
    v = np.asarray(axis, dtype=np.float64)
    norm = np.linalg.norm(v) if v.shape == (3,) else 0.0
    if not np.isfinite(norm) or norm == 0.0:
        raise Error("invalid_axis", STATUSES["invalid_axis"], f"no direction in {axis!r}")
    return v / norm


def _partitions(points):
    """The cloud as a list of delayed (n_i, 3) arrays, in the global order."""
    if isinstance(points, da.Array):
        if points.ndim != 2 or points.shape[1] != 3 or len(points.chunks[1]) != 1:
            raise Error("invalid_argument", STATUSES["invalid_argument"],
                        "a dask array of points has shape (n, 3) and is chunked by rows only")
        return list(points.to_delayed().ravel())
    return [dask.delayed(np.load)(p, mmap_mode="r") if isinstance(p, str)
            else dask.delayed(p) for p in points]


def _summary(part, unit, skip_invalid):
    """Count, height range and coordinate sum of one partition (of its finite points)."""
    part = np.asarray(part, dtype=np.float64)
    finite = np.isfinite(part).all(axis=1)
    if not skip_invalid and not finite.all():
        raise Error("invalid_point", STATUSES["invalid_point"],
                    "a coordinate is NaN or infinite (skip_invalid=True skips such points)")
    good = part[finite]
    h = good @ unit
    low, high = (h.min(), h.max()) if len(h) else (np.inf, -np.inf)
    return len(part), low, high, good.sum(axis=0), len(good)


def plan(points, *, axis, layer_height=None, layers=None, ranges=None, skip_invalid=False,
         surface_flips=False, open_ends=False):
    """Measures the cloud in parallel and fixes the layers, the ranges and the origin.

    layers: that many equal layers over the cloud's height; else layer_height: the nearest
    whole number of equal layers of about that height. ranges: how many ranges of whole
    layers are meshed in parallel (default: one per partition, at most one per layer).
    """
    unit = _unit(axis)
    parts = _partitions(points)
    stats = dask.compute(*[dask.delayed(_summary)(p, unit, skip_invalid) for p in parts])
    counts = [s[0] for s in stats]
    low = min(s[1] for s in stats)
    high = max(s[2] for s in stats)
    valid = sum(s[4] for s in stats)
    if valid < 3:
        raise Error("too_few_points", STATUSES["too_few_points"], f"{valid} valid points")
    if not high > low:
        raise Error("flat_cloud", STATUSES["flat_cloud"], "every point at one height")
    # Summed in partition order, so the origin is the same bits on every run.
    origin = tuple(float(c) for c in np.sum([s[3] for s in stats], axis=0) / valid)
    if layers is None:
        if layer_height is None or not layer_height > 0:
            raise Error("invalid_layers", STATUSES["invalid_layers"],
                        "give layers or a positive layer_height")
        layers = max(1, int(round((high - low) / layer_height)))
    layers = int(layers)
    if layers < 1:
        raise Error("invalid_layers", STATUSES["invalid_layers"], "layers must be 1 or more")
    cuts = low + (high - low) * np.arange(1, layers) / layers
    ranges = min(layers, len(parts) if ranges is None else int(ranges))
    if ranges < 1:
        raise Error("invalid_argument", STATUSES["invalid_argument"], "ranges must be 1 or more")
    bounds = tuple(int(b) for b in np.linspace(0, layers, ranges + 1).round())
    return Plan(axis=axis, unit=tuple(unit), origin=origin, cuts=cuts,
                height_min=float(low), height_max=float(high), bounds=bounds,
                offsets=tuple(int(o) for o in np.cumsum([0] + counts)),
                options={"skip_invalid": skip_invalid, "surface_flips": surface_flips,
                         "open_ends": open_ends})


def layer_of(points, plan):
    """Each point's layer: the number of cuts at or below it (a point on a cut is above it).
    NaN heights land past the last layer and are pushed with it (the stream skips them)."""
    heights = np.asarray(points, dtype=np.float64) @ np.array(plan.unit)
    return np.searchsorted(plan.cuts, heights, side="right")


def _split(part, offset, plan):
    """One partition cut into the pieces each range needs, as (points, global indices): its
    own layers and one more on each side (the layers that the bands at its edges join to)."""
    part = np.asarray(part)
    layer = layer_of(part, plan)
    index = np.arange(offset, offset + len(part), dtype=plan.index_dtype)
    pieces = []
    for lo, hi in zip(plan.bounds[:-1], plan.bounds[1:]):
        take = (layer >= lo - 1) & (layer <= hi)
        pieces.append((part[take], index[take]))
    return pieces


def _stream_span(points, starts, first, plan, max_points):
    """Pushes layers first, first + 1, ... (layer first + i is points[starts[i]:starts[i+1]])
    into one stream; returns the triangles with indices into points, and its report."""
    stream = Stream(axis=plan.axis, max_points=max_points, origin=plan.origin,
                    layer_info=plan.layer_count, **plan.options)
    out = []
    for i in range(len(starts) - 1):
        j = first + i
        top = plan.cuts[j] if j < len(plan.cuts) else plan.height_max
        out.append(stream.push(points[starts[i]:starts[i + 1]], top))
    out.append(stream.close())
    return np.concatenate(out), stream.report


def _check_edges(report, lo, hi, first, last, plan):
    """The union equals one stream's triangles when the layers at the range's edges stand
    on their own as they do there: no push merged across an edge cut, no edge taken for
    the object's closed end. Raises otherwise."""
    tops = np.array([layer.top for layer in report.layers.info])
    for c in (lo - 1, lo, hi - 2, hi - 1):
        if not first <= c < last:
            continue
        # The report's tops come back from the stream's frame, rounded.
        tolerance = 1e-9 * (plan.height_max - plan.height_min + abs(plan.cuts[c]))
        if not (abs(tops - plan.cuts[c]) <= tolerance).any():
            raise Error("invalid_layers", STATUSES["invalid_layers"],
                        f"the layer below height {plan.cuts[c]} merged with its neighbour at "
                        "a range's edge: choose a larger layer_height or fewer ranges")
    info = report.layers.info
    if ((first < lo and info[0].closed_ends & _CLOSED_BOTTOM)
            or (last > hi - 1 and info[-1].closed_ends & _CLOSED_TOP)):
        raise Error("not_columnar", STATUSES["not_columnar"],
                    "a range's edge was taken for a closed end: mesh with open_ends=True")


def _mesh_range(k, plan, *pieces):
    """Meshes range k's layers; keeps each triangle whose highest layer is in the range, so
    the band between two ranges is the upper one's. Returns global indices."""
    lo, hi = plan.bounds[k], plan.bounds[k + 1]
    first, last = max(lo - 1, 0), min(hi, plan.layer_count - 1)
    points = np.concatenate([p[0] for p in pieces])
    index = np.concatenate([p[1] for p in pieces])
    layer = layer_of(points, plan)
    # Stable: within a layer the points keep the global order, as one stream would get them.
    order = np.argsort(layer, kind="stable")
    points, index = points[order], index[order]
    sizes = np.bincount(layer - first, minlength=last - first + 1)
    starts = np.concatenate([[0], np.cumsum(sizes)])
    held = max(_LEAST_HELD, min(len(points), 3 * int(sizes.max())))
    try:
        local, report = _stream_span(points, starts, first, plan, held)
    except Error as e:
        if e.status != "out_of_memory":
            raise
        # Merged pushes held more than three layers' worth: hold the whole span.
        local, report = _stream_span(points, starts, first, plan, max(_LEAST_HELD, len(points)))
    _check_edges(report, lo, hi, first, last, plan)
    # The points are in layer order, so a triangle's highest layer is its highest index's.
    top = local.max(axis=1)
    kept = local[(top >= starts[lo - first]) & (top < starts[hi - first])]
    return index[kept]


def mesh(points, plan):
    """The triangles as a lazy dask array (m, 3) of global indices, one chunk per range."""
    parts = _partitions(points)
    ranges = len(plan.bounds) - 1
    pieces = [dask.delayed(_split, nout=ranges)(p, plan.offsets[i], plan)
              for i, p in enumerate(parts)]
    chunks = [da.from_delayed(dask.delayed(_mesh_range)(k, plan, *[pc[k] for pc in pieces]),
                              shape=(np.nan, 3), dtype=plan.index_dtype)
              for k in range(ranges)]
    return da.concatenate(chunks, axis=0)
