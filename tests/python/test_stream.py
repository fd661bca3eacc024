import numpy as np
import pytest

import stratmesh
from conftest import WRONG_TYPE, WRONG_VALUE, assert_manifold, bumpy_tube, refused_argument

CUTS = np.linspace(0, 2 * np.pi, 9)[1:-1]
ORIGIN = (0.0, 0.0, 3.0)


def layered_tube(n=40_000):
    """A tube sorted by layer (stable), with each point's layer."""
    cloud = bumpy_tube(n)
    layer = np.searchsorted(CUTS, cloud[:, 2], side="right")
    order = np.argsort(layer, kind="stable")
    return cloud[order], layer[order]


def stream_all(cloud, layer, axis="z", **options):
    stream = stratmesh.Stream(axis=axis, max_points=len(cloud), origin=ORIGIN, **options)
    parts = []
    for j in range(len(CUTS) + 1):
        top = CUTS[j] if j < len(CUTS) else cloud[:, 2].max()
        parts.append(stream.push(cloud[layer == j], top))
    parts.append(stream.close())
    return parts, stream


@pytest.mark.parametrize("flips", [False, True])
def test_the_stream_gives_reconstructs_triangles(flips):
    cloud, layer = layered_tube()
    parts, stream = stream_all(cloud, layer, surface_flips=flips)
    streamed = np.concatenate(parts)
    whole, report = stratmesh.reconstruct(cloud, axis="z", cuts=CUTS, origin=ORIGIN,
                                          surface_flips=flips, parts="one_tube")
    assert stream.closed and stream.report.status == "ok"
    assert stream.report.layers.used_count == report.layers.used_count == len(CUTS) + 1
    assert np.array_equal(streamed, whole)
    assert_manifold(streamed)
    # Triangles leave while the cloud is still arriving, not all at the close.
    assert sum(len(p) for p in parts[:-2]) > 0


def test_cap_ends_on_the_stream_gives_reconstructs_caps():
    cloud, layer = layered_tube()
    streamed = np.concatenate(stream_all(cloud, layer)[0])
    capped, report = stratmesh.cap_ends(cloud, streamed, axis="z", origin=ORIGIN)
    whole, _ = stratmesh.reconstruct(cloud, axis="z", cuts=CUTS, origin=ORIGIN, cap=True,
                                     parts="one_tube")
    assert report.caps.closed_count == 2
    assert np.array_equal(capped, whole)


def test_the_stream_holds_only_a_few_layers():
    cloud, layer = layered_tube()
    largest = np.bincount(layer).max()
    _, stream = stream_all(cloud, layer)
    assert stream.report.points.held_count <= 3 * largest < len(cloud)
    small = stratmesh.Stream(axis="z", max_points=3 * largest, origin=ORIGIN)
    for j in range(len(CUTS) + 1):
        small.push(cloud[layer == j], CUTS[j] if j < len(CUTS) else 7.0)
    small.close()
    # The header's figure: about 190 bytes per point held.
    assert 150 < stratmesh.stream_workspace_size(10**6) / 10**6 < 250


def test_refused_pushes_leave_the_stream_usable():
    cloud, layer = layered_tube()
    stream = stratmesh.Stream(axis="z", max_points=len(cloud), origin=ORIGIN)
    stream.push(cloud[layer == 0], CUTS[0])
    with pytest.raises(stratmesh.Error) as e:
        stream.push(cloud[layer == 0], CUTS[1])
    assert e.value.status == "out_of_order"
    bad = cloud[layer == 1].copy()
    bad[3] = np.nan
    with pytest.raises(stratmesh.Error) as e:
        stream.push(bad, CUTS[1])
    assert e.value.status == "invalid_point"
    stream.push(cloud[layer == 1], CUTS[1])
    assert stream.report.points.in_count == (layer <= 1).sum()


def test_a_closed_stream_and_a_small_one_raise():
    cloud, layer = layered_tube(4_000)
    stream = stratmesh.Stream(axis="z", max_points=len(cloud))
    stream.push(cloud, 7.0)
    stream.close()
    with pytest.raises(stratmesh.Error) as e:
        stream.push(cloud, 8.0)
    assert e.value.status == "invalid_argument"
    with pytest.raises(stratmesh.Error) as e:
        stratmesh.Stream(axis="z", max_points=100).push(cloud, 7.0)
    assert e.value.status == "out_of_memory"


STREAM_OPTIONS = [
    (WRONG_VALUE, "invalid_axis", "axis", "auto"),
    (WRONG_VALUE, "invalid_axis", "axis", (0.0, 0.0, 0.0)),
    (WRONG_TYPE, "invalid_axis", "axis", None),
    (WRONG_VALUE, "invalid_argument", "max_points", 15),
    (WRONG_VALUE, "invalid_argument", "max_points", 2**32 - 2),
    (WRONG_TYPE, "invalid_argument", "max_points", 100.0),
    (WRONG_VALUE, "invalid_argument", "layer_info", -1),
    (WRONG_VALUE, "invalid_argument", "layer_info", 2**28 + 1),
    (WRONG_TYPE, "invalid_argument", "layer_info", "256"),
    (WRONG_VALUE, "invalid_argument", "flags", ("add_caps",)),
    (WRONG_VALUE, "invalid_argument", "flags", ("drop_outliers",)),
    (WRONG_TYPE, "invalid_argument", "flags", "ends_are_cuts"),
    (WRONG_VALUE, "invalid_argument", "origin", (0, np.inf, 0)),
    (WRONG_TYPE, "invalid_argument", "skip_invalid", "yes"),
    (WRONG_TYPE, "invalid_argument", "surface_flips", 1),
    (WRONG_TYPE, "invalid_argument", "ends_are_cuts", None),
]


@pytest.mark.parametrize("kind, status, name, value", STREAM_OPTIONS)
def test_each_stream_option_is_checked(kind, status, name, value):
    options = {"axis": "z", "max_points": 1000, name: value}
    refused_argument(kind, status, name, stratmesh.Stream, **options)


def test_a_push_checks_its_arguments_and_leaves_the_stream_usable():
    cloud, _ = layered_tube(4_000)
    stream = stratmesh.Stream(axis="z", max_points=len(cloud))
    for kind, status, name, args, kwargs in [
            (WRONG_VALUE, "invalid_layers", "top", (cloud, np.nan), {}),
            (WRONG_VALUE, "invalid_layers", "top", (cloud, -np.inf), {}),
            (WRONG_TYPE, "invalid_layers", "top", (cloud, "7"), {}),
            (WRONG_TYPE, "invalid_layers", "top", (cloud, None), {}),
            (WRONG_TYPE, "invalid_argument", "copy", (cloud, 7.0), {"copy": "no"}),
            (WRONG_TYPE, "invalid_argument", "points", (cloud.astype(np.int32), 7.0), {}),
            (WRONG_VALUE, "invalid_argument", "points", (cloud[:, :2], 7.0), {}),
            (WRONG_TYPE, "invalid_argument", "Stream.push", (cloud,), {"tops": 7.0})]:
        refused_argument(kind, status, name, stream.push, *args, **kwargs)
    stream.push(cloud, 7.0)
    assert stream.report.points.in_count == len(cloud)
    refused_argument(WRONG_TYPE, "invalid_argument", "Stream.close", stream.close, True)


def test_stream_workspace_size_checks_its_arguments():
    size = stratmesh.stream_workspace_size
    refused_argument(WRONG_VALUE, "invalid_argument", "max_points", size, -1)
    refused_argument(WRONG_VALUE, "invalid_argument", "max_points", size, 2**32 - 2)
    refused_argument(WRONG_TYPE, "invalid_argument", "max_points", size, "10")
    refused_argument(WRONG_VALUE, "invalid_axis", "axis", size, 10, axis="auto")
    refused_argument(WRONG_TYPE, "invalid_argument", "ends_are_cuts", size, 10, ends_are_cuts="yes")
    assert size(2**32 - 3) > size(10) > 0


@pytest.mark.parametrize("length", [1e200, 1e-300])
def test_an_axis_of_any_length_streams_as_the_unit_axis(length):
    cloud, layer = layered_tube(8_000)
    unit, _ = stream_all(cloud, layer)
    scaled, stream = stream_all(cloud, layer, axis=(0.0, 0.0, length))
    assert stream.report.axis == (0.0, 0.0, 1.0)
    assert np.array_equal(np.concatenate(scaled), np.concatenate(unit))
