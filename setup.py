"""Installs the Python package dynid: `pip install --no-build-isolation .` (README "Install").

The compiled extension dynid._core is the CMake target dynid_python (python/CMakeLists.txt), built
by CMake, not by setuptools, so that it is compiled with the project's flags and dependencies
(Debian's pybind11-dev; nothing is downloaded). The build reuses the CMake build folder named by
$DYNID_BUILD_DIR when it is set (e.g. DYNID_BUILD_DIR=build after ./scripts/build: only the
module is brought up to date), else it configures one of its own under build/pip/ (tests and
benchmarks off) and compiles the library into the module there, as long as a first build. The
package is python/dynid/*.py, the extension, and the built-in robots as dynid/robots, where the
extension finds them (src/model/robots.cpp), so that `import dynid` works from any folder.
"""
import os
import re
import shutil
import subprocess
import sys
import sysconfig

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = os.path.dirname(os.path.abspath(__file__))
# setuptools' own folders inside the (git-ignored) build/, beside CMake's default build folder.
PIP_BUILD = os.path.join("build", "pip")


def project_version():
    with open(os.path.join(ROOT, "CMakeLists.txt"), encoding="utf-8") as f:
        match = re.search(r"project\(dynid VERSION ([0-9.]+)", f.read())
    if not match:
        sys.exit("error: CMakeLists.txt has no project(dynid VERSION ...); "
                 "setup.py reads the version there")
    return match.group(1)


def require_wheel():
    """pip builds a wheel: setuptools before 70.1 needs the package `wheel` for it, which
    --no-build-isolation does not fetch. Said in one line instead of setuptools' "invalid command
    'bdist_wheel'"."""
    try:
        import setuptools.command.bdist_wheel  # noqa: F401  (setuptools >= 70.1)
    except ImportError:
        try:
            import wheel  # noqa: F401
        except ImportError:
            sys.exit(f"error: {sys.executable} lacks the Python package 'wheel' that pip needs to "
                     "build dynid offline; use Debian's python3 (python3-wheel, scripts/setup), "
                     "e.g. a venv made by /usr/bin/python3 -m venv --system-site-packages "
                     "(README \"Install\"), or install wheel for this interpreter")


class CMakeBuild(build_ext):
    """Builds dynid._core with CMake and puts it, with the built-in robots, into the package."""

    def build_extension(self, ext):
        build_dir = os.environ.get("DYNID_BUILD_DIR")
        if build_dir:
            build_dir = os.path.abspath(build_dir)
            if not os.path.isfile(os.path.join(build_dir, "CMakeCache.txt")):
                sys.exit(f"error: DYNID_BUILD_DIR={build_dir} is not a configured CMake build "
                         "folder; run ./scripts/build first or unset DYNID_BUILD_DIR")
        else:
            build_dir = os.path.abspath(os.path.join(self.build_temp, "cmake"))
            if not os.path.isfile(os.path.join(build_dir, "CMakeCache.txt")):
                generator = ["-G", "Ninja"] if shutil.which("ninja") else []
                self._run(["cmake", "-S", ROOT, "-B", build_dir, *generator,
                           "-DCMAKE_BUILD_TYPE=Release", "-DDYNID_BUILD_TESTS=OFF",
                           "-DDYNID_BUILD_BENCH=OFF", "-DDYNID_BUILD_PYTHON=ON",
                           f"-DPython_EXECUTABLE={sys.executable}"])
        self._run(["cmake", "--build", build_dir, "--target", "dynid_python",
                   "-j", str(os.cpu_count() or 2)])

        # The module must be for this interpreter: a build folder configured for another Python
        # (e.g. Debian's python3 when pip is pyenv's) names its file with that one's suffix.
        suffix = sysconfig.get_config_var("EXT_SUFFIX")
        built = os.path.join(build_dir, "python", "dynid", "_core" + suffix)
        if not os.path.isfile(built):
            sys.exit(f"error: {build_dir} holds no {os.path.basename(built)} for this Python "
                     f"({sys.executable}); it was configured for another interpreter: run pip with "
                     "that one (e.g. /usr/bin/python3 -m pip) or unset DYNID_BUILD_DIR")
        target = self.get_ext_fullpath(ext.name)
        os.makedirs(os.path.dirname(target), exist_ok=True)
        shutil.copyfile(built, target)
        robots = os.path.join(os.path.dirname(target), "robots")
        shutil.rmtree(robots, ignore_errors=True)
        shutil.copytree(os.path.join(ROOT, "examples", "robots"), robots)

    def _run(self, command):
        print(" ".join(command), flush=True)
        subprocess.run(command, check=True)


if {"bdist_wheel", "dist_info"} & set(sys.argv):
    require_wheel()
setup(
    name="dynid",
    version=project_version(),
    description="Identification of robot dynamic models (link inertias, actuator inertias, "
                "friction, payload)",
    license="Apache-2.0",
    python_requires=">=3.8",
    packages=["dynid"],
    package_dir={"dynid": "python/dynid"},
    ext_modules=[Extension("dynid._core", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    zip_safe=False,
    options={"build": {"build_base": PIP_BUILD}, "egg_info": {"egg_base": PIP_BUILD}},
)
