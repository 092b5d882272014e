#!/usr/bin/env python3
"""Writes a head-on counter-flow scenario: N people walking east and N walking west, placed at
random in the two halves of a 4 m wide hallway of the given length (the measurements in
docs/verify.md, "Known limits").

    scripts/counterflow-scenario.py N LENGTH SEED > case.json
    ./build/crowddb run case.json --out case.sqlite
"""
import json
import sys


def scenario(n: int, length: float, seed: int) -> dict:
    width = 4.0
    half = length / 2
    return {
        "name": f"counterflow-{n}x2-{length:g}m-seed{seed}",
        "bounds": [0, 0, length, width], "duration": 120, "seed": seed,
        "goals": [{"name": "E", "area": [[length - 1, 0], [length, 0], [length, width], [length - 1, width]]},
                  {"name": "W", "area": [[0, 0], [1, 0], [1, width], [0, width]]}],
        "groups": [{"name": "eastbound", "count": n, "goal": "E", "radius": [0.2, 0.25], "pref_speed": [1.2, 1.4],
                    "placement": {"type": "uniform", "region": [1, 0, half - 0.5, width], "gap": 0.05}},
                   {"name": "westbound", "count": n, "goal": "W", "radius": [0.2, 0.25], "pref_speed": [1.2, 1.4],
                    "placement": {"type": "uniform", "region": [half + 0.5, 0, length - 1, width], "gap": 0.05}}],
    }


if __name__ == "__main__":
    if len(sys.argv) != 4:
        sys.exit("usage: counterflow-scenario.py N LENGTH SEED")
    json.dump(scenario(int(sys.argv[1]), float(sys.argv[2]), int(sys.argv[3])), sys.stdout, indent=1)
    print()
