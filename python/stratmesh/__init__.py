"""stratmesh for Python: meshes columnar point clouds given as numpy arrays.

    triangles, report = stratmesh.reconstruct(points, axis="z", layers=8)

points is any (n, 3) float32 or float64 array; triangles is an (m, 3) uint32 array of
indices into it, counter-clockwise seen from outside. See docs/python.md.
"""
import os

from . import _check, _core
from ._error import ArgumentTypeError, Error

Error.__module__ = __name__  # shown as stratmesh.Error, where users catch it
ArgumentTypeError.__module__ = __name__

__all__ = ["ArgumentTypeError", "Error", "FLAGS", "PARTS", "POOR_MISFIT_FRACTION", "STATUSES",
           "Stream", "Workspace", "cap_ends", "reconstruct", "stream_workspace_size"]
__version__ = _core.__version__

#: The library's Flags bits by name; flags=(...) accepts any of them.
FLAGS = dict(_core.FLAGS)
#: The library's Parts values by name; parts="..." accepts any of them.
PARTS = dict(_core.PARTS)
#: Every status name with its one-line explanation.
STATUSES = dict(_core.STATUSES)
#: A surface with a crossing pair, or whose diagnostics.misfit_area_fraction exceeds this,
#: is poor (the command line's verdict).
POOR_MISFIT_FRACTION = _core.POOR_MISFIT_FRACTION


class Workspace(_core.Workspace):
    """A workspace that reconstruct(..., workspace=w) keeps between calls: its memory,
    touched once, costs no page faults the next time. It grows to the largest call's need
    (w.size bytes) and is freed with the object; one call uses it at a time."""

    @_check.signature_checked
    def __init__(self):
        super().__init__()


_AXIS_CODES = {"auto": 0, "x": 1, "y": 2, "z": 3}
_DIRECTION = 4
# Each keyword that sets one flag, with that flag's name.
_SWITCHES = {"cap": "add_caps", "skip_invalid": "skip_invalid_points",
             "drop_outliers": "drop_outliers", "surface_flips": "surface_flips",
             "ends_are_cuts": "ends_are_cuts"}
_MOST_THREADS = 2**32 - 1     # the binding counts threads in an unsigned
_MOST_LAYERS = 2**32 - 1      # Options::layer_count is a uint32_t
_LEAST_HELD = 16              # the fewest points a stream's workspace holds
_MOST_HELD = 2**32 - 3        # the most: 32-bit indices, two values reserved
_MOST_STREAM_LAYERS = 2**28   # a stream's layers hold 16 points or more
_NOT_STREAMED = ("add_caps", "drop_outliers")  # flags the stream refuses


def _flag_bits(flags, switches, refused):
    """The Flags bits of flags (names) and of the switch keywords that are True."""
    names = _check.flag_names(flags, refused)
    names += [_SWITCHES[k] for k, on in switches.items() if _check.switch(k, on)]
    bits = 0
    for name in names:
        bits |= FLAGS[name]
    return bits


def _options(axis="auto", cuts=None, layers=0, layer_height=0.0, origin=None, threads=1,
             flags=(), refused=(), automatic=True, parts="automatic", **switches):
    """The options dict _core reads, every value checked; switches are the keywords of
    _SWITCHES."""
    name, direction = _check.direction(axis, automatic)
    bits = _flag_bits(flags, switches, refused)
    if origin is not None:
        origin = _check.vector("origin", origin, "invalid_argument")
        bits |= FLAGS["origin_given"]
    threads = _check.whole("threads", threads, 0, _MOST_THREADS)
    cuts = None if cuts is None else _check.heights("cuts", cuts, "invalid_layers")
    layers = _check.whole("layers", layers, 0, _MOST_LAYERS, "invalid_layers")
    layer_height = _check.real("layer_height", layer_height, "invalid_layers", "from 0")
    _check.one_layering(cuts is not None and len(cuts) > 0, layers > 0, layer_height > 0)
    return {
        "axis": _AXIS_CODES[name] if name else _DIRECTION,
        "direction": direction,
        "cuts": cuts,
        "layer_count": layers,
        "layer_height": layer_height,
        "flags": bits,
        "parts": _check.choice("parts", parts, PARTS),
        "origin": (0.0, 0.0, 0.0) if origin is None else origin,
        "threads": threads or (os.cpu_count() or 1),
    }


@_check.signature_checked
def reconstruct(points, *, axis="auto", cuts=None, layers=0, layer_height=0.0, cap=False,
                skip_invalid=False, drop_outliers=False, surface_flips=False,
                ends_are_cuts=False, parts="automatic", origin=None, threads=1, progress=None,
                flags=(), copy=True, workspace=None):
    """Meshes a columnar cloud; returns (triangles, report).

    points         (n, 3) float32 or float64. Read in place when each point's x, y, z are
                   adjacent in memory (any row stride: a view of wider records is fine);
                   otherwise copied first, or refused with copy=False.
    axis           "auto", "x", "y", "z" or a 3-vector of any finite non-zero length.
    cuts           a one-dimensional sequence of finite heights along the axis where layers
                   start; or layers equal layers; or layers of about layer_height (a finite
                   number from 0); at most one of the three; without any, the library's
                   automatic layers.
    cap            close the tube's ends (the add_caps flag).
    skip_invalid, drop_outliers, surface_flips, ends_are_cuts
                   the flags of the same names (skip_invalid: skip_invalid_points).
    parts          where the cloud parts into branches: "automatic" (look, join the parts,
                   keep them where whole and smaller than one tube), "one_tube" (do not
                   look) or "apart" (keep the parts, joined where they can be): the keys
                   of stratmesh.PARTS.
    origin         the frame's reference point, 3 finite numbers (sets origin_given).
    threads        the layers are triangulated on this many threads (0: one per core); the
                   triangles are the same bytes for any number.
    progress       callable(phase, fraction), called with the GIL held.
    flags          more flags: a sequence of names, keys of stratmesh.FLAGS.
    workspace      a stratmesh.Workspace to reuse; by default each call allocates its own.

    The switches (cap, ..., ends_are_cuts, copy) take True or False, the counts (layers,
    threads) integers.
    triangles is an (m, 3) uint32 array of indices into points; report a namespace with
    status, triangle_count, axis, axis_origin and the groups points, layers, caps, parts,
    diagnostics, then detail and workspace_used_bytes. Any refusal raises stratmesh.Error
    (ArgumentTypeError, also a TypeError, for an argument of the wrong type).
    """
    options = _options(axis, cuts, layers, layer_height, origin, threads, flags, parts=parts,
                       cap=cap, skip_invalid=skip_invalid, drop_outliers=drop_outliers,
                       surface_flips=surface_flips, ends_are_cuts=ends_are_cuts)
    progress = _check.optional_callable("progress", progress)
    if workspace is not None:
        _check.instance("workspace", workspace, Workspace, "a stratmesh.Workspace or None")
    return _core.reconstruct(points, options, progress, _check.switch("copy", copy), workspace)


@_check.signature_checked
def cap_ends(points, triangles, *, axis="z", origin=None, skip_invalid=False, flags=(),
             copy=True):
    """Closes the boundary loops of a surface over points (a stream's, say) with caps.

    triangles is an (m, 3) array of integer indices into points. Returns (triangles with
    the caps appended, report). With the options the stream had and every point it was
    given, in order, the result is reconstruct()'s with cap=True for the same cuts.
    """
    options = _options(axis, origin=origin, flags=flags, skip_invalid=skip_invalid)
    triangles = _check.indices("triangles", triangles)
    return _core.cap_ends(points, triangles, options, _check.switch("copy", copy))


@_check.signature_checked
def stream_workspace_size(max_points, *, axis="z", surface_flips=False, ends_are_cuts=False):
    """Bytes of workspace a Stream holding at most max_points points at once allocates."""
    options = _options(axis, automatic=False, surface_flips=surface_flips,
                       ends_are_cuts=ends_are_cuts)
    held = _check.whole("max_points", max_points, 0, _MOST_HELD)
    return _core.stream_workspace_size(held, options)


class Stream:
    """Meshes a cloud pushed layer by layer, bottom to top along the axis.

        stream = stratmesh.Stream(axis="z", max_points=3 * largest_layer)
        for layer, top in layers:
            mesh.append(stream.push(layer, top))   # triangles final so far
        mesh.append(stream.close())

    Each push and the close return the triangles that became final, as (m, 3) uint32
    global indices (the position among all points pushed). max_points bounds the points
    held at once (three times the largest push suffices for pushes of 16 points or more,
    1.5 rows thick); layer_info, how many layers' details the report keeps. The stream
    gives reconstruct()'s triangles for cuts at the pushes' tops when both are given the
    same origin (see docs/python.md).
    """

    @_check.signature_checked
    def __init__(self, *, axis, max_points, origin=None, skip_invalid=False,
                 surface_flips=False, ends_are_cuts=False, flags=(), layer_info=256):
        options = _options(axis, origin=origin, flags=flags, refused=_NOT_STREAMED,
                           automatic=False, skip_invalid=skip_invalid,
                           surface_flips=surface_flips, ends_are_cuts=ends_are_cuts)
        held = _check.whole("max_points", max_points, _LEAST_HELD, _MOST_HELD)
        layer_info = _check.whole("layer_info", layer_info, 0, _MOST_STREAM_LAYERS)
        self._stream = _core.Stream(options, held, layer_info)

    @_check.signature_checked
    def push(self, points, top, *, copy=True):
        """Pushes one layer (points between the previous top and this one)."""
        top = _check.real("top", top, "invalid_layers")
        return self._stream.push(points, top, _check.switch("copy", copy))

    @_check.signature_checked
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
