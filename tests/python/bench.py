#!/usr/bin/python3
"""Benchmarks of the Python API against the rm3d command line (not a test: prints figures).

Each comparison measures its variants in turns (A B A B ...) and reports the median of --reps
runs (default 3) of each, then a table with the ratios:

  1. World with Lua control (worlds/snake.lua, 10 modules, 600 steps): w.step(600) and a Python
     loop of w.step(), against `rm3d run --steps 600` minus `rm3d run --steps 1` (the load and one step:
     `--steps 0` is refused), i.e. 599 steps.
  2. A Python policy loop (obs -> numpy -> act every step, policy=True) on an 8-module chain
     (worlds/python/py_chain.lua) against `rm3d run` of the same chain with the Lua gait
     (--param behavior=behaviors/snake.lua), in steps per second.
  3. A Batch of 64 snakes (120 steps each) at threads=1 and threads=2, against two `rm3d run`
     processes in parallel doing the same 64 runs (32 each, one after another).
  4. rm3d.evaluate of 16 candidates x 20 s (threads=2) against `rm3d sweep --jobs 2` of the same
     runs (and whether both give the same metrics).

    PYTHONPATH=build/python /usr/bin/python3 tests/python/bench.py [--reps N] [--only 1,2,3,4]

The rm3d binary: rm3d.executable() ($RM3D_BIN, else the one beside the package, else PATH).
"""
import argparse
import json
import os
import pathlib
import platform
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

import rm3d

ROOT = pathlib.Path(__file__).resolve().parents[2]
SNAKE = str(ROOT / "worlds" / "snake.lua")
CHAIN = str(ROOT / "worlds" / "python" / "py_chain.lua")


BIN = rm3d.executable()


def run_cli(*args):
    """Wall time of one `rm3d ...` (output discarded); raises when it fails."""
    t0 = time.perf_counter()
    done = subprocess.run([BIN, *args], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                          text=True, cwd=ROOT)
    wall = time.perf_counter() - t0
    if done.returncode not in (0, 1):  # 1: an expectation of the world failed; still timed
        raise RuntimeError("rm3d %s exited %d: %s" % (" ".join(args), done.returncode,
                                                      done.stderr.strip()[-400:]))
    return wall


def interleaved(variants, reps):
    """variants: list of (name, fn returning seconds). Runs A B A B ...; returns name -> median."""
    times = {name: [] for name, _ in variants}
    for _ in range(reps):
        for name, fn in variants:
            times[name].append(fn())
    return {name: statistics.median(ts) for name, ts in times.items()}


# --- 1. World with Lua control vs rm3d run --------------------------------------------------------

def bench_world_lua(reps, steps=600):
    params = {"modules": 10}

    def world_step_n():
        with rm3d.World(SNAKE, params=params) as w:
            t0 = time.perf_counter()
            w.step(steps)
            return time.perf_counter() - t0

    def world_step_loop():
        with rm3d.World(SNAKE, params=params) as w:
            t0 = time.perf_counter()
            for _ in range(steps):
                w.step()
            return time.perf_counter() - t0

    def cli_steps():
        return run_cli("run", SNAKE, "--headless", "--quiet", "--steps", str(steps))

    def cli_load():
        return run_cli("run", SNAKE, "--headless", "--quiet", "--steps", "1")

    m = interleaved([("step(600)", world_step_n), ("600 x step()", world_step_loop),
                     ("rm3d run", cli_steps), ("rm3d run --steps 1", cli_load)], reps)
    cli = (steps - 1) / max(m["rm3d run"] - m["rm3d run --steps 1"], 1e-9)  # steps/s
    sps = lambda s: steps / s
    return [
        ("snake 10, 600 steps: World.step(600) vs rm3d run (load subtracted)",
         "%.0f steps/s" % sps(m["step(600)"]), "%.0f steps/s" % cli,
         sps(m["step(600)"]) / cli),
        ("snake 10, 600 steps: 600 x World.step() vs rm3d run (load subtracted)",
         "%.0f steps/s" % sps(m["600 x step()"]), "%.0f steps/s" % cli,
         sps(m["600 x step()"]) / cli),
        ("  (rm3d run --steps 1: load, one step, exit)", "%.3f s" % m["rm3d run --steps 1"], "",
         None),
    ]


# --- 2. Python policy loop vs rm3d run with Lua control ------------------------------------------

def bench_policy(reps, steps=600):
    def python_policy():
        with rm3d.World(CHAIN, params={"modules": 8, "seconds": steps / 60 + 1},
                        policy=True) as w:
            n = len(w.modules)
            lag = 2 * np.pi / 5 * np.arange(n)
            t0 = time.perf_counter()
            for _ in range(steps):
                obs = np.asarray(w.obs)
                target = 0.6 * np.sin(2 * np.pi * w.time / 1.5 - lag) - 0.01 * obs[:, 1]
                w.act[:, 0] = target
                w.step()
            return time.perf_counter() - t0

    args = ["run", CHAIN, "--headless", "--quiet", "--param", "modules=8",
            "--param", "behavior=behaviors/snake.lua"]

    def cli_steps():
        return run_cli(*args, "--steps", str(steps))

    def cli_load():
        return run_cli(*args, "--steps", "1")

    m = interleaved([("python", python_policy), ("cli", cli_steps), ("load", cli_load)], reps)
    py = steps / m["python"]
    cli = (steps - 1) / max(m["cli"] - m["load"], 1e-9)
    return [("chain 8, 600 steps: Python policy (obs->numpy->act) vs rm3d run, Lua gait",
             "%.0f steps/s" % py, "%.0f steps/s" % cli, py / cli)]


# --- 3. Batch of 64 vs two rm3d run processes ----------------------------------------------------

def bench_batch(reps, worlds=64, steps=120):
    seeds = list(range(worlds))

    def batch(threads):
        def fn():
            b = rm3d.Batch(SNAKE, seeds=seeds, params={"modules": 10}, threads=threads)
            try:
                t0 = time.perf_counter()
                b.step(steps)
                return time.perf_counter() - t0
            finally:
                b.close()
        return fn

    def two_processes():
        def chain(part):
            runs = " ; ".join("'%s' run '%s' --headless --quiet --param modules=10 --steps %d "
                              "--seed %d > /dev/null 2>&1" % (BIN, SNAKE, steps, s)
                              for s in part)
            return subprocess.Popen(["sh", "-c", runs], cwd=ROOT)
        t0 = time.perf_counter()
        procs = [chain(seeds[:worlds // 2]), chain(seeds[worlds // 2:])]
        for p in procs:
            p.wait()
        return time.perf_counter() - t0

    m = interleaved([("t1", batch(1)), ("t2", batch(2)), ("cli", two_processes)], reps)
    ws = lambda s: worlds * steps / s  # world-steps per second
    return [
        ("Batch 64 snakes x 120 steps: threads=2 vs threads=1",
         "%.0f world-steps/s" % ws(m["t2"]), "%.0f world-steps/s" % ws(m["t1"]),
         m["t1"] / m["t2"]),
        ("Batch 64 snakes x 120 steps: threads=2 vs 2 rm3d run processes (32 runs each)",
         "%.2f s" % m["t2"], "%.2f s" % m["cli"], m["cli"] / m["t2"]),
        ("Batch 64 snakes x 120 steps: threads=1 vs 2 rm3d run processes (32 runs each)",
         "%.2f s" % m["t1"], "%.2f s" % m["cli"], m["cli"] / m["t1"]),
    ]


# --- 4. rm3d.evaluate vs rm3d sweep ---------------------------------------------------------------

def bench_evaluate(reps, candidates=16, seconds=20):
    amplitudes = [round(0.2 + 0.05 * i, 2) for i in range(candidates)]
    params = [{"amplitude": a} for a in amplitudes]
    results = {}

    def evaluate():
        t0 = time.perf_counter()
        r = rm3d.evaluate(SNAKE, params=params, seeds=[1], seconds=seconds, threads=2,
                          metric="speed_m_s")
        wall = time.perf_counter() - t0
        results["evaluate"] = np.asarray(r)[:, 0]
        return wall

    def sweep():
        with tempfile.TemporaryDirectory() as tmp:
            out = pathlib.Path(tmp) / "sweep.jsonl"
            wall = run_cli("sweep", SNAKE, "--out", str(out), "--param",
                           "amplitude=" + ",".join(str(a) for a in amplitudes), "--seeds", "1",
                           "--jobs", "2", "--seconds", str(seconds))
            by_amp = {}
            for line in out.read_text().splitlines():
                row = json.loads(line)
                by_amp[float(row["params"]["amplitude"])] = row["metrics"].get("speed_m_s",
                                                                               float("nan"))
            results["sweep"] = np.array([by_amp.get(a, np.nan) for a in amplitudes])
        return wall

    m = interleaved([("evaluate", evaluate), ("sweep", sweep)], reps)
    same = np.array_equal(results["evaluate"], results["sweep"])
    return [("evaluate 16 x 20 s (threads=2) vs rm3d sweep --jobs 2",
             "%.2f s" % m["evaluate"], "%.2f s" % m["sweep"], m["sweep"] / m["evaluate"]),
            ("  same speed_m_s from both: %s" % ("yes, bit for bit" if same else
                                                 "NO: evaluate %s, sweep %s"
                                                 % (results["evaluate"], results["sweep"])),
             "", "", None)]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reps", type=int, default=3, help="runs per variant (median)")
    ap.add_argument("--only", default="1,2,3,4", help="which comparisons, e.g. 1,3")
    args = ap.parse_args(argv)
    which = {int(x) for x in args.only.split(",") if x.strip()}
    print("rm3d bench.py: %s, %d CPUs, rm3d binary %s, median of %d" % (
        platform.node(), os.cpu_count() or 0, BIN, args.reps), flush=True)
    rows = []
    for k, fn in ((1, bench_world_lua), (2, bench_policy), (3, bench_batch),
                  (4, bench_evaluate)):
        if k in which:
            t0 = time.perf_counter()
            rows += fn(args.reps)
            print("comparison %d done in %.0f s" % (k, time.perf_counter() - t0), flush=True)
    w0 = max(len(r[0]) for r in rows)
    w1 = max(max(len(r[1]) for r in rows), len("A"))
    w2 = max(max(len(r[2]) for r in rows), len("B"))
    print()
    print("%-*s  %*s  %*s  %s" % (w0, "comparison (A vs B)", w1, "A", w2, "B", "A/B speed"))
    for name, a, b, ratio in rows:
        print("%-*s  %*s  %*s  %s" % (w0, name, w1, a, w2, b,
                                     "" if ratio is None else "%.2fx" % ratio))
    return 0


if __name__ == "__main__":
    sys.exit(main())
