"""Runs each example of worlds/python/ with --quick and checks what it printed: the evolved gait
and bodies improve on the first generation, the trained chain crawls further than the untrained
one, and the distributed policy's messages crossed the chain one hop per step.

    PYTHONPATH=build/python /usr/bin/python3 -m pytest tests/python -q
"""
import csv
import pathlib
import re
import shutil
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "worlds" / "python"
NUMBER = r"(-?\d+(?:\.\d+)?)"


def run_example(name, *args, cwd=None):
    done = subprocess.run([sys.executable, str(EXAMPLES / name), "--quick", *args],
                          capture_output=True, text=True, timeout=300, cwd=cwd)
    assert done.returncode == 0, "%s exited %d\nstdout:\n%s\nstderr:\n%s" % (
        name, done.returncode, done.stdout, done.stderr)
    return done.stdout


def test_cmaes_gait_improves_the_snakes_speed():
    out = run_example("cmaes_gait.py")
    gens = re.findall(r"generation +\d+: best " + NUMBER + " m/s", out)
    assert len(gens) == 6, out
    m = re.search(r"first generation best " + NUMBER + " m/s, best " + NUMBER + " m/s", out)
    assert m, out
    first, best = float(m.group(1)), float(m.group(2))
    assert first == float(gens[0])
    assert best == max(float(g) for g in gens)
    assert best > first and best > 0.02, out   # the snake crawls forward, faster than at first


def test_train_chain_trained_beats_untrained(tmp_path):
    out = run_example("train_chain.py", "--out", str(tmp_path / "curve"))
    m = re.search(r"untrained " + NUMBER + " m, trained " + NUMBER + " m", out)
    assert m, out
    untrained, trained = float(m.group(1)), float(m.group(2))
    assert trained > untrained + 0.05, out     # at least 5 cm further in the episode
    with open(tmp_path / "curve" / "curve.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert [int(r["generation"]) for r in rows] == list(range(len(rows)))
    assert float(rows[0]["policy_m"]) == pytest.approx(untrained, abs=1e-3)
    assert float(rows[-1]["policy_m"]) == pytest.approx(trained, abs=1e-3)
    if shutil.which("gnuplot"):                # rm3d plot draws through gnuplot
        png = tmp_path / "curve" / "curve.png"
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_morphology_evolves_a_better_population():
    out = run_example("morphology.py")
    gens = re.findall(r"generation +\d+: best " + NUMBER + r" m \((\d+) modules", out)
    assert len(gens) == 8, out
    m = re.search(r"first generation best " + NUMBER + " m, best " + NUMBER + r" m \(genome [0-9,]+\); mean "
                  + NUMBER + " m -> " + NUMBER + " m", out)
    assert m, out
    first, best, first_mean, last_mean = (float(m.group(k)) for k in range(1, 5))
    assert best >= first and last_mean > first_mean, out
    # elitism: the best of a generation never falls
    bests = [float(g[0]) for g in gens]
    assert all(b2 >= b1 for b1, b2 in zip(bests, bests[1:])), out


def test_distributed_messages_cross_the_chain_hop_by_hop():
    out = run_example("distributed.py")
    for k in range(2, 7):
        # the head sends in step 1; module m<k>, k - 1 hops away, reads it in step k
        assert re.search(r"^m%d: first heard at step %d, %d hop\(s\) from the head$"
                         % (k, k, k - 1), out, re.M), out
    assert "steps per hop: 1 1 1 1 1" in out, out
    assert "one step per hop (5 hops in 5 steps)" in out, out
    # the step table: after step s, exactly the modules within s - 1 hops of the head have heard
    for s in range(1, 7):
        row = re.search(r"^ *%d  (.*)$" % s, out, re.M)
        assert row, out
        assert row.group(1).split() == ["0"] + ["1"] * (s - 1) + ["0"] * (6 - s), out
    # and the wave the messages carried moved the chain forward (+x)
    m = re.search(r"the chain's head moved " + NUMBER + " m", out)
    assert m and float(m.group(1)) > 0.05, out
