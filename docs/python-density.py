#!/usr/bin/env python3
"""Runs a crowddb scenario from Python and plots where the crowd was dense.

    PYTHONPATH=build/python python3 docs/python-density.py scenarios/bottleneck.json \\
        --seconds 60 --out bottleneck-density.png

The map is the mean density [persons/m^2] over the run, from the agents' positions after every
tick, in cells of --cell metres; the agents of the last tick are drawn on top at their radius.
"""
import argparse

import matplotlib

matplotlib.use("Agg")  # no display needed
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import crowddb  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scenario")
    ap.add_argument("--seconds", type=float, default=60.0, help="simulated time [s]")
    ap.add_argument("--cell", type=float, default=0.5, help="density cell [m]")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--out", default="density.png")
    args = ap.parse_args()

    sim = crowddb.Simulation.from_file(args.scenario, threads=args.threads)
    xs, ys = [], []
    ticks = max(1, round(args.seconds / sim.dt))
    for _ in range(ticks):
        sim.step()
        a = sim.agents
        xs.append(a.x.copy())  # the views are valid until the next step: keep copies
        ys.append(a.y.copy())
    x, y = np.concatenate(xs), np.concatenate(ys)
    if x.size == 0:
        raise SystemExit("no agents to plot")
    x0, x1 = np.floor(x.min()) - 1, np.ceil(x.max()) + 1
    y0, y1 = np.floor(y.min()) - 1, np.ceil(y.max()) + 1
    bins = (np.arange(x0, x1 + args.cell, args.cell), np.arange(y0, y1 + args.cell, args.cell))
    counts, ex, ey = np.histogram2d(x, y, bins=bins)
    density = counts / ticks / args.cell**2

    fig, ax = plt.subplots(figsize=(9, 9 * (y1 - y0) / max(x1 - x0, 1e-9) + 1))
    im = ax.imshow(density.T, origin="lower", extent=(ex[0], ex[-1], ey[0], ey[-1]),
                   cmap="magma", interpolation="nearest")
    fig.colorbar(im, ax=ax, label="mean density [persons/m²]", shrink=0.8)
    a = sim.agents
    for px, py, r in zip(a.x, a.y, a.radius):
        ax.add_patch(plt.Circle((px, py), r, fill=False, color="cyan", lw=0.5))
    ax.set(xlabel="x [m]", ylabel="y [m]", aspect="equal",
           title=f"{args.scenario}: {sim.time:.0f} s, {sim.arrived_total} arrived, "
                 f"{len(a)} still walking")
    fig.savefig(args.out, dpi=120, bbox_inches="tight")
    print(f"{args.out}: peak {density.max():.2f} persons/m², {sim.arrived_total} arrived")


if __name__ == "__main__":
    main()
