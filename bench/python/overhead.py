#!/usr/bin/env python3
"""The Python module's costs, measured against the CLI in one run (issue 14's acceptance):

1. reading all positions (sim.agents.x and .y) of 10^6 agents: time per read, and whether the
   arrays are views of the simulation's memory (no copy);
2. one step at 10^5 agents from Python vs `crowddb run` on the same scenario: median ms per tick
   over the same ticks, runs interleaved (CLI, Python, CLI, Python, ...).

    PYTHONPATH=build/python python3 bench/python/overhead.py --cli build/crowddb [--rounds 3]
"""
import argparse
import json
import os
import statistics
import subprocess
import tempfile
import time

import crowddb


def scenario(n: int) -> dict:
    side = (n / 0.5) ** 0.5  # 0.5 agents per m^2
    return {"name": f"uniform-{n}", "bounds": [0, 0, side, side], "seed": 3,
            "goals": [{"name": f"g{k}", "x": x, "y": y, "arrival_radius": 2}
                      for k, (x, y) in enumerate([(2, 2), (side - 2, 2), (2, side - 2),
                                                  (side - 2, side - 2)])],
            "groups": [{"count": n, "radius": 0.25,
                        "placement": {"type": "uniform", "region": [1, 1, side - 1, side - 1]},
                        "goals": {"assign": "random"}}]}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--cli", required=True)
    ap.add_argument("--agents", type=int, default=100_000)
    ap.add_argument("--read-agents", type=int, default=1_000_000)
    ap.add_argument("--ticks", type=int, default=20)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--rounds", type=int, default=3)
    args = ap.parse_args()
    tmp = tempfile.mkdtemp()

    # 1. Reading columns at 10^6 agents.
    big = os.path.join(tmp, "big.json")
    with open(big, "w") as f:
        json.dump(scenario(args.read_agents), f)
    sim = crowddb.Simulation.from_file(big, threads=args.threads)
    sim.step()
    reads = []
    for _ in range(1000):
        t0 = time.perf_counter()
        x, y = sim.agents.x, sim.agents.y
        reads.append(time.perf_counter() - t0)
    same = x.__array_interface__["data"][0] == sim.agents.x.__array_interface__["data"][0]
    print(f"read x and y of {len(x):,} agents: median {statistics.median(reads) * 1e6:.2f} us "
          f"per read; owndata={x.flags.owndata}, same memory on every read={same}")
    t0 = time.perf_counter()
    copy = x.copy()
    print(f"(for scale, one copy of x: {(time.perf_counter() - t0) * 1e3:.2f} ms, "
          f"{copy.nbytes / 1e6:.0f} MB)")
    del sim, x, y, copy

    # 2. A step at 10^5 agents: CLI vs Python, interleaved.
    path = os.path.join(tmp, "step.json")
    with open(path, "w") as f:
        json.dump(scenario(args.agents), f)
    cli_ms, py_ms = [], []
    for _ in range(args.rounds):
        summary = os.path.join(tmp, "s.json")
        subprocess.run([args.cli, "run", path, "--ticks", str(args.ticks), "--threads",
                        str(args.threads), "--no-output", "--quiet", "--summary-json", summary],
                       check=True)
        with open(summary) as f:
            cli_ms.append(json.load(f)["ms_per_tick_median"])
        sim = crowddb.Simulation.from_file(path, threads=args.threads)
        ticks = []
        for _ in range(args.ticks):
            t0 = time.perf_counter()
            sim.step()
            ticks.append(time.perf_counter() - t0)
        py_ms.append(statistics.median(ticks) * 1e3)
        del sim
    c, p = statistics.median(cli_ms), statistics.median(py_ms)
    print(f"step at {args.agents:,} agents, {args.threads} threads, median of {args.rounds} "
          f"rounds x {args.ticks} ticks: CLI {c:.1f} ms, Python {p:.1f} ms, "
          f"overhead {100 * (p - c) / c:+.1f} % (CLI rounds {cli_ms}, Python rounds "
          f"{[round(v, 1) for v in py_ms]})")


if __name__ == "__main__":
    main()
