# `pip install --no-build-isolation .` in a venv made from Debian's interpreter: the package, the
# `rm3d` command and the shipped worlds come with it, and it runs from any folder. The suite's build
# is reused (RM3D_BUILD_DIR), so this installs rather than compiles; a clean clone builds its own
# (setup.py, build-pip/).
import os
import pathlib
import subprocess
import sys

import pytest

import rm3d
from conftest import ROOT

BUILD = pathlib.Path(rm3d.__file__).resolve().parents[2]


def test_pip_install_in_a_venv_runs_the_shipped_worlds(tmp_path):
    if not (BUILD / "CMakeCache.txt").is_file():
        pytest.skip("the package under test is not from a CMake build folder")
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--system-site-packages", str(venv)], check=True)
    py = str(venv / "bin" / "python")
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "RM3D_BIN", "RM3D_ROOT")}
    pip = subprocess.run([py, "-m", "pip", "install", "--no-build-isolation", "--no-index", str(ROOT)],
                         env=dict(env, RM3D_BUILD_DIR=str(BUILD)), capture_output=True, text=True)
    assert pip.returncode == 0, pip.stdout[-3000:] + pip.stderr[-3000:]
    away = tmp_path / "elsewhere"
    away.mkdir()
    script = ("import rm3d, pathlib; w = rm3d.World('worlds/snake.lua', params={'modules': 3}); w.step(30); "
              "print(pathlib.Path(rm3d.__file__).parent); print(w.path); print(len(w.modules), w.steps); "
              "print(w.render(32, 24).shape); print(rm3d.executable())")
    out = subprocess.run([py, "-c", script], cwd=away, env=env, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    package, world, counts, frame, exe = out.stdout.split("\n")[:5]
    assert package.startswith(str(venv)) and world == package + "/share/rm3d/worlds/snake.lua"
    assert counts == "3 30" and frame == "(24, 32, 3)" and exe == package + "/bin/rm3d"
    cli = subprocess.run([str(venv / "bin" / "rm3d"), "run", "worlds/snake.lua", "--seconds", "0.5", "--quiet"],
                         cwd=away, env=env, capture_output=True, text=True)
    assert cli.returncode == 0, cli.stderr
    assert "30 steps, 0.50 s simulated" in cli.stdout and "10 modules, 0 faults" in cli.stdout
