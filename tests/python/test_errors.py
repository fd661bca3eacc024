import pickle

import numpy as np
import pytest

import stratmesh
from conftest import bumpy_tube

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


def test_wrong_shapes_and_dtypes():
    refused("invalid_argument", CLOUD[:, :2], axis="z")
    refused("invalid_argument", CLOUD.ravel(), axis="z")
    refused("invalid_argument", CLOUD.astype(np.int64), axis="z")
    refused("invalid_argument", CLOUD.astype(np.float16), axis="z")
    refused("invalid_argument", "not points", axis="z")


def test_too_few_points_and_flat_clouds():
    refused("too_few_points", CLOUD[:2], axis="z")
    refused("too_few_points", np.empty((0, 3)), axis="z")
    flat = CLOUD.copy()
    flat[:, 2] = 1.0
    refused("flat_cloud", flat, axis="z")


def test_bad_options():
    refused("invalid_axis", CLOUD, axis="w")
    refused("invalid_axis", CLOUD, axis=(0, 0))
    refused("invalid_axis", CLOUD, axis=(0, 0, 0))
    refused("invalid_layers", CLOUD, axis="z", cuts=[np.inf])
    refused("invalid_layers", CLOUD, axis="z", layers=-1)
    refused("invalid_layers", CLOUD, axis="z", layer_height=-1.0)
    refused("invalid_argument", CLOUD, axis="z", origin=(np.nan, 0, 0))
    refused("invalid_argument", CLOUD, axis="z", flags=("no_such_flag",))
    refused("invalid_argument", CLOUD, axis="z", threads=-2)


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
