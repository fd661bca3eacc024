import numpy as np
import pytest

import stratmesh
from conftest import (WRONG_TYPE, WRONG_VALUE, assert_manifold, bumpy_tube, canonical,
                      refused_argument)

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

    def split_short(part, i, plan):
        short = []
        for (p, index), hi in zip(split(part, i, plan), plan.bounds[1:]):
            below = smd.layer_of(p, plan) < hi
            short.append((p[below], index[below]))
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


CLOUD = bumpy_tube(1_000)

PLAN_ARGUMENTS = [
    (WRONG_TYPE, "invalid_argument", "points", {"points": CLOUD}),
    (WRONG_TYPE, "invalid_argument", "points", {"points": "cloud.npy"}),
    (WRONG_TYPE, "invalid_argument", "points[1]", {"points": [CLOUD, 5]}),
    (WRONG_TYPE, "invalid_argument", "points[0]", {"points": [CLOUD.astype(np.int64)]}),
    (WRONG_VALUE, "invalid_argument", "points[0]", {"points": [CLOUD[:, :2]]}),
    (WRONG_VALUE, "invalid_argument", "points", {"points": da.from_array(CLOUD.ravel())}),
    (WRONG_VALUE, "invalid_argument", "points", {"points": da.from_array(CLOUD, chunks=(500, 2))}),
    (WRONG_VALUE, "invalid_axis", "axis", {"axis": "auto"}),
    (WRONG_VALUE, "invalid_axis", "axis", {"axis": (0, 0, 0)}),
    (WRONG_TYPE, "invalid_axis", "axis", {"axis": ("0", "0", "1")}),
    (WRONG_VALUE, "invalid_layers", "layers", {"layers": 0}),
    (WRONG_VALUE, "invalid_layers", "layers", {"layers": 2**28 + 1}),
    (WRONG_TYPE, "invalid_layers", "layers", {"layers": 2.0}),
    (WRONG_VALUE, "invalid_layers", "layers", {"layers": None}),
    (WRONG_VALUE, "invalid_layers", "layer_height", {"layers": None, "layer_height": 0.0}),
    (WRONG_VALUE, "invalid_layers", "layer_height", {"layers": None, "layer_height": np.nan}),
    (WRONG_TYPE, "invalid_layers", "layer_height", {"layers": None, "layer_height": "1"}),
    (WRONG_VALUE, "invalid_layers", "layer_height", {"layers": None, "layer_height": 1e-300}),
    (WRONG_VALUE, "invalid_argument", "ranges", {"ranges": 0}),
    (WRONG_TYPE, "invalid_argument", "ranges", {"ranges": 1.5}),
    (WRONG_TYPE, "invalid_argument", "skip_invalid", {"skip_invalid": "yes"}),
    (WRONG_TYPE, "invalid_argument", "surface_flips", {"surface_flips": 1}),
    (WRONG_TYPE, "invalid_argument", "ends_are_cuts", {"ends_are_cuts": None}),
    (WRONG_TYPE, "invalid_argument", "plan", {"layer": 2}),
]


@pytest.mark.parametrize("kind, status, name, changed", PLAN_ARGUMENTS)
def test_each_plan_argument_is_checked(kind, status, name, changed):
    arguments = {"points": [CLOUD], "axis": "z", "layers": 2, **changed}
    with dask.config.set(scheduler="sync"):
        refused_argument(kind, status, name, smd.plan, **arguments)


def test_plan_refuses_the_data_naming_the_partition(tmp_path):
    nan = CLOUD.copy()
    nan[5, 0] = np.nan
    integers = str(tmp_path / "integers.npy")
    np.save(integers, CLOUD.astype(np.int32))
    with dask.config.set(scheduler="sync"):
        refused_argument(WRONG_VALUE, "invalid_point", "points[1]", smd.plan, [CLOUD, nan],
                         axis="z", layers=2)
        refused_argument(WRONG_TYPE, "invalid_argument", "points[0]", smd.plan, [integers],
                         axis="z", layers=2)
        refused_argument(WRONG_VALUE, "too_few_points", "points", smd.plan, [], axis="z",
                         layers=2)


def test_mesh_takes_the_points_its_plan_measured():
    parts = np.array_split(CLOUD, 2)
    with dask.config.set(scheduler="sync"):
        plan = smd.plan(parts, axis="z", layers=2)
        refused_argument(WRONG_TYPE, "invalid_argument", "plan", smd.mesh, parts, vars(plan))
        refused_argument(WRONG_VALUE, "invalid_argument", "points", smd.mesh, parts[:1], plan)
        refused_argument(WRONG_VALUE, "invalid_argument", "points[1]",
                         lambda: smd.mesh([parts[0], parts[1][1:]], plan).compute())
        refused_argument(WRONG_TYPE, "invalid_argument", "plan", smd.layer_of, CLOUD, None)
        refused_argument(WRONG_VALUE, "invalid_argument", "points", smd.layer_of, CLOUD[:, :2],
                         plan)
        refused_argument(WRONG_TYPE, "invalid_argument", "points", smd.layer_of,
                         [[1.0, 2.0, 3.0], [4.0]], plan)


def test_an_axis_of_any_length_plans_along_the_unit_axis():
    with dask.config.set(scheduler="sync"):
        unit = smd.plan([CLOUD], axis="z", layers=4)
        for length in (1e200, 1e-300):
            scaled = smd.plan([CLOUD], axis=(0, 0, length), layers=4)
            assert scaled.unit == unit.unit == (0.0, 0.0, 1.0)
            assert np.array_equal(scaled.cuts, unit.cuts)
            assert np.array_equal(canonical(smd.mesh([CLOUD], scaled).compute()),
                                  canonical(smd.mesh([CLOUD], unit).compute()))
