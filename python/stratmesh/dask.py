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

from . import Error, Stream, _check
from ._check import refuse

_UNIT = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0)}
_CLOSED_BOTTOM, _CLOSED_TOP = 1, 2  # the header's ClosedEnd bits in LayerInfo::closed_ends
_LEAST_HELD = 16                    # a stream's workspace holds at least this many points
_MOST_LAYERS = 2**28                # the most a stream forms (and its layer_info keeps)


@dataclass(frozen=True)
class Plan:
    """What every worker needs to mesh its range in the same frame as the others."""

    axis: object            # as given to the streams: "x", "y", "z" or the unit vector
    unit: tuple             # the unit axis the heights are measured along
    origin: tuple           # the shared frame origin (the cloud's centroid)
    cuts: np.ndarray        # heights between layers: layer j lies in [cuts[j-1], cuts[j])
    height_min: float       # the lowest point's height
    height_max: float       # the highest point's height: the last layer's top
    bounds: tuple           # range k holds layers bounds[k] <= j < bounds[k + 1]
    offsets: tuple          # global index of each partition's first point, then the count
    options: dict           # stream keywords: skip_invalid, surface_flips, ends_are_cuts

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


def _partitions(points):
    """The cloud as a list of delayed (n_i, 3) arrays, in the global order."""
    if isinstance(points, da.Array):
        _check.cloud_array("points", points)
        if len(points.chunks[1]) != 1:
            raise refuse("invalid_argument", "points, a dask array, must be chunked by rows only")
        return list(points.to_delayed().ravel())
    if not isinstance(points, (list, tuple)):
        raise _check.must(_check.wrong_type, "invalid_argument", "points",
                          "a dask array or a list of partitions", points)
    for i, p in enumerate(points):
        if isinstance(_check.partition(f"points[{i}]", p), np.ndarray):
            _check.cloud_array(f"points[{i}]", p)
    return [dask.delayed(np.load)(p, mmap_mode="r") if not isinstance(p, np.ndarray)
            else dask.delayed(p) for p in points]


def _summary(part, i, unit, skip_invalid):
    """Count, height range and coordinate sum of partition i (of its finite points)."""
    part = np.asarray(_check.cloud(f"points[{i}]", part), dtype=np.float64)
    finite = np.isfinite(part).all(axis=1)
    if not skip_invalid and not finite.all():
        raise refuse("invalid_point", f"points[{i}]: a coordinate is NaN or infinite "
                     "(skip_invalid=True skips such points)")
    good = part[finite]
    h = good @ unit
    low, high = (h.min(), h.max()) if len(h) else (np.inf, -np.inf)
    return len(part), low, high, good.sum(axis=0), len(good)


def _layer_arguments(layers, layer_height):
    """layers and layer_height, checked; at least one is given."""
    if layers is not None:
        layers = _check.whole("layers", layers, 1, _MOST_LAYERS, "invalid_layers")
    if layer_height is not None:
        layer_height = _check.real("layer_height", layer_height, "invalid_layers", "above 0")
    elif layers is None:
        raise refuse("invalid_layers", "layers or layer_height must be given")
    return layers, layer_height


def _layer_count(low, high, layers, layer_height):
    """layers, or the whole number of equal layers nearest layer_height over [low, high]."""
    if layers is not None:
        return layers
    count = max(1.0, round((high - low) / layer_height))
    if count > _MOST_LAYERS:
        raise refuse("invalid_layers", f"layer_height {layer_height} makes {count:.3g} layers "
                     f"of the cloud's height {high - low:.6g}, more than 2^28")
    return int(count)


def _measure(parts, unit, skip_invalid):
    """The lowest and highest height, the centroid and each partition's point count."""
    stats = dask.compute(*[dask.delayed(_summary)(p, i, unit, skip_invalid)
                           for i, p in enumerate(parts)])
    valid = sum(s[4] for s in stats)
    if valid < 3:
        raise refuse("too_few_points", f"points: {valid} valid points")
    low = min(s[1] for s in stats)
    high = max(s[2] for s in stats)
    if not high > low:
        raise refuse("flat_cloud", "points: every point at one height")
    # Summed in partition order, so the origin is the same bits on every run.
    origin = tuple(float(c) for c in np.sum([s[3] for s in stats], axis=0) / valid)
    return low, high, origin, [s[0] for s in stats]


@_check.signature_checked
def plan(points, *, axis, layer_height=None, layers=None, ranges=None, skip_invalid=False,
         surface_flips=False, ends_are_cuts=False):
    """Measures the cloud in parallel and fixes the layers, the ranges and the origin.

    layers: that many equal layers over the cloud's height; else layer_height: the nearest
    whole number of equal layers of about that height. ranges: how many ranges of whole
    layers are meshed in parallel (default: one per partition, at most one per layer).
    """
    name, unit = _check.direction(axis, automatic=False)
    layers, layer_height = _layer_arguments(layers, layer_height)
    if ranges is not None:
        ranges = _check.whole("ranges", ranges, 1, _MOST_LAYERS)
    options = {"skip_invalid": _check.switch("skip_invalid", skip_invalid),
               "surface_flips": _check.switch("surface_flips", surface_flips),
               "ends_are_cuts": _check.switch("ends_are_cuts", ends_are_cuts)}
    parts = _partitions(points)
    unit = _UNIT[name] if name else unit
    low, high, origin, counts = _measure(parts, np.array(unit), options["skip_invalid"])
    layers = _layer_count(low, high, layers, layer_height)
    cuts = low + (high - low) * np.arange(1, layers) / layers
    ranges = min(layers, len(parts) if ranges is None else ranges)
    bounds = tuple(int(b) for b in np.linspace(0, layers, ranges + 1).round())
    return Plan(axis=name or unit, unit=unit, origin=origin, cuts=cuts,
                height_min=float(low), height_max=float(high), bounds=bounds,
                offsets=tuple(int(o) for o in np.cumsum([0] + counts)), options=options)


@_check.signature_checked
def layer_of(points, plan):
    """Each point's layer: the number of cuts at or below it (a point on a cut is above it).
    NaN heights land past the last layer and are pushed with it (the stream skips them)."""
    _check.instance("plan", plan, Plan, "a Plan from stratmesh.dask.plan()")
    points = _check.cloud("points", points)
    heights = points.astype(np.float64, copy=False) @ np.array(plan.unit)
    return np.searchsorted(plan.cuts, heights, side="right")


def _split(part, i, plan):
    """Partition i cut into the pieces each range needs, as (points, global indices): its
    own layers and one more on each side (the layers that the bands at its edges join to)."""
    part = np.asarray(part)
    offset, end = plan.offsets[i], plan.offsets[i + 1]
    if len(part) != end - offset:
        raise refuse("invalid_argument", f"points[{i}] has {len(part)} points where the plan "
                     f"counted {end - offset}: mesh() takes the points plan() measured")
    layer = layer_of(part, plan)
    index = np.arange(offset, end, dtype=plan.index_dtype)
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
            raise refuse("invalid_layers",
                         f"the layer below height {plan.cuts[c]} merged with its neighbour at "
                         "a range's edge: choose a larger layer_height or fewer ranges")
    info = report.layers.info
    if ((first < lo and info[0].closed_ends & _CLOSED_BOTTOM)
            or (last > hi - 1 and info[-1].closed_ends & _CLOSED_TOP)):
        raise refuse("not_columnar",
                     "a range's edge was taken for a closed end: mesh with ends_are_cuts=True")


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


@_check.signature_checked
def mesh(points, plan):
    """The triangles as a lazy dask array (m, 3) of global indices, one chunk per range.
    points are the partitions plan() measured, in the same order."""
    _check.instance("plan", plan, Plan, "a Plan from stratmesh.dask.plan()")
    parts = _partitions(points)
    if len(parts) != len(plan.offsets) - 1:
        raise refuse("invalid_argument", f"points has {len(parts)} partitions where the plan "
                     f"has {len(plan.offsets) - 1}: mesh() takes the points plan() measured")
    ranges = len(plan.bounds) - 1
    pieces = [dask.delayed(_split, nout=ranges)(p, i, plan) for i, p in enumerate(parts)]
    chunks = [da.from_delayed(dask.delayed(_mesh_range)(k, plan, *[pc[k] for pc in pieces]),
                              shape=(np.nan, 3), dtype=plan.index_dtype)
              for k in range(ranges)]
    return da.concatenate(chunks, axis=0)
