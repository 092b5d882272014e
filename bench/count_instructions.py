#!/usr/bin/env python3
"""Instructions per tick of `crowddb run`, counted by valgrind's callgrind.

On one thread the count depends only on the binary and the input: two builds compare to the
instruction on a host whose speed swings by half between runs (docs/benchmarks.md), where timing
A B B A runs tells apart only changes of several per cent. A count is not a time: a change that
trades instructions for cache misses or mispredicted branches can count fewer and run slower
(the journal's stream meetings in lanes, 2026-12-05), so a change is kept on its timed runs;
the count says where the instructions go and whether a change removed the ones it meant to.

The tick's share is the difference of two runs (T1 and T0 ticks), so the scenario's loading and
the first ticks' warm-up drop out. Needs valgrind (`apt-get install valgrind`); each run takes
about fifty times as long as it does natively.

    bench/count_instructions.py build/crowddb /tmp/a20k.json 10 30
    bench/count_instructions.py --top 30 --threads 1 build/crowddb scenarios/airport.json 100 200
    bench/count_instructions.py --against /tmp/crowddb.before build/crowddb a20k.json 10 30

With --against, the other binary is counted the same way and the two are compared: the totals,
their ratio, whether the final state hashes agree, and the functions whose instructions changed
most.
"""
import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile


def fail(msg):
    print(f"count_instructions: {msg}", file=sys.stderr)
    sys.exit(2)


def count(crowddb, scenario, ticks, threads, workdir):
    """Instructions per function (self cost) of a run of `ticks` ticks."""
    out = os.path.join(workdir, f"callgrind.{ticks}.out")
    run = subprocess.run(
        ["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", crowddb, "run", scenario,
         "--ticks", str(ticks), "--no-output", "--threads", str(threads), "--quiet"],
        stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if run.returncode != 0 or not os.path.exists(out):
        own = [l for l in run.stderr.splitlines() if l.strip() and not l.startswith("==")]
        last = own[-1] if own else "no message"
        fail(f"{crowddb} run {scenario} --ticks {ticks} under valgrind failed "
             f"(exit {run.returncode}): {last}")
    hash_line = [l for l in run.stdout.splitlines() if "final state hash" in l]
    ann = subprocess.run(["callgrind_annotate", "--inclusive=no", "--threshold=100", out],
                         stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True)
    if ann.returncode != 0:
        fail(f"callgrind_annotate {out} failed: {ann.stderr.strip()}")
    costs = {}
    total = None
    for line in ann.stdout.splitlines():
        m = re.match(r"^\s*([\d,]+)\s+\([^)]*\)\s+(.*)$", line)
        if not m:
            continue
        value, name = int(m.group(1).replace(",", "")), m.group(2).strip()
        if name.startswith("PROGRAM TOTALS"):
            total = value
        else:
            name = re.sub(r"\s*\[[^\]]*\]$", "", name)  # the object file: differs between builds
            costs[name] = costs.get(name, 0) + value
    if total is None:
        fail(f"no total in callgrind_annotate's output for {out}")
    return total, costs, (hash_line[0].strip() if hash_line else "")


def main():
    p = argparse.ArgumentParser(
        description="Instructions per tick of `crowddb run` (callgrind), between two tick counts.")
    p.add_argument("crowddb", help="the crowddb binary")
    p.add_argument("scenario", help="a scenario file")
    p.add_argument("t0", type=int, help="ticks of the first run (its instructions are subtracted)")
    p.add_argument("t1", type=int, help="ticks of the second run (> t0)")
    p.add_argument("--threads", type=int, default=1,
                   help="threads (default 1; more make the count depend on the schedule)")
    p.add_argument("--top", type=int, default=20, help="functions listed (default 20)")
    p.add_argument("--against", metavar="BASE",
                   help="another crowddb binary to count the same way and compare with")
    a = p.parse_args()
    if a.t0 < 0 or a.t1 <= a.t0:
        fail(f"ticks: need 0 <= t0 < t1, got {a.t0} and {a.t1}")
    if a.threads < 1 or a.top < 0:
        fail("--threads must be at least 1 and --top at least 0")
    for tool in ("valgrind", "callgrind_annotate"):
        if not shutil.which(tool):
            fail(f"{tool} not found (apt-get install valgrind)")
    if not os.access(a.crowddb, os.X_OK):
        fail(f"{a.crowddb}: not an executable")
    if not os.path.isfile(a.scenario):
        fail(f"{a.scenario}: no such file")
    if a.against is not None and not os.access(a.against, os.X_OK):
        fail(f"{a.against}: not an executable")
    ticks = a.t1 - a.t0

    def per_tick(binary):
        with tempfile.TemporaryDirectory() as work:
            total0, costs0, _ = count(binary, a.scenario, a.t0, a.threads, work)
            total1, costs1, state = count(binary, a.scenario, a.t1, a.threads, work)
        names = set(costs0) | set(costs1)
        return ((total1 - total0) / ticks,
                {n: (costs1.get(n, 0) - costs0.get(n, 0)) / ticks for n in names}, state)

    total, costs, state = per_tick(a.crowddb)
    span = f"ticks {a.t0 + 1}-{a.t1}, {a.threads} thread(s)"
    if a.against is None:
        print(f"{a.scenario}: {total / 1e6:.3f} M instructions per tick over {span}; {state}")
        for name, c in sorted(costs.items(), key=lambda kv: -kv[1])[:a.top]:
            if c <= 0:
                break
            print(f"  {c / 1e6:8.3f} M  {100 * c / total:5.1f} %  {name[:150]}")
        return
    base, base_costs, base_state = per_tick(a.against)
    print(f"{a.scenario}, {span}: {total / 1e6:.3f} M instructions per tick ({a.crowddb}) against "
          f"{base / 1e6:.3f} M ({a.against}): {100 * (total - base) / base:+.2f} %")
    print(f"  {a.crowddb}: {state}")
    print(f"  {a.against}: {base_state}")
    if state != base_state:
        print("  the final state hashes differ: the two builds do not compute the same run")
    names = set(costs) | set(base_costs)
    diff = {n: costs.get(n, 0) - base_costs.get(n, 0) for n in names}
    for name, d in sorted(diff.items(), key=lambda kv: -abs(kv[1]))[:a.top]:
        if abs(d) < 100:  # (a run's own paths and numbers printed differ by a few instructions)
            break
        print(f"  {d / 1e6:+9.3f} M  {base_costs.get(name, 0) / 1e6:8.3f} -> "
              f"{costs.get(name, 0) / 1e6:8.3f} M  {name[:140]}")


if __name__ == "__main__":
    main()
