#!/usr/bin/python3
"""Trains a chain of SuperBots to crawl, from Python, on the per-module arrays (numpy only).

The world is worlds/python/py_chain.lua (7 modules by default, policy=True): each module's
observation row is its pitch angle and velocity, its action row its pitch servo target, and its
reward how far the chain's mean x moved in the step (so an episode's return is the distance
crawled along +x). One small linear policy is shared by every module:

    target_i = theta . [sin(phase_i), cos(phase_i), angle_i, velocity_i / 10, 1]
    phase_i  = 2 pi t / 1.5 s + i 2 pi / 5        (a clock, shifted down the chain)

and an evolution strategy (antithetic Gaussian perturbations, centred ranks) improves theta.
Every generation's candidates run together in one rm3d.Batch (one world per candidate, plus
one for the current policy). Writes the learning curve as CSV and PNG (through `rm3d plot`) and
prints "untrained X m, trained Y m".

    PYTHONPATH=build/python /usr/bin/python3 worlds/python/train_chain.py [--quick] [--out DIR]
"""
import argparse
import pathlib
import subprocess
import sys

import numpy as np

import rm3d

ROOT = pathlib.Path(__file__).resolve().parents[2]
WORLD = ROOT / "worlds" / "python" / "py_chain.lua"
PERIOD, LAG, LIMIT = 1.5, 2 * np.pi / 5, 1.5
DT = 1 / 60  # py_chain.lua's world.set{dt = 1 / 60}



def features(obs, t):
    """(worlds, modules, 5): the clock's sine and cosine, pitch angle and velocity, 1."""
    w, m = obs.shape[:2]
    phase = 2 * np.pi * t[:, None] / PERIOD + LAG * np.arange(m)[None, :]
    f = np.empty((w, m, 5))
    f[..., 0], f[..., 1] = np.sin(phase), np.cos(phase)
    f[..., 2], f[..., 3] = obs[..., 0], 0.1 * obs[..., 1]  # velocity in 10 rad/s
    f[..., 4] = 1.0
    return f


def episodes(batch, thetas, steps):
    """Runs every world of the batch once with its own theta; returns the distance each crawled."""
    batch.reset()
    ret = np.zeros(len(batch))
    mask = np.asarray(batch.mask)
    for _ in range(steps):
        f = features(np.asarray(batch.obs), np.asarray(batch.time))
        a = np.einsum("wmk,wk->wm", f, thetas)
        batch.act[:, :, 0] = np.clip(a, -LIMIT, LIMIT)
        batch.step()
        ret += np.where(mask, batch.reward, 0).sum(axis=1) / mask.sum(axis=1)
    return ret


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="a short run (the test suite's)")
    ap.add_argument("--generations", type=int, default=None)
    ap.add_argument("--pairs", type=int, default=None, help="antithetic pairs per generation")
    ap.add_argument("--seconds", type=float, default=None, help="episode length (s)")
    ap.add_argument("--modules", type=int, default=7)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--sigma", type=float, default=0.1)
    ap.add_argument("--lr", type=float, default=0.05)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", default="out/train_chain", help="folder for curve.csv and curve.png")
    args = ap.parse_args(argv)
    generations = args.generations or (8 if args.quick else 20)
    pairs = args.pairs or (6 if args.quick else 8)
    seconds = args.seconds or (2.5 if args.quick else 5.0)
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)

    rng = np.random.default_rng(args.seed)
    worlds = 2 * pairs + 1  # world 0 runs the current policy, the rest its perturbations
    params = {"modules": args.modules, "seconds": seconds + 1}
    batch = rm3d.Batch(str(WORLD), seeds=[1] * worlds, params=params, threads=args.threads,
                       policy=True)
    steps = int(round(seconds / DT))
    theta = rng.normal(0, 0.02, 5)  # untrained: a faint random policy
    rows = []
    untrained = None
    for gen in range(generations + 1):
        eps = rng.normal(0, 1, (pairs, 5))
        thetas = np.vstack([theta, theta + args.sigma * eps, theta - args.sigma * eps])
        ret = episodes(batch, thetas, steps)
        if untrained is None:
            untrained = ret[0]
        rows.append((gen, ret[0], ret[1:].max()))
        print("generation %2d: policy %.3f m, best candidate %.3f m" % (gen, ret[0],
                                                                       ret[1:].max()), flush=True)
        if gen == generations:
            break
        # Centred ranks of the perturbations' returns, antithetic estimate of the gradient.
        r = ret[1:]
        ranks = np.empty(len(r))
        ranks[np.argsort(r)] = np.arange(len(r))
        ranks = ranks / (len(r) - 1) - 0.5
        grad = ((ranks[:pairs] - ranks[pairs:])[:, None] * eps).sum(axis=0) / (pairs * args.sigma)
        theta = theta + args.lr * grad
    trained = rows[-1][1]
    batch.close()

    csv = out / "curve.csv"
    with open(csv, "w") as fh:
        fh.write("generation,policy_m,best_candidate_m\n")
        for g, p, b in rows:
            fh.write("%d,%.6f,%.6f\n" % (g, p, b))
    print("wrote %s" % csv)
    png = out / "curve.png"
    cmd = [rm3d.executable(), "plot", str(csv), "--x", "generation", "--y",
           "policy_m,best_candidate_m", "--out", str(png), "--title",
           "train_chain: distance crawled in %.1f s" % seconds, "--ylabel", "distance (m)"]
    try:
        done = subprocess.run(cmd, capture_output=True, text=True)
        if done.returncode == 0:
            print("wrote %s" % png)
        else:
            print("rm3d plot failed (exit %d): %s" % (done.returncode, done.stderr.strip()),
                  file=sys.stderr)
    except OSError as e:
        print("could not run rm3d plot (%s): %s" % (cmd[0], e), file=sys.stderr)
    print("theta = [%s]" % ", ".join("%.3f" % v for v in theta))
    print("untrained %.3f m, trained %.3f m" % (untrained, trained))
    return 0 if trained > untrained else 1


if __name__ == "__main__":
    sys.exit(main())
