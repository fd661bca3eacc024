"""stratmesh for Python: meshes columnar point clouds given as numpy arrays.

    triangles, report = stratmesh.reconstruct(points, axis="z", layers=8)

points is any (n, 3) float32 or float64 array; triangles is an (m, 3) uint32 array of
indices into it, counter-clockwise seen from outside. See docs/python.md.
"""
import os

import numpy as np

from . import _core
from ._error import Error

Error.__module__ = __name__  # shown as stratmesh.Error, where users catch it

__all__ = ["Error", "FLAGS", "STATUSES", "Stream", "Workspace", "cap_ends", "reconstruct",
           "stream_workspace_size"]
__version__ = _core.__version__

#: The library's Flags bits by name; flags=(...) accepts any of them.
FLAGS = dict(_core.FLAGS)
#: Every status name with its one-line explanation.
STATUSES = dict(_core.STATUSES)

#: A workspace that reconstruct(..., workspace=w) keeps between calls: its memory, touched
#: once, costs no page faults the next time. It grows to the largest call's need (w.size
#: bytes) and is freed with the object; one call uses it at a time.
Workspace = _core.Workspace

_AXES = {"auto": 0, "x": 1, "y": 2, "z": 3}
_DIRECTION = 4


def _axis(axis):
    if isinstance(axis, str):
        if axis not in _AXES:
            raise Error("invalid_axis", STATUSES["invalid_axis"],
                        f"axis must be 'auto', 'x', 'y', 'z' or a 3-vector, not {axis!r}")
        return _AXES[axis], (0.0, 0.0, 0.0)
    direction = np.asarray(axis, dtype=np.float64)
    if direction.shape != (3,):
        raise Error("invalid_axis", STATUSES["invalid_axis"],
                    f"an axis direction has 3 components, not shape {direction.shape}")
    return _DIRECTION, tuple(float(c) for c in direction)


def _options(axis="auto", cuts=None, layers=0, layer_height=0.0, origin=None, threads=1,
             flags=(), **named):
    """The options dict _core reads; named are the keyword flags (True/False) by name."""
    code, direction = _axis(axis)
    bits = 0
    for name in list(flags) + [n for n, on in named.items() if on]:
        if name not in FLAGS:
            raise Error("invalid_argument", STATUSES["invalid_argument"],
                        f"unknown flag {name!r}; known: {', '.join(FLAGS)}")
        bits |= FLAGS[name]
    if origin is not None:
        bits |= FLAGS["origin_given"]
        origin = np.asarray(origin, dtype=np.float64)
        if origin.shape != (3,):
            raise Error("invalid_argument", STATUSES["invalid_argument"],
                        f"origin has 3 components, not shape {origin.shape}")
    if cuts is not None:
        cuts = np.ascontiguousarray(cuts, dtype=np.float64).reshape(-1)
    if int(layers) != layers or layers < 0 or layers >= 2**32:
        raise Error("invalid_layers", STATUSES["invalid_layers"],
                    f"layers must be a whole number from 0, not {layers!r}")
    if int(threads) != threads or threads < 0:
        raise Error("invalid_argument", STATUSES["invalid_argument"],
                    f"threads must be a whole number from 0, not {threads!r}")
    return {
        "axis": code,
        "direction": direction,
        "cuts": cuts,
        "layer_count": int(layers),
        "layer_height": float(layer_height),
        "flags": bits,
        "origin": (0.0, 0.0, 0.0) if origin is None else tuple(float(c) for c in origin),
        "threads": int(threads) or (os.cpu_count() or 1),
    }


def reconstruct(points, *, axis="auto", cuts=None, layers=0, layer_height=0.0, cap=False,
                skip_invalid=False, drop_outliers=False, surface_flips=False, open_ends=False,
                one_tube=False, keep_parts=False, origin=None, threads=1, progress=None,
                flags=(), copy=True, workspace=None):
    """Meshes a columnar cloud; returns (triangles, report).

    points         (n, 3) float32 or float64. Read in place when each point's x, y, z are
                   adjacent in memory (any row stride: a view of wider records is fine);
                   otherwise copied first, or refused with copy=False.
    axis           "auto", "x", "y", "z" or a 3-vector (Axis::direction).
    cuts           heights along the axis where layers start; else layers equal layers;
                   else layers of about layer_height; else the library's automatic layers.
    cap            close the tube's ends (the close_ends flag).
    skip_invalid, drop_outliers, surface_flips, open_ends, one_tube, keep_parts
                   the flags of the same names (skip_invalid: skip_invalid_points).
    origin         the frame's reference point (sets origin_given).
    threads        the layers are triangulated on this many threads (0: one per core); the
                   triangles are the same bytes for any number.
    progress       callable(phase, fraction), called with the GIL held.
    flags          more flags by name, any key of stratmesh.FLAGS.
    workspace      a stratmesh.Workspace to reuse; by default each call allocates its own.

    triangles is an (m, 3) uint32 array of indices into points; report a namespace with
    status, triangle_count, axis, axis_origin and the groups points, layers, caps, parts,
    diagnostics, then detail and workspace_used_bytes. A failure raises stratmesh.Error.
    """
    options = _options(axis, cuts, layers, layer_height, origin, threads, flags,
                       close_ends=cap, skip_invalid_points=skip_invalid,
                       drop_outliers=drop_outliers, surface_flips=surface_flips,
                       open_ends=open_ends, one_tube=one_tube, keep_parts=keep_parts)
    return _core.reconstruct(points, options, progress, copy, workspace)


def cap_ends(points, triangles, *, axis="z", origin=None, skip_invalid=False, flags=(),
             copy=True):
    """Closes the boundary loops of a surface over points (a stream's, say) with caps.

    Returns (triangles with the caps appended, report). With the options the stream had
    and every point it was given, in order, the result is reconstruct()'s with cap=True
    for the same cuts.
    """
    options = _options(axis, origin=origin, flags=flags, skip_invalid_points=skip_invalid)
    return _core.cap_ends(points, triangles, options, copy)


def stream_workspace_size(max_points, *, axis="z", surface_flips=False, open_ends=False):
    """Bytes of workspace a Stream holding at most max_points points at once allocates."""
    options = _options(axis, surface_flips=surface_flips, open_ends=open_ends)
    return _core.stream_workspace_size(int(max_points), options)


class Stream:
    """Meshes a cloud pushed layer by layer, bottom to top along the axis.

        stream = stratmesh.Stream(axis="z", max_points=3 * largest_layer)
        for layer, top in layers:
            mesh.append(stream.push(layer, top))   # triangles final so far
        mesh.append(stream.close())

    Each push and the close return the triangles that became final, as (m, 3) uint32
    global indices (the position among all points pushed). max_points bounds the points
    held at once (three times the largest push suffices for pushes of 16 points or more,
    1.5 rows thick). The stream gives reconstruct()'s triangles for cuts at the pushes'
    tops when both are given the same origin (see docs/python.md).
    """

    def __init__(self, *, axis, max_points, origin=None, skip_invalid=False,
                 surface_flips=False, open_ends=False, flags=(), layer_info=256):
        options = _options(axis, origin=origin, flags=flags, skip_invalid_points=skip_invalid,
                           surface_flips=surface_flips, open_ends=open_ends)
        self._stream = _core.Stream(options, int(max_points), int(layer_info))

    def push(self, points, top, *, copy=True):
        """Pushes one layer (points between the previous top and this one)."""
        return self._stream.push(points, float(top), copy)

    def close(self):
        """Forms the last layers; returns their triangles. No push may follow."""
        return self._stream.close()

    @property
    def report(self):
        """The report as of the last push or the close (layers: the first layer_info)."""
        return self._stream.report

    @property
    def closed(self):
        return self._stream.closed
