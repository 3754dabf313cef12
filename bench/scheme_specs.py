"""Writes the job specs of bench/schemes.sh (docs/performance.md, "Time
schemes") into a directory:

  terzaghi-real-<scheme>.json  verification §9, real water (H = 1 m, E = 10 MPa,
                               nu = 0, n = 0.3, k = 1e-3 m/s, Kw = 2.2 GPa,
                               q = 10 kPa), 40 cells x 2 particles, to T_v = 1
  embankment-<size>-<scheme>[-<solver>][-short].json
                               examples/embankment.json refined to about
                               <size> particles (10k, 100k, 400k);
                               -short: the first STEPS steps only

Usage: scheme_specs.py ROOT OUT_DIR
"""
import copy
import json
import os
import sys

SIZES = {"10k": (80, 40), "100k": (226, 113), "400k": (452, 226)}
SHORT_STEPS = 8


def terzaghi_real(scheme):
    h_cells, ppc, H, q = 40, 2, 1.0, 1e4
    e, nu, n, k, kw = 10e6, 0.0, 0.3, 1e-3, 2.2e9
    m_v = (1 + nu) * (1 - 2 * nu) / (e * (1 - nu))
    c_v = k / (9810 * (m_v + n / kw))
    dp = H / (h_cells * ppc)
    return {
        "name": f"terzaghi-real-{scheme}",
        "dimension": 1,
        "grid": {"min": [0.0], "max": [H], "cells": [h_cells]},
        "materials": {"soil": {"model": "linear_elastic", "density": 2650.0, "youngs_modulus": e,
                               "poisson_ratio": nu,
                               "hydraulic": {"porosity": n, "hydraulic_conductivity": k,
                                             "fluid_bulk_modulus": kw, "fluid_density": 1000.0}}},
        "bodies": [{"material": "soil", "box": {"min": [0.0], "max": [H]}, "particles_per_cell": ppc,
                    "initial": {"pore_pressure": q, "effective_stress": [0, 0, 0, 0, 0, 0]}}],
        "gravity": [0.0],
        "boundaries": [{"nodes": {"box": {"min": [0.0], "max": [0.0]}}, "velocity": [0.0]},
                       {"nodes": {"box": {"min": [H], "max": [H]}}, "pore_pressure": 0.0}],
        "tractions": [{"particles": {"box": {"min": [H - dp], "max": [H]}}, "face": "x+",
                       "traction": [-q]}],
        "time": {"end": H * H / c_v, "scheme": scheme},
    }


def embankment(root, size, scheme, solver=None, short=False):
    with open(os.path.join(root, "examples", "embankment.json")) as f:
        spec = json.load(f)
    spec = copy.deepcopy(spec)
    nx, ny = SIZES[size]
    spec["grid"]["cells"] = [nx, ny]
    W, H = spec["grid"]["max"]
    dp = H / ny / spec["bodies"][0]["particles_per_cell"]
    spec["tractions"][0]["particles"]["box"]["min"][1] = H - dp
    spec["output"] = {}
    t = spec["time"]
    if scheme != "quasi_static":
        t.pop("dt", None)
        t["scheme"] = scheme
        if short:
            # 10 steps of the skeleton's wave limit 0.5 h/(c_d sqrt 2),
            # c_d = sqrt(E_oed/rho) = 60.7 m/s for this clay
            t["end"] = 10 * 0.5 * (H / ny) / (60.7 * 2 ** 0.5)
    elif short:
        # the first SHORT_STEPS steps of the growth
        g = t["dt"]
        t["end"] = sum(g["initial"] * g["growth"] ** i for i in range(SHORT_STEPS))
    if solver:
        t["implicit"] = {"linear_solver": solver}
    name = f"embankment-{size}-{scheme}" + (f"-{solver}" if solver else "") + ("-short" if short else "")
    spec["name"] = name
    return name, spec


def main():
    root, out = sys.argv[1:3]
    os.makedirs(out, exist_ok=True)
    specs = {}
    for scheme in ("explicit", "semi_implicit", "quasi_static"):
        specs[f"terzaghi-real-{scheme}"] = terzaghi_real(scheme)
    for size in SIZES:
        for args in [("quasi_static",), ("quasi_static", "direct", True),
                     ("quasi_static", "iterative", True), ("semi_implicit", "direct", True),
                     ("semi_implicit", "iterative", True), ("explicit",)]:
            scheme = args[0]
            solver = args[1] if len(args) > 1 else None
            short = len(args) > 2
            name, spec = embankment(root, size, scheme, solver, short)
            specs[name] = spec
    for name, spec in specs.items():
        with open(os.path.join(out, name + ".json"), "w") as f:
            json.dump(spec, f, indent=1)


if __name__ == "__main__":
    main()
