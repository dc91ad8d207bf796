"""pip install --no-build-isolation .  builds the Python module geardiag with CMake (the same
build as `make python`: the libraries and python/bindings.cpp) and installs the package from
python/geardiag. Offline: only Debian's setuptools, wheel, pybind11-dev and the C++ build
dependencies (scripts/install-deps) are used."""
import os
import pathlib
import shutil
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = pathlib.Path(__file__).resolve().parent


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        target = pathlib.Path(self.get_ext_fullpath(ext.name)).resolve()
        # GEARDIAG_BUILD_DIR: an existing CMake build of this checkout (e.g. build/, where
        # `make python` built the module) is reused; else a Release build of its own.
        given = os.environ.get("GEARDIAG_BUILD_DIR")
        build = (pathlib.Path(given) if given else
                 pathlib.Path(self.build_temp) / "cmake").resolve()
        if not given:
            subprocess.run(["cmake", "-S", str(ROOT), "-B", str(build),
                            "-DCMAKE_BUILD_TYPE=Release", "-DGEARDIAG_BUILD_TESTS=OFF",
                            "-DGEARDIAG_WITH_PYTHON=ON", f"-DPython3_EXECUTABLE={sys.executable}"],
                           check=True)
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL", str(os.cpu_count() or 2))
        subprocess.run(["cmake", "--build", str(build), "--target", "geardiag_py", "-j", jobs],
                       check=True)
        built = sorted((build / "python" / "geardiag").glob("_geardiag*.so"))
        if not built:
            sys.exit("setup.py: CMake did not build the module (is pybind11-dev installed?)")
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(built[0], target)


setup(
    name="geardiag",
    version="0.1.0",
    description="Gear and bearing vibration diagnostics (simulator and detectors)",
    packages=["geardiag"],
    package_dir={"": "python"},
    ext_modules=[Extension("geardiag._geardiag", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    install_requires=["numpy"],
    python_requires=">=3.9",
    zip_safe=False,
)
