"""Shared by the random-field studies of issue 43 (check_random_bearing.py,
check_random_slope.py, plot_random_field.py): running many `hmpm run`
samples in parallel processes, reading a snapshot's fields back with the
standard library, and the binomial confidence intervals.

Standard library only (the figures import matplotlib themselves).
"""
import base64
import concurrent.futures
import json
import math
import os
import struct
import subprocess
import xml.etree.ElementTree as ET


def run(hmpm, work, name, spec, threads=1):
    """Runs one spec with the hmpm CLI; returns (result directory, summary.json)."""
    os.makedirs(work, exist_ok=True)
    path = os.path.join(work, name + ".json")
    with open(path, "w") as f:
        json.dump(spec, f)
    out = os.path.join(work, name)
    subprocess.run([hmpm, "run", path, "--out", out, "--threads", str(threads)], check=False,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    with open(os.path.join(out, "summary.json")) as f:
        return out, json.load(f)


def run_all(hmpm, work, jobs, processes):
    """jobs: [(name, spec)]; runs them in `processes` single-threaded hmpm
    processes at a time; returns {name: (result directory, summary)}."""
    with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, processes)) as pool:
        futures = {name: pool.submit(run, hmpm, work, name, spec) for name, spec in jobs}
        return {name: f.result() for name, f in futures.items()}


def read_vtu(path):
    """{name: list of tuples (or floats for one component)} of a snapshot's
    PointData, plus "Points": [(x, y, z)]. hmpm's VTU arrays are one base64
    block each: a UInt64 byte count, then the little-endian values."""
    root = ET.parse(path).getroot()
    codes = {"Float64": "d", "Int32": "i", "Int64": "q", "UInt8": "B"}
    piece = root.find("./UnstructuredGrid/Piece")
    out = {}
    for arr in list(piece.find("PointData")) + list(piece.find("Points")):
        raw = base64.b64decode(arr.text.strip())
        (nbytes,) = struct.unpack_from("<Q", raw, 0)
        code = codes[arr.get("type")]
        values = struct.unpack_from(f"<{nbytes // struct.calcsize(code)}{code}", raw, 8)
        nc = int(arr.get("NumberOfComponents", "1"))
        out[arr.get("Name")] = list(values) if nc == 1 else [values[i:i + nc] for i in range(0, len(values), nc)]
    return out


def snapshots(out):
    """[(time, path)] of a result directory's snapshots.pvd."""
    root = ET.parse(os.path.join(out, "snapshots.pvd")).getroot()
    return [(float(d.get("timestep")), os.path.join(out, d.get("file"))) for d in root.iter("DataSet")]


def phi(z):
    """The standard normal distribution function."""
    return 0.5 * math.erfc(-z / math.sqrt(2))


def wilson(k, n, z=1.959964):
    """Wilson's score interval for a binomial proportion k / n (95 % at z = 1.96)."""
    p = k / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z / (1 + z * z / n) * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n))
    return max(0.0, centre - half), min(1.0, centre + half)


def _beta_cdf(x, a, b):
    """The regularised incomplete beta function I_x(a, b) for integer a, b >= 1,
    as the binomial tail: I_x(a, b) = P[Bin(a + b - 1, x) >= a]."""
    n = a + b - 1
    return sum(math.comb(n, j) * x ** j * (1 - x) ** (n - j) for j in range(a, n + 1))


def clopper_pearson(k, n, alpha=0.05):
    """The exact (Clopper-Pearson) interval: the p at which P[X >= k] = alpha / 2
    and P[X <= k] = alpha / 2, by bisection on the binomial tails."""

    def solve(f, target):
        lo, hi = 0.0, 1.0
        for _ in range(200):
            mid = (lo + hi) / 2
            if f(mid) < target:
                lo = mid
            else:
                hi = mid
        return (lo + hi) / 2

    lower = 0.0 if k == 0 else solve(lambda p: _beta_cdf(p, k, n - k + 1), alpha / 2)
    # P[X <= k] = 1 - P[X >= k + 1] = alpha / 2
    upper = 1.0 if k == n else solve(lambda p: _beta_cdf(p, k + 1, n - k), 1 - alpha / 2)
    return lower, upper
