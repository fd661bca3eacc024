import threading
import time

import numpy as np
import pytest

import stratmesh
from conftest import assert_manifold, bumpy_tube


def test_triangles_index_the_input_and_form_a_manifold(tube):
    triangles, report = stratmesh.reconstruct(tube, axis="z", layers=8)
    assert triangles.dtype == np.uint32 and triangles.shape[1] == 3
    assert report.status == "ok"
    assert len(triangles) == report.triangle_count > len(tube)
    assert triangles.max() < len(tube)
    assert (triangles[:, 0] != triangles[:, 1]).all() and (triangles[:, 1] != triangles[:, 2]).all()
    assert_manifold(triangles)


def test_the_manifold_check_catches_a_flipped_triangle(tube):
    triangles, _ = stratmesh.reconstruct(tube, axis="z", layers=8)
    broken = triangles.copy()
    broken[0] = broken[0, ::-1]
    with pytest.raises(AssertionError):
        assert_manifold(broken)


def test_report_counts_add_up(tube):
    cloud = np.concatenate([tube, tube[:50], [[np.nan, 0, 0]]])
    triangles, report = stratmesh.reconstruct(cloud, axis="z", layers=8, skip_invalid=True)
    p = report.points
    assert p.in_count == len(cloud)
    assert p.in_count == p.used_count + p.duplicate_count + p.rejected_count + p.unused_count
    assert p.duplicate_count == 50 and p.rejected_count == 1
    assert len(np.unique(triangles)) == p.used_count
    assert report.layers.used_count == len(report.layers.info) == 8
    assert report.layers.info[0].bottom < report.layers.info[-1].top
    assert report.axis == (0.0, 0.0, 1.0)
    assert report.caps.closed_count == 0


def test_the_fit_of_a_tube_and_of_two_tubes_as_one():
    tube = bumpy_tube(4000)  # small enough for the whole crossing check
    _, report = stratmesh.reconstruct(tube, axis="z")
    d = report.diagnostics
    assert d.fit_sample_count > 0 and d.point_spacing > 0
    assert d.crossing_pair_count == 0 and d.crossing_check_complete
    assert d.misfit_area_fraction < stratmesh.POOR_MISFIT_FRACTION
    # Two tubes side by side meshed as one: the surface spans the gap between them.
    twins = np.concatenate([tube + [3, 0, 0], tube - [3, 0, 0]])
    _, report = stratmesh.reconstruct(twins, axis="z", parts="one_tube")
    d = report.diagnostics
    assert d.misfit_area_fraction > stratmesh.POOR_MISFIT_FRACTION
    assert d.misfit_box_min[0] < -2 and d.misfit_box_max[0] > 2


def test_caps_close_the_tube(tube):
    triangles, report = stratmesh.reconstruct(tube, axis="z", layers=8, cap=True)
    assert report.caps.closed_count == 2
    # A closed surface through V vertices has 2V - 4 triangles.
    assert len(triangles) == 2 * report.points.used_count - 4
    assert_manifold(triangles)


def test_a_float32_strided_view_is_read_in_place(tube):
    # Records of five float32 (intensity, x, y, z, time): the view skips the other fields.
    records = np.zeros((len(tube), 5), dtype=np.float32)
    records[:, 1:4] = tube
    view = records[:, 1:4]
    assert view.strides == (20, 4)
    in_place, _ = stratmesh.reconstruct(view, axis="z", layers=6, copy=False)
    copied, _ = stratmesh.reconstruct(np.ascontiguousarray(view), axis="z", layers=6)
    assert np.array_equal(in_place, copied)


def test_a_layout_that_needs_a_copy_is_copied_or_refused(tube):
    fortran = np.asfortranarray(tube)
    expected, _ = stratmesh.reconstruct(tube, axis="z", layers=6)
    copied, _ = stratmesh.reconstruct(fortran, axis="z", layers=6)
    assert np.array_equal(copied, expected)
    for needs_copy in (fortran, tube[::-1], tube.astype(">f8"),
                       np.broadcast_to(tube[0], (100, 3))):
        with pytest.raises(stratmesh.Error) as e:
            stratmesh.reconstruct(needs_copy, axis="z", layers=6, copy=False)
        assert e.value.status == "invalid_argument"


def test_threads_give_the_same_bytes(tube):
    one, report_one = stratmesh.reconstruct(tube, axis="z", layers=12, surface_flips=True)
    assert report_one.layers.parallel_count == 0
    for threads in (2, 3, 0):
        many, report = stratmesh.reconstruct(tube, axis="z", layers=12, surface_flips=True,
                                             threads=threads)
        assert many.tobytes() == one.tobytes()
    assert report.layers.parallel_count > 0


def test_axis_by_name_and_by_vector_agree(tube):
    by_name, _ = stratmesh.reconstruct(tube, axis="z", layers=6)
    by_vector, report = stratmesh.reconstruct(tube, axis=(0, 0, 2.0), layers=6)
    assert report.axis == (0.0, 0.0, 1.0)
    assert np.array_equal(by_name, by_vector)
    _, automatic = stratmesh.reconstruct(tube, layers=6)
    assert abs(automatic.axis[2]) > 0.99


def test_cuts_and_layer_height_set_the_layers(tube):
    _, report = stratmesh.reconstruct(tube, axis="z", cuts=[1.0, 2.5, 4.0])
    assert [round(layer.top, 9) for layer in report.layers.info[:3]] == [1.0, 2.5, 4.0]
    _, report = stratmesh.reconstruct(tube, axis="z", layer_height=np.pi / 2)
    assert report.layers.used_count == 4


def test_drop_outliers_counts_them(tube):
    cloud = np.concatenate([tube, [[40.0, 0, 3], [0, -50.0, 2]]])
    triangles, report = stratmesh.reconstruct(cloud, axis="z", layers=6, drop_outliers=True)
    assert report.points.outlier_count == 2
    assert len(tube) not in triangles and len(tube) + 1 not in triangles


def test_ends_are_cuts_and_flags_by_name(tube):
    a, _ = stratmesh.reconstruct(tube, axis="z", layers=6, ends_are_cuts=True, surface_flips=True)
    b, _ = stratmesh.reconstruct(tube, axis="z", layers=6, flags=("ends_are_cuts", "surface_flips"))
    assert np.array_equal(a, b)
    assert set(stratmesh.FLAGS) >= {"skip_invalid_points", "add_caps", "origin_given",
                                    "drop_outliers", "surface_flips", "ends_are_cuts"}


def test_progress_sees_the_phases_in_order(tube):
    phases = []
    stratmesh.reconstruct(tube, axis="z", layers=6, progress=lambda p, f: phases.append(p))
    order = ["validate", "layers", "triangulate", "stitch", "manifold", "done"]
    seen = [p for i, p in enumerate(phases) if i == 0 or phases[i - 1] != p]
    assert seen == order


def test_an_exception_in_progress_is_raised_after_the_call(tube):
    def fail(phase, fraction):
        raise KeyError(phase)
    with pytest.raises(KeyError):
        stratmesh.reconstruct(tube, axis="z", layers=6, progress=fail)


def test_origin_changes_only_rounding(tube):
    a, _ = stratmesh.reconstruct(tube, axis="z", layers=6)
    b, report = stratmesh.reconstruct(tube, axis="z", layers=6, origin=(0.0, 0.0, 3.0))
    assert len(a) == len(b)
    assert report.points.used_count == len(tube)


def test_a_float32_cloud_meshes_like_its_float64_values():
    cloud = bumpy_tube(20_000, dtype=np.float32)
    a, _ = stratmesh.reconstruct(cloud, axis="z", layers=5)
    b, _ = stratmesh.reconstruct(cloud.astype(np.float64), axis="z", layers=5)
    assert np.array_equal(a, b)


def test_a_kept_workspace_grows_and_gives_the_same_triangles(tube):
    workspace = stratmesh.Workspace()
    assert workspace.size == 0
    small, _ = stratmesh.reconstruct(tube[:20_000], axis="z", layers=4, workspace=workspace)
    first = workspace.size
    assert first > 0
    big, _ = stratmesh.reconstruct(tube, axis="z", layers=8, workspace=workspace)
    assert workspace.size > first
    again, _ = stratmesh.reconstruct(tube[:20_000], axis="z", layers=4, workspace=workspace)
    assert workspace.size > first
    assert np.array_equal(small, again)
    assert np.array_equal(big, stratmesh.reconstruct(tube, axis="z", layers=8)[0])


def test_the_gil_is_released_while_the_library_runs():
    # Were the GIL held through the call, this thread would stall for all of it.
    cloud = bumpy_tube(400_000)
    done = threading.Event()
    elapsed = []

    def mesh():
        start = time.perf_counter()
        stratmesh.reconstruct(cloud, axis="z", layers=8)
        elapsed.append(time.perf_counter() - start)
        done.set()

    worker = threading.Thread(target=mesh)
    last = time.perf_counter()
    longest = 0.0
    worker.start()
    while not done.is_set():
        now = time.perf_counter()
        longest = max(longest, now - last)
        last = now
    worker.join()
    assert longest < 0.5 * elapsed[0]


def forked_tube():
    """A trunk of radius 10 up to z = 60 and two prongs of radius 3 on its wall above it."""
    golden = np.pi * (3 - np.sqrt(5.0))
    parts = []
    for count, cx, radius, z0, z1 in ((4200, 0, 10, 0, 60), (850, -7, 3, 60, 100), (850, 7, 3, 60, 100)):
        t = np.arange(count, dtype=np.float64)
        parts.append(np.stack([cx + radius * np.cos(golden * t), radius * np.sin(golden * t),
                               z0 + (z1 - z0) * (t + 0.5) / count], axis=1))
    return np.concatenate(parts)


def test_a_forked_cloud_is_meshed_in_parts_joined_into_one_surface():
    points = forked_tube()
    triangles, report = stratmesh.reconstruct(points, axis="z", layers=4)
    assert report.parts.outcome == "joined"
    assert report.parts.part_count == 3
    assert report.parts.above_branch_count == 2
    assert report.parts.joined_side_count == 1
    assert report.points.used_count == len(points)
    assert_manifold(triangles)
    _, one = stratmesh.reconstruct(points, axis="z", layers=4, parts="one_tube")
    assert one.parts.outcome == "one_tube"
    assert one.parts.part_count == 0


def test_a_bent_pipe_is_meshed_across_its_skeleton():
    # Half a torus, open at both ends: a pipe of radius 0.5 bent around a circle of radius 3.
    rng = np.random.default_rng(5)
    t = rng.uniform(0, np.pi, 8000)
    phi = rng.uniform(0, 2 * np.pi, 8000)
    radial = np.stack([np.cos(t), np.zeros_like(t), -np.sin(t)], axis=1)
    across = np.array([0.0, 1.0, 0.0])
    points = (3 * radial + 0.5 * (np.cos(phi)[:, None] * radial + np.sin(phi)[:, None] * across))
    triangles, report = stratmesh.reconstruct(points)
    assert report.layers.skeleton_node_count >= 4
    # Every triangle lies on the pipe: its centroid within a tenth of the radius of it.
    centroid = points[triangles].mean(axis=1)
    off_centre_line = np.hypot(np.hypot(centroid[:, 0], centroid[:, 2]) - 3, centroid[:, 1])
    assert np.abs(off_centre_line - 0.5).max() < 0.05
    # One tube along one axis webs across the bend instead.
    tube, straight = stratmesh.reconstruct(points, parts="one_tube")
    assert straight.layers.skeleton_node_count == 0
    centroid = points[tube].mean(axis=1)
    off_centre_line = np.hypot(np.hypot(centroid[:, 0], centroid[:, 2]) - 3, centroid[:, 1])
    assert np.abs(off_centre_line - 0.5).max() > 0.2
