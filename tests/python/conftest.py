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


@pytest.fixture
def sigint():
    """Python's own Ctrl-C handler for the test: a suite started in the background (nohup, a CI
    runner, `cmd &` in a script) inherits SIGINT ignored, and then a test that sends itself
    SIGINT would never see KeyboardInterrupt (it waited forever on a step of 10**7)."""
    import signal
    old = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, old)
