import pickle

import numpy as np
import pytest
from numpy.lib.stride_tricks import as_strided

import stratmesh
from conftest import WRONG_TYPE, WRONG_VALUE, bumpy_tube, refused_argument

CLOUD = bumpy_tube(2_000)


def refused(status, *args, **kwargs):
    with pytest.raises(stratmesh.Error) as e:
        stratmesh.reconstruct(*args, **kwargs)
    assert e.value.status == status
    assert isinstance(e.value, ValueError)
    assert str(e.value).startswith(status + ":")
    return e.value


def test_nan_is_refused_with_its_index():
    cloud = CLOUD.copy()
    cloud[123, 2] = np.nan
    error = refused("invalid_point", cloud, axis="z")
    assert error.report.points.first_invalid_index == 123
    assert error.detail


def test_too_few_points_and_flat_clouds():
    refused("too_few_points", CLOUD[:2], axis="z")
    refused("too_few_points", np.empty((0, 3)), axis="z")
    flat = CLOUD.copy()
    flat[:, 2] = 1.0
    refused("flat_cloud", flat, axis="z")


POINTS = [
    (WRONG_VALUE, CLOUD[:, :2]),
    (WRONG_VALUE, CLOUD.ravel()),
    (WRONG_TYPE, CLOUD.astype(np.int64)),
    (WRONG_TYPE, CLOUD.astype(np.float16)),
    (WRONG_TYPE, "not points"),
    (WRONG_TYPE, None),
    (WRONG_TYPE, [[0.0, 1.0, 2.0], [3.0, 4.0]]),
]


@pytest.mark.parametrize("kind, points", POINTS)
def test_points_of_the_wrong_type_or_shape(kind, points):
    refused_argument(kind, "invalid_argument", "points", stratmesh.reconstruct, points,
                     axis="z")


def test_points_that_need_a_copy_under_copy_false():
    refused_argument(WRONG_VALUE, "invalid_argument", "points", stratmesh.reconstruct,
                     np.asfortranarray(CLOUD), axis="z", copy=False)


def test_more_points_than_the_library_addresses():
    # A view that claims 2^32 rows: refused on its count, before anything reads it.
    huge = as_strided(CLOUD, shape=(2**32, 3), strides=(24, 8))
    refused_argument(WRONG_VALUE, "too_many_points", "points", stratmesh.reconstruct, huge,
                     axis="z", copy=False)


OPTIONS = [
    (WRONG_VALUE, "invalid_argument", "threads", 2**40),
    (WRONG_VALUE, "invalid_argument", "threads", -2),
    (WRONG_TYPE, "invalid_argument", "threads", 2.0),
    (WRONG_TYPE, "invalid_argument", "threads", "2"),
    (WRONG_VALUE, "invalid_layers", "layers", -1),
    (WRONG_VALUE, "invalid_layers", "layers", 2**32),
    (WRONG_TYPE, "invalid_layers", "layers", 2.5),
    (WRONG_TYPE, "invalid_layers", "layers", True),
    (WRONG_TYPE, "invalid_layers", "layers", "8"),
    (WRONG_VALUE, "invalid_layers", "layer_height", -1.0),
    (WRONG_VALUE, "invalid_layers", "layer_height", np.nan),
    (WRONG_VALUE, "invalid_layers", "layer_height", np.inf),
    (WRONG_TYPE, "invalid_layers", "layer_height", "1"),
    (WRONG_TYPE, "invalid_layers", "cuts", ["a"]),
    (WRONG_TYPE, "invalid_layers", "cuts", "1, 2"),
    (WRONG_TYPE, "invalid_layers", "cuts", [1.0, None]),
    (WRONG_TYPE, "invalid_layers", "cuts", [[1.0], [2.0, 3.0]]),
    (WRONG_VALUE, "invalid_layers", "cuts", [[1.0], [2.0]]),
    (WRONG_VALUE, "invalid_layers", "cuts", 1.5),
    (WRONG_VALUE, "invalid_layers", "cuts", [1.0, np.inf]),
    (WRONG_VALUE, "invalid_layers", "cuts", [np.nan]),
    (WRONG_VALUE, "invalid_axis", "axis", "w"),
    (WRONG_VALUE, "invalid_axis", "axis", (0, 0)),
    (WRONG_VALUE, "invalid_axis", "axis", (0, 0, 0)),
    (WRONG_VALUE, "invalid_axis", "axis", (np.nan, 0, 1)),
    (WRONG_VALUE, "invalid_axis", "axis", (np.inf, 0, 1)),
    (WRONG_VALUE, "invalid_axis", "axis", (10**400, 0, 1)),
    (WRONG_TYPE, "invalid_axis", "axis", None),
    (WRONG_TYPE, "invalid_axis", "axis", b"z"),
    (WRONG_TYPE, "invalid_axis", "axis", ("a", "b", "c")),
    (WRONG_TYPE, "invalid_axis", "axis", (1j, 0, 1)),
    (WRONG_VALUE, "invalid_argument", "origin", (np.nan, 0, 0)),
    (WRONG_VALUE, "invalid_argument", "origin", (0, 0)),
    (WRONG_TYPE, "invalid_argument", "origin", "abc"),
    (WRONG_TYPE, "invalid_argument", "flags", "add_caps"),
    (WRONG_TYPE, "invalid_argument", "flags", 3),
    (WRONG_TYPE, "invalid_argument", "flags", np.array(3.0)),
    (WRONG_TYPE, "invalid_argument", "flags", (1,)),
    (WRONG_VALUE, "invalid_argument", "flags", ("no_such_flag",)),
    (WRONG_TYPE, "invalid_argument", "progress", 5),
    (WRONG_TYPE, "invalid_argument", "workspace", bytearray(10)),
    (WRONG_TYPE, "invalid_argument", "copy", "no"),
    (WRONG_VALUE, "invalid_argument", "parts", "keep"),
    (WRONG_TYPE, "invalid_argument", "parts", 1),
    (WRONG_TYPE, "invalid_argument", "parts", None),
]


@pytest.mark.parametrize("kind, status, name, value", OPTIONS)
def test_each_option_is_checked_before_the_call(kind, status, name, value):
    options = {"axis": "z", name: value}
    refused_argument(kind, status, name, stratmesh.reconstruct, CLOUD, **options)


@pytest.mark.parametrize("name", ["cap", "skip_invalid", "drop_outliers", "surface_flips",
                                  "ends_are_cuts"])
@pytest.mark.parametrize("value", ["no", 1, None])
def test_switches_take_true_or_false(name, value):
    refused_argument(WRONG_TYPE, "invalid_argument", name, stratmesh.reconstruct, CLOUD, axis="z",
                     **{name: value})


@pytest.mark.parametrize("layering", [{"cuts": [1.0], "layers": 4},
                                      {"layers": 4, "layer_height": 2.0},
                                      {"cuts": [1.0], "layer_height": 2.0}])
def test_at_most_one_layer_option(layering):
    refused_argument(WRONG_VALUE, "invalid_argument", "cuts", stratmesh.reconstruct, CLOUD,
                     axis="z", **layering)


def test_a_call_that_does_not_fit_the_signature():
    for call, args, kwargs, named in [
            (stratmesh.reconstruct, (CLOUD,), {"axis": "z", "lyers": 4}, "'lyers'"),
            (stratmesh.reconstruct, (), {"axis": "z"}, "'points'"),
            (stratmesh.Stream, (), {"axis": "z"}, "'max_points'"),
            (stratmesh.Workspace, (1 << 20,), {}, "positional"),
            (stratmesh.cap_ends, (CLOUD,), {}, "'triangles'")]:
        with pytest.raises(WRONG_TYPE) as e:
            call(*args, **kwargs)
        assert e.value.status == "invalid_argument"
        assert named in e.value.detail and call.__qualname__ in e.value.detail


def test_axis_lengths_far_from_one_give_the_unit_axis_triangles():
    unit, report = stratmesh.reconstruct(CLOUD, axis=(0, 0, 1), layers=4)
    assert np.array_equal(unit, stratmesh.reconstruct(CLOUD, axis="z", layers=4)[0])
    for length in (1e200, 1e-300, 5e-324, 1.7e308):
        scaled, scaled_report = stratmesh.reconstruct(CLOUD, axis=(0, 0, length), layers=4)
        assert np.array_equal(scaled, unit)
        assert scaled_report.axis == report.axis == (0.0, 0.0, 1.0)


def test_a_tilted_axis_scaled_by_a_power_of_two_gives_the_same_triangles():
    tilted, report = stratmesh.reconstruct(CLOUD, axis=(0.3, 0, 4), layers=4)
    for scale in (2.0**660, 2.0**-990):
        scaled, scaled_report = stratmesh.reconstruct(CLOUD, axis=(0.3 * scale, 0, 4 * scale),
                                                      layers=4)
        assert scaled_report.axis == report.axis
        assert np.array_equal(scaled, tilted)


def test_cap_ends_checks_the_triangles():
    triangles, _ = stratmesh.reconstruct(CLOUD, axis="z", layers=4)
    for kind, value in [(WRONG_TYPE, triangles.astype(np.float64)), (WRONG_TYPE, "0 1 2"),
                        (WRONG_TYPE, None), (WRONG_VALUE, triangles[:, :2]),
                        (WRONG_VALUE, triangles.astype(np.int64) - 1)]:
        refused_argument(kind, "invalid_argument", "triangles", stratmesh.cap_ends, CLOUD,
                         value, axis="z")
    refused_argument(WRONG_VALUE, "invalid_axis", "axis", stratmesh.cap_ends, CLOUD, triangles,
                     axis="v")


def test_every_status_has_a_message():
    assert "ok" in stratmesh.STATUSES and "invalid_point" in stratmesh.STATUSES
    assert all(stratmesh.STATUSES.values())


def test_an_error_survives_pickling():
    cloud = CLOUD.copy()
    cloud[7, 0] = np.inf
    error = refused("invalid_point", cloud, axis="z")
    copy = pickle.loads(pickle.dumps(error))
    assert type(copy) is stratmesh.Error
    assert (copy.status, copy.detail, str(copy)) == (error.status, error.detail, str(error))
    assert copy.report.points.first_invalid_index == 7
    with pytest.raises(WRONG_TYPE) as e:
        stratmesh.reconstruct(CLOUD, axis="z", threads="2")
    copy = pickle.loads(pickle.dumps(e.value))
    assert type(copy) is WRONG_TYPE and str(copy) == str(e.value)
