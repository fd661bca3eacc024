"""The arguments' checks, made before the library runs: each refusal names the argument.

A wrong type raises ArgumentTypeError (an Error and a TypeError), a wrong value Error (a
ValueError), with the status the library gives for that option (invalid_axis for axis,
invalid_layers for the layer options, invalid_argument for the rest).
"""
import functools
import inspect
import math
import numbers
import os
import reprlib

import numpy as np

from . import _core
from ._error import ArgumentTypeError, Error

STATUSES = dict(_core.STATUSES)
FLAGS = dict(_core.FLAGS)
AXES = ("x", "y", "z")
_BOOLS = (bool, np.bool_)


def refuse(status, detail):
    return Error(status, STATUSES[status], detail)


def wrong_type(status, detail):
    return ArgumentTypeError(status, STATUSES[status], detail)


def must(make, status, name, what, value):
    """make (refuse or wrong_type) for `name must be what, not value`, value shortened."""
    return make(status, f"{name} must be {what}, not {reprlib.repr(value)}")


def signature_checked(function):
    """function, refusing a call that does not fit its signature (an unknown keyword, a
    missing argument) with ArgumentTypeError rather than Python's TypeError."""
    signature = inspect.signature(function)

    @functools.wraps(function)
    def checked(*args, **kwargs):
        try:
            signature.bind(*args, **kwargs)
        except TypeError as e:
            raise wrong_type("invalid_argument", f"{function.__qualname__}(): {e}") from None
        return function(*args, **kwargs)

    return checked


def switch(name, value):
    """A keyword that is True or False."""
    if not isinstance(value, _BOOLS):
        raise must(wrong_type, "invalid_argument", name, "True or False", value)
    return bool(value)


def whole(name, value, low, high, status="invalid_argument"):
    """An integer (not a bool, not a float) from low to high."""
    what = f"a whole number from {low} to {high}"
    if isinstance(value, _BOOLS) or not isinstance(value, numbers.Integral):
        raise must(wrong_type, status, name, what, value)
    if not low <= value <= high:
        raise must(refuse, status, name, what, value)
    return int(value)


_BOUNDS = {"": lambda x: True, "from 0": lambda x: x >= 0, "above 0": lambda x: x > 0}


def real(name, value, status="invalid_argument", bound=""):
    """A finite real number within bound, a key of _BOUNDS."""
    what = f"a finite number {bound}".rstrip()
    if isinstance(value, _BOOLS) or not isinstance(value, numbers.Real):
        raise must(wrong_type, status, name, what, value)
    try:
        number = float(value)
    except OverflowError:
        number = math.inf
    if not (math.isfinite(number) and _BOUNDS[bound](number)):
        raise must(refuse, status, name, what, value)
    return number


def _is_real(x):
    return isinstance(x, numbers.Real) and not isinstance(x, _BOOLS)


def reals(name, value, status, what):
    """value as a float64 array of finite numbers, of any shape; what is what name takes."""
    if value is None or isinstance(value, (str, bytes)):
        raise must(wrong_type, status, name, what, value)
    try:
        array = np.asarray(value)
    except (TypeError, ValueError):  # ragged nesting
        raise must(wrong_type, status, name, what, value) from None
    if array.dtype.kind == "O" and all(_is_real(x) for x in array.flat):
        try:  # Python integers beyond 64 bits, Fractions
            array = array.astype(np.float64)
        except OverflowError:
            raise must(refuse, status, name, what + ", all finite", value) from None
    if array.dtype.kind not in "iuf":
        raise must(wrong_type, status, name, what, value)
    array = array.astype(np.float64)
    if not np.isfinite(array).all():
        raise must(refuse, status, name, what + ", all finite", value)
    return array


def vector(name, value, status, what="3 numbers"):
    """Three finite numbers, as a tuple of floats."""
    v = reals(name, value, status, what)
    if v.shape != (3,):
        raise must(refuse, status, name, what, value)
    return tuple(float(c) for c in v)


def direction(value, automatic=True):
    """axis: a name ("auto" where automatic) or a finite non-zero 3-vector of any length,
    as (name or None, unit vector). As the command-line tool does, the vector is scaled by a
    power of two (exactly) and then normalised, so that no square overflows or underflows."""
    names = ("auto",) + AXES if automatic else AXES
    what = ", ".join(repr(n) for n in names) + " or a non-zero 3-vector"
    if isinstance(value, str):
        if value not in names:
            raise must(refuse, "invalid_axis", "axis", what, value)
        return value, (0.0, 0.0, 0.0)
    v = vector("axis", value, "invalid_axis", what)
    largest = max(abs(c) for c in v)
    if largest == 0:
        raise must(refuse, "invalid_axis", "axis", what, value)
    exponent = math.frexp(largest)[1] - 1  # the largest component becomes 1 to 2
    v = [math.ldexp(c, -exponent) for c in v]
    length = math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    return None, tuple(c / length for c in v)


def heights(name, value, status):
    """A one-dimensional array of finite heights (float64, contiguous)."""
    what = "a one-dimensional sequence of heights"
    h = reals(name, value, status, what)
    if h.ndim != 1:
        raise refuse(status, f"{name} must be {what}, not of shape {h.shape}")
    return np.ascontiguousarray(h)


def flag_names(value, refused=()):
    """flags: a sequence of names from FLAGS (none of refused), not a string."""
    what = "a sequence of flag names such as ('ends_are_cuts',)"
    if isinstance(value, (str, bytes)):
        raise must(wrong_type, "invalid_argument", "flags", what, value)
    try:
        names = list(value)
    except TypeError:  # not iterable, as a number or a numpy array of no dimension
        raise must(wrong_type, "invalid_argument", "flags", what, value) from None
    for name in names:
        if not isinstance(name, str):
            raise must(wrong_type, "invalid_argument", "flags", what, value)
        if name not in FLAGS or name in refused:
            known = ", ".join(n for n in FLAGS if n not in refused)
            raise refuse("invalid_argument", f"flags: unknown flag {name!r}; known: {known}")
    return names


def choice(name, value, choices):
    """A name among the keys of choices, as its value."""
    what = " or ".join(repr(n) for n in choices)
    if not isinstance(value, str):
        raise must(wrong_type, "invalid_argument", name, what, value)
    if value not in choices:
        raise must(refuse, "invalid_argument", name, what, value)
    return choices[value]


def one_layering(cuts, layers, layer_height):
    """At most one of the layer options is given (each flag: whether it is)."""
    if cuts + layers + layer_height > 1:
        raise refuse("invalid_argument", "cuts, layers and layer_height: give at most one")


def optional_callable(name, value):
    if value is not None and not callable(value):
        raise must(wrong_type, "invalid_argument", name, "callable or None", value)
    return value


def instance(name, value, kind, what):
    if not isinstance(value, kind):
        raise must(wrong_type, "invalid_argument", name, what, value)
    return value


def partition(name, value):
    """A partition as given: a numpy array or the path of a .npy file."""
    what = "a numpy array or the path of a .npy file"
    return instance(name, value, (str, os.PathLike, np.ndarray), what)


def cloud(name, value):
    """value as an (n, 3) float32 or float64 array."""
    try:
        array = np.asarray(value)
    except (TypeError, ValueError):  # ragged nesting
        raise must(wrong_type, "invalid_argument", name, "an (n, 3) array", value) from None
    return cloud_array(name, array)


def cloud_array(name, array):
    """An (n, 3) float32 or float64 array (or dask array), as the library reads."""
    what = "an (n, 3) array of float32 or float64"
    if array.dtype.kind != "f" or array.dtype.itemsize not in (4, 8):
        raise wrong_type("invalid_argument", f"{name} must be {what}, not of {array.dtype}")
    if array.ndim != 2 or array.shape[1] != 3:
        raise refuse("invalid_argument", f"{name} must be {what}, not of shape {array.shape}")
    return array


def indices(name, value):
    """An (m, 3) array of integer point indices, as contiguous uint32."""
    what = "an (m, 3) array of integer point indices"
    if isinstance(value, (str, bytes)):
        raise must(wrong_type, "invalid_argument", name, what, value)
    try:
        array = np.asarray(value)
    except (TypeError, ValueError):
        raise must(wrong_type, "invalid_argument", name, what, value) from None
    if array.dtype.kind not in "iu":
        raise wrong_type("invalid_argument", f"{name} must be {what}, not of {array.dtype}")
    if array.ndim != 2 or array.shape[1] != 3:
        raise refuse("invalid_argument", f"{name} must be {what}, not of shape {array.shape}")
    if array.size and (array.min() < 0 or array.max() > 2**32 - 1):
        raise refuse("invalid_argument", f"{name} must hold indices from 0 to 2^32 - 1")
    return np.ascontiguousarray(array, dtype=np.uint32)
