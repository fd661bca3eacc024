import numpy as np
import pytest

import stratmesh
from conftest import assert_manifold, bumpy_tube

CUTS = np.linspace(0, 2 * np.pi, 9)[1:-1]
ORIGIN = (0.0, 0.0, 3.0)


def layered_tube(n=40_000):
    """A tube sorted by layer (stable), with each point's layer."""
    cloud = bumpy_tube(n)
    layer = np.searchsorted(CUTS, cloud[:, 2], side="right")
    order = np.argsort(layer, kind="stable")
    return cloud[order], layer[order]


def stream_all(cloud, layer, **options):
    stream = stratmesh.Stream(axis="z", max_points=len(cloud), origin=ORIGIN, **options)
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
                                          surface_flips=flips, one_tube=True)
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
                                     one_tube=True)
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


def test_a_closed_stream_and_bad_options_raise():
    cloud, layer = layered_tube(4_000)
    with pytest.raises(stratmesh.Error) as e:
        stratmesh.Stream(axis="auto", max_points=100)
    assert e.value.status == "invalid_axis"
    stream = stratmesh.Stream(axis="z", max_points=len(cloud))
    stream.push(cloud, 7.0)
    stream.close()
    with pytest.raises(stratmesh.Error) as e:
        stream.push(cloud, 8.0)
    assert e.value.status == "invalid_argument"
    with pytest.raises(stratmesh.Error) as e:
        stratmesh.Stream(axis="z", max_points=100).push(cloud, 7.0)
    assert e.value.status == "out_of_memory"
