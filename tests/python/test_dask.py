import numpy as np
import pytest

import stratmesh
from conftest import assert_manifold, bumpy_tube, canonical

dask = pytest.importorskip("dask")
distributed = pytest.importorskip("distributed")
import dask.array as da  # noqa: E402

import stratmesh.dask as smd  # noqa: E402


def one_stream(cloud, plan):
    """One machine's stream over the whole cloud with the plan's layers and origin: the
    points pushed layer by layer, each layer in the global order; global indices back."""
    layer = np.searchsorted(plan.cuts, cloud.astype(np.float64) @ np.array(plan.unit),
                            side="right")
    order = np.argsort(layer, kind="stable")
    stream = stratmesh.Stream(axis=plan.axis, max_points=len(cloud), origin=plan.origin,
                              **plan.options)
    out = []
    for j in range(plan.layer_count):
        top = plan.cuts[j] if j < len(plan.cuts) else plan.height_max
        out.append(stream.push(cloud[order[layer[order] == j]], top))
    out.append(stream.close())
    return order[np.concatenate(out)]


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                       dashboard_address=None)
    with distributed.Client(cluster) as c:
        yield c
    cluster.close()


def test_a_cluster_gives_one_streams_triangles(client):
    cloud = bumpy_tube(2_000_000, seed=11)
    points = da.from_array(cloud, chunks=(250_000, 3))  # 8 partitions, each all heights
    plan = smd.plan(points, axis="z", layer_height=0.25, ranges=8)
    assert plan.count == len(cloud) and plan.layer_count == 25
    triangles = smd.mesh(points, plan).compute()
    expected = one_stream(cloud, plan)
    assert triangles.dtype == np.uint32
    assert len(triangles) == len(expected) > 1.99 * len(cloud)
    assert np.array_equal(canonical(triangles), canonical(expected))
    assert_manifold(triangles)


def test_files_and_float32_partitions(tmp_path):
    cloud = bumpy_tube(120_000, seed=3, dtype=np.float32)
    paths = []
    for i, part in enumerate(np.array_split(cloud, 5)):
        paths.append(str(tmp_path / f"part{i}.npy"))
        np.save(paths[-1], part)
    with dask.config.set(scheduler="sync"):
        plan = smd.plan(paths, axis="z", layers=12, ranges=4, surface_flips=True)
        triangles = smd.mesh(paths, plan).compute()
    assert plan.offsets == (0, 24_000, 48_000, 72_000, 96_000, 120_000)
    assert np.array_equal(canonical(triangles), canonical(one_stream(cloud, plan)))


def test_without_the_layer_beyond_each_edge_the_union_differs(monkeypatch):
    # The control: ranges that do not push the next range's first layer miss the flips
    # and peeling the band above makes in their last layer, and the equality fails.
    cloud = bumpy_tube(100_000, seed=5)
    parts = np.array_split(cloud, 4)
    split = smd._split

    def split_short(part, offset, plan):
        short = []
        for (p, i), hi in zip(split(part, offset, plan), plan.bounds[1:]):
            below = smd.layer_of(p, plan) < hi
            short.append((p[below], i[below]))
        return short

    with dask.config.set(scheduler="sync"):
        plan = smd.plan(parts, axis="z", layers=16, ranges=4, surface_flips=True)
        monkeypatch.setattr(smd, "_split", split_short)
        # An empty layer beyond the edge fails the edge check first; the triangles are the point.
        monkeypatch.setattr(smd, "_check_edges", lambda *args: None)
        short = smd.mesh(parts, plan).compute()
    expected = one_stream(cloud, plan)
    assert not np.array_equal(canonical(short), canonical(expected))


def test_layers_too_thin_to_stand_alone_at_an_edge_are_refused(client):
    # Raised on a worker, the error reaches the client whole.
    cloud = bumpy_tube(60_000, seed=5)
    plan = smd.plan([cloud], axis="z", layers=400, ranges=4)
    with pytest.raises(stratmesh.Error) as e:
        smd.mesh([cloud], plan).compute()
    assert e.value.status == "invalid_layers"
    assert "merged" in e.value.detail


def test_plan_refusals():
    with pytest.raises(stratmesh.Error) as e:
        smd.plan([bumpy_tube(100)], axis="auto", layers=2)
    assert e.value.status == "invalid_axis"
    with pytest.raises(stratmesh.Error) as e:
        smd.plan([bumpy_tube(100)], axis="z")
    assert e.value.status == "invalid_layers"
    nan = bumpy_tube(100)
    nan[5, 0] = np.nan
    with dask.config.set(scheduler="sync"):
        with pytest.raises(stratmesh.Error) as e:
            smd.plan([nan], axis="z", layers=2)
    assert e.value.status == "invalid_point"
