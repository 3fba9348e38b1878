"""RM3D from Python: worlds, agents' arrays, snapshots, batches and whole-run evaluation.

    import rm3d
    w = rm3d.World("worlds/snake.lua", seed=1, params={"modules": 8}, policy=True)
    w.act[:] = 0.3          # every module's joint targets (rad), applied before each step
    w.step(60)
    print(w.time, w.obs.shape, w.summary()["modules"][0]["position"])

The engine is C++ (rm3d._rm3d, on the public API engine/api/rm3d/simulation.h); `rm3d.gym`
and `rm3d.pettingzoo` wrap it for those libraries when they are installed. docs/python.md is
the guide.
"""
import math as _math
import os as _os
import pathlib as _pathlib
import shutil as _shutil
import sys as _sys
import warnings as _warnings


def _built_for():
    """What the engine beside this file was built for ("CPython 3.11"), from its file name."""
    import re
    for f in sorted(_pathlib.Path(__file__).parent.glob("_rm3d*.so")):
        m = re.match(r"_rm3d\.cpython-(\d)(\d+)", f.name)
        if m:
            return "CPython %s.%s (%s)" % (m.group(1), m.group(2), f.name)
    return None


_HERE = "this Python (%s %s, %s)" % (_sys.implementation.name, ".".join(map(str, _sys.version_info[:2])),
                                     _sys.executable)
try:
    import numpy as _np
except ImportError as _e:
    raise ImportError("rm3d needs numpy, which %s does not have: install it for this interpreter "
                      "(python -m pip install numpy), or run Debian's /usr/bin/python3 "
                      "(apt install python3-numpy)" % _HERE) from _e
try:
    from ._rm3d import Batch, Error, World
    from ._rm3d import _evaluate as _rm3d_evaluate
except ImportError as _e:
    _for = _built_for()
    raise ImportError(
        "rm3d's engine was built for %s and cannot load into %s (%s): run it with the interpreter it "
        "was built for (Debian's /usr/bin/python3 for the project's build), or build it for this one: "
        "%s -m pip install --no-build-isolation . (in the checkout), or "
        "cmake -S . -B build -DPython_EXECUTABLE=%s && cmake --build build"
        % (_for or "another interpreter (no engine file beside the package)", _HERE, _e, _sys.executable,
           _sys.executable)) from _e

__all__ = ["World", "Batch", "Error", "evaluate", "executable"]


def executable():
    """The `rm3d` command line that goes with this package (for `rm3d plot`, `rm3d replay`, ...):
    $RM3D_BIN if set; else the one installed with the package (rm3d/bin/rm3d after `pip install`,
    BUILD/rm3d for a build tree's BUILD/python/rm3d, PREFIX/bin/rm3d for an installed
    PREFIX/lib/python3*/dist-packages/rm3d);
    else `rm3d` on PATH. Raises rm3d.Error naming the places when there is none."""
    if _os.environ.get("RM3D_BIN"):
        return _os.environ["RM3D_BIN"]
    here = _pathlib.Path(__file__).resolve().parent
    tried = [here / "bin" / "rm3d", here.parents[1] / "rm3d", here.parents[3] / "bin" / "rm3d"]
    for p in tried:
        if p.is_file() and _os.access(p, _os.X_OK):
            return str(p)
    found = _shutil.which("rm3d")
    if found:
        return found
    raise Error("no rm3d executable found (looked at $RM3D_BIN, %s and PATH)" % ", ".join(map(str, tried)))


def evaluate(path, params=None, seeds=None, seconds=None, threads=1, metric=None, root=None):
    """Runs `path` once per params dict (x per seed) in C++ threads, Lua in control, and returns
    the metric each run set with world.metric(name, value).

    params: a list of dicts (the world's `args`; None: one run with none).
    seeds: a list of ints: every params dict runs with every seed, the result has shape
    (len(params), len(seeds)); None: the world's own seed, shape (len(params),).
    seconds: simulated seconds per run (None: the world's duration); the world's on_end hooks
    run at the end, as in `rm3d run`.
    A run that fails or does not set the metric gives nan (with a warning naming it); if every
    run fails, rm3d.Error is raised with the first message.
    """
    if metric is None or not isinstance(metric, str) or not metric:
        raise TypeError("metric: expected the name (str) a world sets with world.metric(name, value)")
    if params is None:
        params = [None]
    elif isinstance(params, dict):
        raise TypeError("params: expected a list of dicts (one per candidate), got a dict")
    params = list(params)
    if seeds is not None:
        if isinstance(seeds, (int, str, bytes)):
            raise TypeError("seeds: expected a list of ints or None")
        seeds = list(seeds)
        if not seeds:
            raise ValueError("seeds: empty; expected at least one seed (or None)")
    if seconds is None:
        seconds = 0.0
    else:
        seconds = float(seconds)
        if not (seconds > 0 and _math.isfinite(seconds)):
            raise ValueError("seconds = %r: expected a positive number of simulated seconds" % seconds)
    if not isinstance(threads, int) or isinstance(threads, bool) or threads < 1:
        raise ValueError("threads = %r: expected a whole number >= 1" % (threads,))
    runs = [(s, p) for p in params for s in (seeds if seeds is not None else [None])]
    if not runs:
        return _np.zeros((0,) if seeds is None else (0, len(seeds)))
    values, errors = _rm3d_evaluate(path, runs, seconds, threads, metric, root)
    if len(errors) == len(runs):
        raise Error(errors[0])
    for e in errors[:3]:
        _warnings.warn("rm3d.evaluate: " + e, RuntimeWarning, stacklevel=2)
    if len(errors) > 3:
        _warnings.warn("rm3d.evaluate: %d more runs failed" % (len(errors) - 3), RuntimeWarning, stacklevel=2)
    return values if seeds is None else values.reshape(len(params), len(seeds))


def _command():
    """The `rm3d` command `pip install` puts on PATH: runs the package's own rm3d binary."""
    try:
        exe = executable()
    except Error as e:
        _sys.exit("rm3d: %s" % e)
    if _os.path.realpath(exe) == _os.path.realpath(_sys.argv[0]):
        _sys.exit("rm3d: no rm3d binary installed with the package (reinstall it with pip install .)")
    _os.execv(exe, [exe] + _sys.argv[1:])
