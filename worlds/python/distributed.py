#!/usr/bin/python3
"""A distributed policy: every module of a chain decides from its own observation row only, and
the modules coordinate only through dock messages.

World: worlds/python/py_distributed.lua (six SuperBots in a line, policy=True), behaviour
behaviors/py_distributed.lua: act(a) reads what arrived on the front dock and sends {phase, hops}
on the back dock (the head: the phase Python gave; the others: the phase that arrived plus the
lag Python gave, in the same step), then sets the pitch target a[4]; observe() returns {heard,
phase, hops, head, pitch}. The policy, the same function for every module, reads only its own
row:

    head (nothing docked at its front): start a wave, phase = 2 pi t / 1.5 s
    every module: lag = 2 pi / 5, pitch target = 0.6 sin(its phase) (0 until it has one)

so a travelling wave is passed down the chain by messages. Prints, step by step, which modules
have heard, then when each module first heard and from how many hops away, and how far the chain
crawled.

    PYTHONPATH=build/python /usr/bin/python3 worlds/python/distributed.py [--quick]
"""
import argparse
import pathlib
import sys

import numpy as np

import rm3d

ROOT = pathlib.Path(__file__).resolve().parents[2]
WORLD = ROOT / "worlds" / "python" / "py_distributed.lua"
PERIOD, LAG, AMPLITUDE = 1.5, 2 * np.pi / 5, 0.6
HEARD, PHASE, HOPS, HEAD = 0, 1, 2, 3  # observation columns


def policy(obs_row, t):
    """One module's action row {start, phase, lag, target} from its own observation row."""
    if obs_row[HEAD] == 1:
        phase = 2 * np.pi * t / PERIOD
        return [1.0, phase, 0.0, AMPLITUDE * np.sin(phase)]
    target = AMPLITUDE * np.sin(obs_row[PHASE]) if obs_row[HEARD] == 1 else 0.0
    return [0.0, 0.0, LAG, target]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="a short run (the test suite's)")
    ap.add_argument("--modules", type=int, default=6)
    ap.add_argument("--seconds", type=float, default=None, help="how long the chain crawls")
    args = ap.parse_args(argv)
    seconds = args.seconds or (2.0 if args.quick else 8.0)

    with rm3d.World(str(WORLD), params={"modules": args.modules}, policy=True) as w:
        names = w.modules
        n = len(names)
        first = [None] * n
        hops = [None] * n
        print("step  heard (%s)" % " ".join(names))
        for step in range(1, int(round(seconds / w.dt)) + 1):
            obs = np.asarray(w.obs)
            t = w.time
            w.act[:] = np.array([policy(obs[i], t) for i in range(n)])
            w.step()
            obs = np.asarray(w.obs)
            for i in range(n):
                if first[i] is None and obs[i, HEARD] == 1:
                    first[i], hops[i] = step, int(obs[i, HOPS])
            if step <= n + 1:
                print("%4d  %s" % (step, " ".join("%*d" % (len(names[i]), obs[i, HEARD])
                                                  for i in range(n))))
        moved = w.metrics.get("moved", float("nan"))
    for i in range(n):
        if first[i] is None:
            print("%s: %s" % (names[i], "the head (sends)" if i == 0 else "never heard"))
        else:
            print("%s: first heard at step %d, %d hop(s) from the head" % (names[i], first[i],
                                                                         hops[i]))
    arrivals = [first[i] for i in range(1, n)]
    if all(a is not None for a in arrivals):
        gaps = np.diff([1] + arrivals)  # the head first sent in step 1
        print("steps per hop: %s" % " ".join(str(int(g)) for g in gaps))
        if len(gaps) and all(g == 1 for g in gaps):
            print("the message crossed the chain hop by hop, one step per hop "
                  "(%d hops in %d steps)" % (n - 1, arrivals[-1] - 1))
    print("the chain's head moved %.3f m in %.1f s, driven only by messages" % (moved, seconds))
    return 0 if all(a is not None for a in arrivals) else 1


if __name__ == "__main__":
    sys.exit(main())
