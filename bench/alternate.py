#!/usr/bin/env python3
"""bench/alternate.py — compare benchmark commands on a noisy machine.

Runs the given bench_mpm command lines round robin, ROUNDS times each, and
prints the median and the best particle-steps/s of each. Alternating puts
every command through the same minutes of the machine, so the ratio of the
medians is trustworthy where single runs move by +-15 % (shared vCPUs).

    python3 bench/alternate.py 5 "OLD/bench_mpm --dim 2 --nb 158" "NEW/bench_mpm --dim 2 --nb 158"

Standard library only. Benchmarks, not tests: nothing here asserts a time.
"""
import re
import shlex
import statistics
import subprocess
import sys


def throughput(command):
    out = subprocess.run(shlex.split(command), capture_output=True, text=True, check=True).stdout
    match = re.search(r"particle_steps_per_second=([0-9.e+]+)", out)
    if not match:
        sys.exit(f"alternate.py: no particle_steps_per_second in the output of: {command}")
    return float(match.group(1))


def main(argv):
    if len(argv) < 3 or not argv[1].isdigit():
        sys.exit(__doc__)
    rounds, commands = int(argv[1]), argv[2:]
    results = {c: [] for c in commands}
    for _ in range(rounds):
        for c in commands:
            results[c].append(throughput(c) / 1e6)
    for c in commands:
        v = results[c]
        print(f"median {statistics.median(v):6.2f} M  best {max(v):6.2f} M  {c}")


if __name__ == "__main__":
    main(sys.argv)
