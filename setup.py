# `pip install .` (or `pip install --no-build-isolation .`, no download): builds RM3D with CMake for
# the interpreter that runs pip and installs the Python package `rm3d` with, inside it, the `rm3d`
# command (rm3d/bin/rm3d, also on PATH as `rm3d`) and the data it reads (rm3d/share/rm3d: module
# types, meshes, lua/, behaviors/, worlds/, docs/), as `cmake --install` lays them out.
#
# Needs what `bash .ci/install-deps use` installs (CMake, Ninja, a C++20 compiler, pybind11-dev and
# the engine's -dev packages) and numpy for the interpreter. The CMake build goes to
# build-pip/<interpreter tag> in this folder and is reused by the next `pip install`;
# RM3D_BUILD_DIR=DIR uses an existing build of this checkout instead, which must have been made for
# the same interpreter (`cmake -DPython_EXECUTABLE=...`). RM3D_BUILD_JOBS caps the build's jobs.
import os
import pathlib
import shutil
import subprocess
import sys
import sysconfig

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

HERE = pathlib.Path(__file__).resolve().parent
(HERE / "build-pip").mkdir(exist_ok=True)  # setuptools' own files go there (see the options below)


def version():
    for line in (HERE / "CMakeLists.txt").read_text().splitlines():
        if line.startswith("project(rm3d VERSION "):
            return line.split()[2]
    raise RuntimeError("CMakeLists.txt: no `project(rm3d VERSION x.y.z ...)` line")


def run(cmd, **kw):
    print("+ " + " ".join(str(c) for c in cmd), flush=True)
    subprocess.run([str(c) for c in cmd], check=True, **kw)


class CMakeBuild(build_ext):
    """Builds rm3d and its extension with CMake, then lays the installed tree into the package."""

    def run(self):
        if shutil.which("cmake") is None:
            sys.exit("pip install rm3d: cmake not found; `bash .ci/install-deps use` installs what the "
                     "build needs (as root, Debian 12)")
        given = os.environ.get("RM3D_BUILD_DIR")
        build = pathlib.Path(given).resolve() if given else HERE / "build-pip" / sys.implementation.cache_tag
        suffix = sysconfig.get_config_var("EXT_SUFFIX")
        if given:
            if not (build / "CMakeCache.txt").is_file():
                sys.exit("RM3D_BUILD_DIR=%s: not a CMake build folder (no CMakeCache.txt)" % build)
        else:
            generator = ["-G", "Ninja"] if shutil.which("ninja") else []
            run(["cmake", "-S", HERE, "-B", build, *generator, "-DCMAKE_BUILD_TYPE=Release",
                 "-DRM3D_PYTHON=ON", "-DPython_EXECUTABLE=" + sys.executable])
        jobs = os.environ.get("RM3D_BUILD_JOBS") or str(os.cpu_count() or 1)
        run(["cmake", "--build", build, "--target", "rm3d", "rm3d_python", "--parallel", jobs])
        built = list((build / "python" / "rm3d").glob("_rm3d*.so"))
        if not any(p.name.endswith(suffix) for p in built):
            sys.exit("%s holds %s, not an extension for this interpreter (%s, which loads _rm3d%s): build "
                     "it with cmake -DPython_EXECUTABLE=%s, or leave RM3D_BUILD_DIR unset"
                     % (build, [p.name for p in built] or "no extension", sys.executable, suffix,
                        sys.executable))
        stage = build / "pip-stage"
        shutil.rmtree(stage, ignore_errors=True)
        run(["cmake", "--install", build, "--prefix", stage])
        package = pathlib.Path(self.build_lib) / "rm3d"
        package.mkdir(parents=True, exist_ok=True)
        for p in stage.glob("lib/python*/*-packages/rm3d/*"):
            if p.suffix == ".py" or p.name.endswith(suffix):
                shutil.copy2(p, package / p.name)
        for sub in ("bin", "share"):
            shutil.rmtree(package / sub, ignore_errors=True)
            shutil.copytree(stage / sub, package / sub, symlinks=False)
        shutil.rmtree(stage, ignore_errors=True)


setup(
    name="rm3d",
    version=version(),
    description="Physics-based simulator for self-reconfigurable modular robots (one Lua VM per module)",
    long_description=(HERE / "README.md").read_text(),
    long_description_content_type="text/markdown",
    license="see the repository",
    python_requires=">=3.9",
    install_requires=["numpy"],
    packages=["rm3d"],
    package_dir={"rm3d": "engine/python/rm3d"},
    ext_modules=[Extension("rm3d._rm3d", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    entry_points={"console_scripts": ["rm3d=rm3d:_command"]},
    options={"build": {"build_base": "build-pip/setuptools"}, "egg_info": {"egg_base": "build-pip"}},
    zip_safe=False,
)
