#!/usr/bin/python3
"""Evolves bodies: a genome (a list of whole numbers) becomes a SuperBot body through
worlds/python/py_morph.lua (--param genome=...: which module docks at which dock of which, and
each module's gait phase), and a population of different bodies is evaluated in ONE rm3d.Batch
per generation. Fitness: how far the body's centre moved over the ground (m); a body whose
modules overlap scores 0. Truncation selection with elitism, point mutation and one-point
crossover. Prints the best fitness of every generation, then the first's and the best found.

    PYTHONPATH=build/python /usr/bin/python3 worlds/python/morphology.py [--quick]
"""
import argparse
import pathlib
import sys

import numpy as np

import rm3d

ROOT = pathlib.Path(__file__).resolve().parents[2]
WORLD = ROOT / "worlds" / "python" / "py_morph.lua"
DT = 1 / 60  # py_morph.lua's world.set{dt = 1 / 60}
GENE_MAX = 6  # genes are 0..5 (py_morph.lua takes them modulo what they choose from)


def genome_text(g):
    return ",".join(str(int(v)) for v in g)


def evaluate(population, seconds, threads):
    """Every genome's fitness, all bodies in one Batch."""
    params = [{"genome": genome_text(g), "seconds": seconds + 1} for g in population]
    steps = int(round(seconds / DT))
    batch = rm3d.Batch(str(WORLD), seeds=[1] * len(population), params=params,
                            threads=threads)
    try:
        batch.step(steps)
        metrics = batch.metrics
        modules = np.asarray(batch.mask).sum(axis=1)
    finally:
        batch.close()
    fit = np.zeros(len(population))
    for i, m in enumerate(metrics):
        moved = float(m.get("moved", np.nan))
        fit[i] = moved if m.get("valid", 0) == 1 and np.isfinite(moved) else 0.0
    return fit, modules


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="a short run (the test suite's)")
    ap.add_argument("--generations", type=int, default=None)
    ap.add_argument("--population", type=int, default=None)
    ap.add_argument("--modules", type=int, default=5, help="modules per body (at most 16)")
    ap.add_argument("--seconds", type=float, default=None, help="simulated seconds per body")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--seed", type=int, default=3)
    args = ap.parse_args(argv)
    generations = args.generations or (8 if args.quick else 15)
    size = args.population or (12 if args.quick else 24)
    seconds = args.seconds or (3.0 if args.quick else 6.0)
    elite = max(2, size // 4)
    genes = 3 * (args.modules - 1)
    rng = np.random.default_rng(args.seed)

    population = [rng.integers(0, GENE_MAX, genes) for _ in range(size)]
    first, best, best_g, first_mean, last_mean = None, -np.inf, None, None, None
    for gen in range(generations):
        fit, modules = evaluate(population, seconds, args.threads)
        order = np.argsort(-fit, kind="stable")
        i = int(order[0])
        if fit[i] > best:
            best, best_g = float(fit[i]), population[i].copy()
        if first is None:
            first, first_mean = float(fit[i]), float(fit.mean())
        last_mean = float(fit.mean())
        print("generation %2d: best %.3f m (%d modules, genome %s), mean %.3f m"
              % (gen + 1, fit[i], modules[i], genome_text(population[i]), fit.mean()), flush=True)
        parents = [population[j] for j in order[:elite]]
        children = [p.copy() for p in parents]
        while len(children) < size:
            a, b = rng.choice(len(parents), 2)
            cut = rng.integers(1, genes) if genes > 1 else 0
            child = np.concatenate([parents[a][:cut], parents[b][cut:]])
            flip = rng.random(genes) < 1.5 / genes
            child[flip] = rng.integers(0, GENE_MAX, int(flip.sum()))
            children.append(child)
        population = children
    print("first generation best %.3f m, best %.3f m (genome %s); mean %.3f m -> %.3f m"
          % (first, best, genome_text(best_g), first_mean, last_mean))
    # Selection at work: the population got better. (A random first generation may already hold
    # the best body a short run finds, so the best alone is no test.)
    return 0 if last_mean > first_mean else 1


if __name__ == "__main__":
    sys.exit(main())
