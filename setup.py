"""`pip install .`: builds the Python module ddemap with CMake (the target ddemap_python) and
installs the package python/ddemap with it. The version is the one of CMakeLists.txt.

Needs CMake, a C++17 compiler and the Debian packages of scripts/install-deps.sh (Eigen,
Spectra, SuiteSparse, pybind11, NumPy, ...). Set DDEMAP_CMAKE_ARGS for extra CMake arguments and
DDEMAP_BUILD_JOBS for the number of compile jobs (default: the number of cores).

DDEMAP_BUILD_DIR=FOLDER reuses a build folder that CMake already configured from this source tree
with DDEMAP_BUILD_PYTHON=ON for the same Python (for example build/ of scripts/build.sh): only the
target ddemap_python is brought up to date there, and nothing is compiled twice."""
import os
import re
import shlex
import shutil
import subprocess
import sys
import sysconfig

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

HERE = os.path.dirname(os.path.abspath(__file__))


def cmake_version():
    with open(os.path.join(HERE, "CMakeLists.txt"), encoding="utf-8") as f:
        m = re.search(r"project\(ddemap VERSION ([0-9.]+)", f.read())
    if not m:
        raise RuntimeError("CMakeLists.txt: no project(ddemap VERSION x.y.z)")
    return m.group(1)


def check_build_folder(build):
    """DDEMAP_BUILD_DIR: a folder configured by CMake from this tree, with the Python module on."""
    cache = os.path.join(build, "CMakeCache.txt")
    if not os.path.isfile(cache):
        raise RuntimeError("DDEMAP_BUILD_DIR=" + build + ": no CMakeCache.txt there (expected a folder configured by CMake)")
    with open(cache, encoding="utf-8", errors="replace") as f:
        entries = dict(line.rstrip("\n").split("=", 1) for line in f if "=" in line and not line.startswith(("#", "//")))
    home = entries.get("CMAKE_HOME_DIRECTORY:INTERNAL", "")
    if os.path.realpath(home) != os.path.realpath(HERE):
        raise RuntimeError("DDEMAP_BUILD_DIR=" + build + ": configured from " + home + ", not from " + HERE)
    if entries.get("DDEMAP_BUILD_PYTHON:BOOL", "OFF").upper() not in ("ON", "1", "TRUE", "YES"):
        raise RuntimeError("DDEMAP_BUILD_DIR=" + build + ": configured with DDEMAP_BUILD_PYTHON=OFF (expected ON)")


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        if shutil.which("cmake") is None:
            raise RuntimeError("ddemap needs CMake to build (Debian: apt-get install cmake, or scripts/install-deps.sh)")
        reuse = os.environ.get("DDEMAP_BUILD_DIR", "")
        if reuse:
            build = os.path.abspath(reuse)
            check_build_folder(build)
        else:
            build = os.path.abspath(os.path.join(self.build_temp, "cmake"))
            os.makedirs(build, exist_ok=True)
            generator = ["-G", "Ninja"] if shutil.which("ninja") else []
            args = ["cmake", "-S", HERE, "-B", build, *generator, "-DCMAKE_BUILD_TYPE=Release",
                    "-DDDEMAP_BUILD_TESTS=OFF", "-DDDEMAP_BUILD_BENCH=OFF", "-DDDEMAP_BUILD_PYTHON=ON",
                    "-DPYTHON_EXECUTABLE=" + sys.executable]
            args += shlex.split(os.environ.get("DDEMAP_CMAKE_ARGS", ""))
            subprocess.check_call(args)
        jobs = os.environ.get("DDEMAP_BUILD_JOBS", str(os.cpu_count() or 1))
        subprocess.check_call(["cmake", "--build", build, "--target", "ddemap_python", "-j", jobs])
        built = os.path.join(build, "python", "ddemap")
        suffix = sysconfig.get_config_var("EXT_SUFFIX") or ".so"
        module = [f for f in os.listdir(built) if f == "_ddemap" + suffix]
        if len(module) != 1:
            raise RuntimeError("the CMake build made no module _ddemap" + suffix + " for this Python in " + built)
        target = self.get_ext_fullpath(ext.name)
        os.makedirs(os.path.dirname(target), exist_ok=True)
        shutil.copyfile(os.path.join(built, module[0]), target)


setup(
    version=cmake_version(),
    packages=["ddemap"],
    package_dir={"": "python"},
    ext_modules=[Extension("ddemap._ddemap", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    zip_safe=False,
)
