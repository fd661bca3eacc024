import os
import subprocess
import sys

import numpy as np

from conftest import assert_manifold, bumpy_tube

EXAMPLE = os.path.join(os.path.dirname(__file__), "..", "..", "examples", "python",
                       "mesh_cloud.py")
sys.path.insert(0, os.path.dirname(EXAMPLE))
import mesh_cloud  # noqa: E402


def faces_of(path):
    """The faces of a PLY that mesh_cloud wrote, read back independently of its reader."""
    data = open(path, "rb").read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode("ascii").split("\n")
    vertices = int(next(h for h in header if h.startswith("element vertex")).split()[2])
    faces = int(next(h for h in header if h.startswith("element face")).split()[2])
    body = np.frombuffer(data, dtype=[("n", "u1"), ("v", "<u4", 3)], count=faces,
                         offset=end + 12 * vertices)
    assert (body["n"] == 3).all()
    return vertices, body["v"]


def run(*args):
    return subprocess.run([sys.executable, EXAMPLE, *args], check=True, capture_output=True,
                          text=True).stdout


def test_an_ascii_ply_and_an_xyz_file_give_the_same_mesh(tmp_path):
    cloud = bumpy_tube(5_000)
    ply = tmp_path / "cloud.ply"
    with open(ply, "w") as f:
        f.write(f"ply\nformat ascii 1.0\nelement vertex {len(cloud)}\nproperty double x\n"
                "property double y\nproperty double z\nend_header\n")
        np.savetxt(f, cloud, fmt="%.17g")
    xyz = tmp_path / "cloud.xyz"
    np.savetxt(xyz, np.column_stack([cloud, np.ones(len(cloud))]), fmt="%.17g")
    out = run(str(ply), str(tmp_path / "a.ply"), "--axis", "z", "--layers", "4")
    run(str(xyz), str(tmp_path / "b.ply"), "--axis", "z", "--layers", "4")
    count, a = faces_of(tmp_path / "a.ply")
    _, b = faces_of(tmp_path / "b.ply")
    assert count == len(cloud) and len(a) > len(cloud)
    assert np.array_equal(a, b)
    assert_manifold(a)
    assert f"{len(a)} triangles" in out


def test_a_binary_ply_is_read_in_place_and_written_back(tmp_path):
    cloud = bumpy_tube(3_000, dtype=np.float32)
    path = tmp_path / "records.ply"
    records = np.zeros(len(cloud), dtype=[("i", "u1"), ("x", "<f4"), ("y", "<f4"),
                                          ("z", "<f4"), ("t", "<f8")])
    for i, c in enumerate("xyz"):
        records[c] = cloud[:, i]
    with open(path, "wb") as f:
        f.write(f"ply\nformat binary_little_endian 1.0\nelement vertex {len(cloud)}\n"
                "property uchar i\nproperty float x\nproperty float y\nproperty float z\n"
                "property double t\nend_header\n".encode("ascii"))
        f.write(records.tobytes())
    points = mesh_cloud.read_ply(str(path))
    assert points.strides == (records.itemsize, 4) and not points.flags.owndata
    assert np.array_equal(points, cloud)
    run(str(path), str(tmp_path / "mesh.ply"), "--axis", "z", "--cap")
    written = mesh_cloud.read_ply(str(tmp_path / "mesh.ply"))
    assert np.array_equal(written, cloud)
