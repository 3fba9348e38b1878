# Shared by the Python tests: where the checkout and the rm3d binary are. ctest sets RM3D_BIN and
# PYTHONPATH (tests/CMakeLists.txt); run by hand:
#   PYTHONPATH=build/python RM3D_BIN=build/rm3d /usr/bin/python3 -m pytest tests/python
import pathlib

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
HERE = pathlib.Path(__file__).resolve().parent


def rm3d_bin():
    import rm3d
    return rm3d.executable()


@pytest.fixture
def root():
    return ROOT


@pytest.fixture
def bin():
    return rm3d_bin()
