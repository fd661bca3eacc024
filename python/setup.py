# Builds stratmesh._core from stratmesh.h one directory up, so pip must build in place:
#   python3 -m pip install --no-build-isolation --no-deps ./python
import os

from pybind11.setup_helpers import Pybind11Extension
from setuptools import setup

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
if not os.path.exists(os.path.join(ROOT, "stratmesh.h")):
    raise SystemExit("stratmesh.h is not beside python/: build from the repository")

core = Pybind11Extension(
    "stratmesh._core",
    ["src/_core.cpp"],
    include_dirs=[ROOT],
    cxx_std=17,
    # The library's CMake Release build uses -O3; the same here, so timings compare.
    extra_compile_args=["-O3"],
)

setup(
    name="stratmesh",
    version="0.1.0",
    description="Meshes columnar point clouds: layers, unrolled, 2D Delaunay, stitched",
    license="MIT",
    packages=["stratmesh"],
    ext_modules=[core],
    python_requires=">=3.8",
    install_requires=["numpy"],
    extras_require={"dask": ["dask", "distributed"]},
)
