"""Shared clouds and checks for the Python tests."""
import numpy as np
import pytest

import stratmesh

# The two kinds of refusal: an argument of the wrong type, or of a wrong value.
WRONG_TYPE, WRONG_VALUE = stratmesh.ArgumentTypeError, stratmesh.Error


def bumpy_tube(n, seed=7, height=2 * np.pi, dtype=np.float64):
    """Points on r = 1 + 0.25 sin(5 theta) cos(z), in random order."""
    rng = np.random.default_rng(seed)
    theta = rng.uniform(0, 2 * np.pi, n)
    z = rng.uniform(0, height, n)
    r = 1 + 0.25 * np.sin(5 * theta) * np.cos(z)
    return np.stack([r * np.cos(theta), r * np.sin(theta), z], axis=1).astype(dtype)


def canonical(triangles):
    """Each triangle rotated to start at its smallest index (orientation kept), rows sorted:
    equal arrays mean the same oriented triangles as a set."""
    t = np.asarray(triangles, dtype=np.int64)
    first = t.argmin(axis=1)
    rows = np.arange(len(t))
    rotated = np.stack([t[rows, (first + i) % 3] for i in range(3)], axis=1)
    return rotated[np.lexsort(rotated.T[::-1])]


def assert_manifold(triangles):
    """No directed edge twice (so two triangles on an edge run it in opposite directions),
    no undirected edge on three triangles or more."""
    t = np.asarray(triangles, dtype=np.int64)
    directed = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
    keys = directed[:, 0] * (2**32) + directed[:, 1]
    assert len(np.unique(keys)) == len(keys), "a directed edge repeats: orientation flips"
    undirected = np.sort(directed, axis=1)
    _, uses = np.unique(undirected[:, 0] * (2**32) + undirected[:, 1], return_counts=True)
    assert uses.max() <= 2, "an edge of three triangles or more"


def refused_argument(kind, status, name, call, *args, **kwargs):
    """call(*args, **kwargs) raises exactly kind with status, its message naming name."""
    with pytest.raises(stratmesh.Error) as e:
        call(*args, **kwargs)
    assert type(e.value) is kind
    assert isinstance(e.value, TypeError) == (kind is WRONG_TYPE)
    assert e.value.status == status and e.value.report is None
    assert e.value.detail.startswith(name), e.value.detail
    assert str(e.value) == f"{status}: {e.value.detail}"


@pytest.fixture(scope="module")
def tube():
    return bumpy_tube(60_000)
