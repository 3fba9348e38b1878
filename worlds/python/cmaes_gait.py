#!/usr/bin/python3
"""CMA-ES tunes the snake's travelling wave (amplitude, period, lag of behaviors/snake.lua).

Each candidate is a whole run of worlds/snake.lua with the Lua controllers, done in C++ by
rm3d.evaluate; the fitness is the metric the world sets at its end, speed_m_s (head's progress
along +x per second). Prints the best speed of every generation, then the first generation's best
and the best found.

    PYTHONPATH=build/python /usr/bin/python3 worlds/python/cmaes_gait.py [--quick]
"""
import argparse
import pathlib
import sys

import numpy as np
from cmaes import CMA

import rm3d

ROOT = pathlib.Path(__file__).resolve().parents[2]
WORLD = ROOT / "worlds" / "snake.lua"

# amplitude (rad), period (s), lag between neighbours (rad)
NAMES = ("amplitude", "period", "lag")
BOUNDS = np.array([[0.1, 1.2], [0.6, 3.0], [0.3, 2.5]])


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="a short run (the test suite's)")
    ap.add_argument("--generations", type=int, default=None)
    ap.add_argument("--population", type=int, default=None)
    ap.add_argument("--seconds", type=float, default=None, help="simulated seconds per run")
    ap.add_argument("--modules", type=int, default=10)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--seed", type=int, default=1, help="the optimiser's seed")
    args = ap.parse_args(argv)
    generations = args.generations or (6 if args.quick else 15)
    population = args.population or (8 if args.quick else 12)
    seconds = args.seconds or (2.0 if args.quick else 6.0)

    # A deliberately poor start (small, slow wave) so that the search has somewhere to go.
    start = np.array([0.25, 2.5, 0.6])
    opt = CMA(mean=start, sigma=0.3, bounds=BOUNDS, seed=args.seed, population_size=population)
    first = None
    best, best_x = -np.inf, None
    for gen in range(generations):
        xs = [opt.ask() for _ in range(opt.population_size)]
        params = [dict(zip(NAMES, map(float, x)), modules=args.modules) for x in xs]
        speeds = rm3d.evaluate(str(WORLD), params=params, seconds=seconds,
                               threads=args.threads, metric="speed_m_s")
        speeds = np.where(np.isfinite(speeds), speeds, -1.0)  # a run without the metric
        opt.tell([(x, -float(s)) for x, s in zip(xs, speeds)])  # CMA minimises
        i = int(np.argmax(speeds))
        if speeds[i] > best:
            best, best_x = float(speeds[i]), xs[i]
        if first is None:
            first = float(speeds[i])
        print("generation %2d: best %.4f m/s (amplitude %.3f rad, period %.3f s, lag %.3f rad)"
              % (gen + 1, speeds[i], *xs[i]), flush=True)
    print("first generation best %.4f m/s, best %.4f m/s (amplitude %.3f rad, period %.3f s, "
          "lag %.3f rad)" % (first, best, *best_x))
    return 0 if best > first else 1


if __name__ == "__main__":
    sys.exit(main())
