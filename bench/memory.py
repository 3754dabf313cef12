#!/usr/bin/env python3
"""Memory estimate against measured peak RSS (docs/performance.md, "Memory
estimate").

For a few job sizes and thread counts, runs `hmpm validate --threads N`
(the estimate) and `hmpm run --threads N` (peak RSS from wait4's
ru_maxrss) and prints estimate, RSS and their ratio.

    python3 bench/memory.py [BUILD_DIR]

The cases (`CASES`) are shared with tests/hostile/test_limits.py.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]

SOIL = {"model": "linear_elastic", "density": 2650.0, "youngs_modulus": 1.0e7,
        "poisson_ratio": 0.0,
        "hydraulic": {"porosity": 0.3, "hydraulic_conductivity": 1e-5,
                      "fluid_bulk_modulus": 7.5e7, "fluid_density": 1000.0}}


def grid_case(cells: int, body_cells: int, ppc: int, steps: int = 3) -> dict:
    """2D saturated block of body_cells^2 cells (ppc^2 particles each) in a
    grid of cells^2: a large grid makes the per-thread buffers count."""
    h = 1.0 / cells
    top = body_cells * h
    return {
        "name": f"mem-grid-{cells}-{body_cells}-{ppc}", "dimension": 2,
        "grid": {"min": [0.0, 0.0], "max": [1.0, 1.0], "cells": [cells, cells]},
        "materials": {"soil": SOIL},
        "bodies": [{"material": "soil", "box": {"min": [0.0, 0.0], "max": [top, top]},
                    "particles_per_cell": ppc}],
        "gravity": [0.0, -9.81],
        "time": {"end": steps * 1e-7, "dt": 1e-7},
    }


def series_case(cells: int, series_particles: int, rows: int) -> dict:
    """1D saturated column of `cells` cells whose series keeps
    `series_particles` particles x (pore pressure, displacement, stress)
    for `rows` rows in memory until the run ends."""
    spec = {
        "name": f"mem-series-{cells}-{series_particles}-{rows}", "dimension": 1,
        "grid": {"min": [0.0], "max": [1.0], "cells": [cells]},
        "materials": {"soil": SOIL},
        "bodies": [{"material": "soil", "box": {"min": [0.0], "max": [1.0]},
                    "particles_per_cell": 1, "initial": {"pore_pressure": 1000.0}}],
        "gravity": [0.0],
        "boundaries": [{"nodes": {"box": {"min": [0.0], "max": [0.0]}}, "velocity": [0.0]}],
        "time": {"end": rows * 1e-8, "dt": 1e-8},
        "output": {"series": {"particles": list(range(series_particles)),
                              "fields": ["pore_pressure", "displacement", "effective_stress"],
                              "interval": 1e-8}},
    }
    return spec


CASES = [  # (spec, threads)
    (grid_case(800, 400, 1), 1),
    (grid_case(800, 400, 1), 8),
    (grid_case(1500, 450, 1), 8),
    (grid_case(400, 400, 2), 2),
    (series_case(2000, 2000, 2000), 1),
    (series_case(1000, 1000, 1000), 1),
]

_UNITS = {"B": 1, "KiB": 1 << 10, "MiB": 1 << 20, "GiB": 1 << 30}


def hmpm_binary(build: Path) -> Path:
    return build / "bin" / "hmpm"


def estimate_bytes(hmpm: Path, spec_path: Path, threads: int) -> float:
    out = subprocess.run([str(hmpm), "validate", str(spec_path), "--threads", str(threads)],
                         capture_output=True, text=True, check=True, timeout=60).stdout
    m = re.search(r"memory ~([0-9.]+) (B|KiB|MiB|GiB)", out)
    if not m:
        raise RuntimeError(f"no memory estimate in: {out}")
    return float(m.group(1)) * _UNITS[m.group(2)]


def peak_rss_bytes(hmpm: Path, spec_path: Path, threads: int, out_dir: Path) -> float:
    """Runs the job; its peak resident set (ru_maxrss of that child only).

    The run is started by a fresh interpreter, not by this process: a child's
    ru_maxrss keeps the resident set it had before exec, which for a child
    forked by a large test process (a few hundred MiB after an attack test)
    would be counted as the job's. The fresh interpreter adds ~10 MiB at most.
    """
    launcher = (
        "import os, sys\n"
        "pid = os.posix_spawn(sys.argv[1], sys.argv[1:], os.environ,"
        " file_actions=[(os.POSIX_SPAWN_OPEN, 1, os.devnull, os.O_WRONLY, 0)])\n"
        "_, status, usage = os.wait4(pid, 0)\n"
        "print(os.waitstatus_to_exitcode(status), usage.ru_maxrss)\n")
    r = subprocess.run([sys.executable, "-c", launcher, str(hmpm), "run", str(spec_path), "--out",
                        str(out_dir), "--threads", str(threads)],
                       capture_output=True, text=True)
    fields = r.stdout.split()
    if r.returncode != 0 or len(fields) != 2 or fields[0] != "0":
        raise RuntimeError(f"hmpm run failed ({r.stdout.strip()!r}): {r.stderr!r}")
    return int(fields[1]) * 1024.0


def measure(hmpm: Path, spec: dict, threads: int) -> tuple[float, float]:
    with tempfile.TemporaryDirectory(prefix="hmpm-mem-") as tmp:
        path = Path(tmp) / "spec.json"
        path.write_text(json.dumps(spec))
        return (estimate_bytes(hmpm, path, threads),
                peak_rss_bytes(hmpm, path, threads, Path(tmp) / "out"))


def main(argv: list[str]) -> int:
    build = Path(argv[0]) if argv else Path(os.environ.get("HMPM_BUILD_DIR", REPO / "build"))
    hmpm = hmpm_binary(build)
    print(f"{'case':34s} {'threads':>7s} {'estimate MiB':>12s} {'RSS MiB':>9s} {'est/RSS':>7s}")
    for spec, threads in CASES:
        est, rss = measure(hmpm, spec, threads)
        print(f"{spec['name']:34s} {threads:7d} {est / 2**20:12.1f} {rss / 2**20:9.1f} "
              f"{est / rss:7.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
