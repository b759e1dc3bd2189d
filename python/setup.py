"""Builds meshcast's Python package with CMake (see pyproject.toml).

The repository's CMake project is configured with the Python package on and
the command-line tools and tests off; Vulkan (the GPU backend) and Assimp
(meshcast.read_mesh) are built in where their Debian packages are installed
(libvulkan-dev with glslang-tools; libassimp-dev). Environment:
  MESHCAST_CMAKE_ARGS   more arguments for CMake's configure step
                        (e.g. "-DMESHCAST_VULKAN=OFF -DMESHCAST_ISAS=scalar")
  CMAKE_BUILD_PARALLEL_LEVEL
                        the build's jobs (default: every core)
"""
import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent


def version():
    text = (ROOT / "CMakeLists.txt").read_text()
    return re.search(r"project\(meshcast VERSION ([0-9.]+)", text).group(1)


class CMakeExtension(Extension):
    def __init__(self, name):
        super().__init__(name, sources=[])


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        if not (ROOT / "CMakeLists.txt").exists():
            sys.exit("meshcast: setup.py builds from the meshcast repository (python/ inside it)")
        out = Path(self.get_ext_fullpath(ext.name)).resolve().parent  # .../meshcast
        build = Path(self.build_temp).resolve() / "cmake"
        # --fresh: pip builds in the source tree, and a cache left by an
        # earlier build's MESHCAST_CMAKE_ARGS (scalar walkers, say) would
        # outlive it; the objects are kept, and rebuilt where flags differ.
        configure = ["cmake", "--fresh", "-S", str(ROOT), "-B", str(build), "-DCMAKE_BUILD_TYPE=Release",
                     "-DMESHCAST_PYTHON=ON", "-DMESHCAST_TOOLS=OFF", "-DMESHCAST_TESTS=OFF",
                     "-DMESHCAST_INSTALL=OFF", "-DMESHCAST_VULKAN=AUTO", "-DMESHCAST_READER=AUTO",
                     f"-DPython3_EXECUTABLE={sys.executable}"]
        try:  # pybind11 from pip carries its CMake files; Debian's are in pybind11-dev, found by CMake itself
            import pybind11
            configure.append(f"-Dpybind11_DIR={pybind11.get_cmake_dir()}")
        except ImportError:
            pass
        configure += shlex.split(os.environ.get("MESHCAST_CMAKE_ARGS", ""))
        subprocess.run(configure, check=True)
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL", str(os.cpu_count() or 1))
        subprocess.run(["cmake", "--build", str(build), "--target", "meshcast_python", "-j", jobs], check=True)
        built = next((build / "python" / "meshcast").glob("_meshcast*.so"))
        out.mkdir(parents=True, exist_ok=True)
        self.copy_file(str(built), str(out / built.name))


setup(version=version(), ext_modules=[CMakeExtension("meshcast._meshcast")], cmdclass={"build_ext": CMakeBuild},
      zip_safe=False)
