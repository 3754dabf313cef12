#!/usr/bin/env python3
"""Figure of docs/verification.md, "Drained surfaces inside the grid":
Terzaghi's column drained by surface_pressures on its top face, the surface
on a node row with three empty cells above (explicit scheme, every shape
function), and the matrix of SurfacePressures.TerzaghiDrainedByTheSoilsOwnSurface.

  build/bin/hmpm_solver_tests --gtest_filter='SurfacePressures.Terzaghi*' \
      | grep '\\[ surface \\]' | sed 's/\\[ surface \\] //' > /tmp/matrix.txt
  /usr/bin/python3 scripts/surface_pressures_figure.py build/bin/hmpm /tmp/matrix.txt

Writes docs/figures/surface-pressures-matrix.png.
"""
import json
import math
import os
import subprocess
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

H, Q, E, N, KW, K = 1.0, 1e3, 50e6, 0.3, 75e6, 1.2e-5  # the test's column
CV = K / (1000 * 9.81 * (1 / E + N / KW))


def terzaghi(z, tv):
    total = 0.0
    for m in range(200):
        big_m = math.pi * (2 * m + 1) / 2
        total += 2 / big_m * math.sin(big_m * z / H) * math.exp(-big_m * big_m * tv)
    return total


def column(hmpm, shape, ppc, cells=20):
    h = H / cells
    top = [H - h / ppc]
    spec = {
        "dimension": 1, "shape_function": shape,
        "grid": {"min": [0.0], "max": [(cells + 3) * h], "cells": [cells + 3]},
        "materials": {"s": {"model": "linear_elastic", "density": 2650.0, "youngs_modulus": E,
                            "poisson_ratio": 0.0,
                            "hydraulic": {"porosity": N, "hydraulic_conductivity": K,
                                          "fluid_bulk_modulus": KW, "fluid_density": 1000.0}}},
        "bodies": [{"material": "s", "box": {"min": [0.0], "max": [H]},
                    "particles_per_cell": ppc, "initial": {"pore_pressure": Q}}],
        "gravity": [0.0],
        "boundaries": [{"nodes": {"box": {"min": [0.0], "max": [0.0]}}, "velocity": [0.0]}],
        "tractions": [{"particles": {"box": {"min": top, "max": [H]}}, "face": "x+",
                       "traction": [-Q]}],
        "surface_pressures": [{"particles": {"box": {"min": top, "max": [H]}}, "face": "x+",
                               "pore_pressure": 0.0}],
        "time": {"end": 0.2 * H * H / CV},
        "output": {"series": {"particles": list(range(cells * ppc)), "fields": ["pore_pressure"],
                              "interval": 0.05 * H * H / CV}},
    }
    with tempfile.TemporaryDirectory() as d:
        with open(os.path.join(d, "spec.json"), "w") as f:
            json.dump(spec, f)
        subprocess.run([hmpm, "run", os.path.join(d, "spec.json"), "--out",
                        os.path.join(d, "out"), "--threads", "1"], check=True,
                       capture_output=True)
        with open(os.path.join(d, "out", "series.json")) as f:
            return json.load(f)


def main():
    hmpm, matrix = sys.argv[1], sys.argv[2]
    fig, (a, b) = plt.subplots(1, 2, figsize=(12, 5))
    colours = {"linear": "C0", "gimp": "C1", "bspline": "C2"}
    for shape, ppc, marker in [("linear", 1, "o"), ("gimp", 1, "s"), ("bspline", 1, "^"),
                               ("bspline", 2, "x")]:
        s = column(hmpm, shape, ppc)
        for row in (1, 2, 4):
            z = [H - p["initial_position"][0] for p in s["particles"]]
            p = [p["pore_pressure"][row] / Q for p in s["particles"]]
            a.plot(p, z, marker, ms=4, mfc="none", color=colours[shape],
                   label=f"{shape}, {ppc} per cell" if row == 1 else None)
    zz = [i / 200 for i in range(201)]
    for tv, z_label in ((0.05, 0.3), (0.1, 0.45), (0.2, 0.6)):
        a.plot([terzaghi(z, tv) for z in zz], zz, "k-", lw=1,
               label="Terzaghi" if tv == 0.05 else None)
        a.annotate(f"T_v = {tv}", (terzaghi(z_label, tv) + 0.02, z_label), fontsize=8)
    a.invert_yaxis()
    a.set_xlabel("p / q")
    a.set_ylabel("depth below the surface / H")
    a.set_title("Explicit scheme, surface on a node row, 3 empty cells above")
    a.legend(fontsize=8)
    columns = [(s, p) for s in ["linear", "gimp", "bspline"] for p in ["1", "2"]]
    table = {}
    with open(matrix) as f:
        for line in f:
            parts = line.split()
            key = (" ".join(parts[0:3]), parts[3])
            table.setdefault(key, {})[(parts[4], parts[5])] = 100 * float(parts[9].rstrip(","))
    labels = [f"{g}, {s}" for g, s in table]
    data = [[d.get(c, float("nan")) for c in columns] for d in table.values()]
    image = b.imshow(data, cmap="viridis_r", vmin=0, vmax=3.5, aspect="auto")
    for i, row in enumerate(data):
        for j, v in enumerate(row):
            if v == v:
                b.text(j, i, f"{v:.2f}", ha="center", va="center", fontsize=7,
                       color="w" if v > 1.8 else "k")
    b.set_xticks(range(len(columns)))
    b.set_xticklabels([f"{s} {p}" for s, p in columns], rotation=30, fontsize=8)
    b.set_yticks(range(len(labels)))
    b.set_yticklabels(labels, fontsize=8)
    b.set_title("max |p - p_Terzaghi| / q (%), interior, T_v 0.05-0.2")
    fig.colorbar(image, ax=b, fraction=0.04)
    fig.tight_layout()
    fig.savefig("docs/figures/surface-pressures-matrix.png", dpi=110)


if __name__ == "__main__":
    main()
