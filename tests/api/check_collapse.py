"""Collapse detection in the quasi-static scheme (issue 44): a strip
footing pushed past its limit load by a pressure that keeps rising.

Usage: check_collapse.py HMPM WORK_DIR

Weightless undrained clay (Mohr-Coulomb with phi = 0: Tresca), c_u =
10 kPa, E = 10 MPa, nu = 0.3, tension cut-off at c_u; half model of a
smooth flexible strip of half-width b = 0.5 m (a uniform pressure on the
top particles' faces x in [0, b]) on a layer 3 m wide and 2 m deep, base
fixed, sides rollers. The pressure rises as 6 c_u t / 1 s over 30
quasi-static steps, past Prandtl's limit (2 + pi) c_u = 5.14 c_u (the
same for a uniform pressure and a smooth rigid strip on weightless
Tresca soil). Expected: the run stops with a collapse (summary.json
"collapse", criterion no_convergence, status failed) at a load within 5 %
of Prandtl's, instead of crawling to time.end. Quadratic B-splines
(linear shape functions lock in isochoric plastic flow: +14 % at this
grid), 2 x 2 particles per cell. Two grids: h = 0.2 m (b / 2.5) and
0.1 m (b / 5): the finer is closer (measured +9.8 % and +5.0 %: the
tolerance is 5 % on the finer one with 0.5 % for the load bracket and
the step, and the coarser one must be farther).
Also: time.on_collapse "continue" still ends the run there (no state
exists past a limit load), with the collapse and a message that says so.
"""
import json
import math
import os
import subprocess
import sys

C_U, B = 1.0e4, 0.5


def spec(h, on_collapse=None):
    s = {
        "name": "footing-collapse", "dimension": 2, "shape_function": "bspline",
        "grid": {"min": [0.0, 0.0], "max": [3.0, 2.0 + 2 * h], "cells": [round(3.0 / h), round((2.0 + 2 * h) / h)]},
        "materials": {"clay": {"model": "mohr_coulomb", "density": 1800.0, "youngs_modulus": 1.0e7,
                               "poisson_ratio": 0.3, "friction_angle": 0.0, "dilatancy_angle": 0.0,
                               "cohesion": C_U, "tensile_strength": C_U}},
        "bodies": [{"material": "clay", "box": {"min": [0.0, 0.0], "max": [3.0, 2.0]}, "particles_per_cell": 2}],
        "boundaries": [
            {"nodes": {"box": {"min": [0.0, 0.0], "max": [3.0, 0.0]}}, "velocity": [0.0, 0.0]},
            {"nodes": {"box": {"min": [0.0, 0.0], "max": [0.0, 2.0 + 2 * h]}}, "velocity": [0.0, None]},
            {"nodes": {"box": {"min": [3.0, 0.0], "max": [3.0, 2.0 + 2 * h]}}, "velocity": [0.0, None]}],
        "tractions": [{"particles": {"box": {"min": [0.0, 2.0 - h / 2], "max": [B, 2.0]}}, "face": "y+",
                       "traction": [0.0, f"-{6 * C_U}*t"]}],
        "time": {"end": 1.0, "scheme": "quasi_static", "dt": 1.0 / 30},
    }
    if on_collapse:
        s["time"]["on_collapse"] = on_collapse
    return s


def run(hmpm, work, name, s):
    os.makedirs(work, exist_ok=True)
    path = os.path.join(work, name + ".json")
    with open(path, "w") as f:
        json.dump(s, f)
    out = os.path.join(work, name)
    subprocess.run([hmpm, "run", path, "--out", out], check=False, stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL)
    with open(os.path.join(out, "summary.json")) as f:
        return json.load(f)


def main():
    hmpm, work = sys.argv[1:3]
    prandtl = (2 + math.pi) * C_U
    problems, ratio = [], {}
    for h in (0.2, 0.1):
        s = run(hmpm, work, f"footing-{h}", spec(h))
        k = s.get("collapse")
        if s["status"] != "failed" or not k or k["criterion"] != "no_convergence" or not k["stopped"]:
            problems.append(f"h = {h}: no collapse reported: {s['status']}: {s['message']}")
            continue
        q = -k["load"][1] / B
        ratio[h] = q / prandtl
        print(f"h = {h} m: collapse at t = {k['time']:.4f} s, q = {q / C_U:.4f} c_u, "
              f"{ratio[h]:.4f} x Prandtl's (2 + pi) c_u; yielding {k['yielding_particles']} particles in "
              f"{k['yielding_min'][:2]} .. {k['yielding_max'][:2]}, max displacement "
              f"{k['max_displacement']:.4f} m, {s['end_time']:.4f} s reached of 1 s; message: {s['message']}")
        if "collapses" not in s["message"]:
            problems.append(f"h = {h}: the status message does not say collapse: {s['message']}")
    if 0.1 in ratio and not abs(ratio[0.1] - 1) <= 0.055:
        problems.append(f"h = 0.1: collapse load {ratio[0.1]:.4f} x Prandtl's, not within 5.5 %")
    if 0.1 in ratio and 0.2 in ratio and not abs(ratio[0.1] - 1) < abs(ratio[0.2] - 1):
        problems.append(f"the finer grid is not closer: {ratio}")
    s = run(hmpm, work, "footing-continue", spec(0.2, "continue"))
    k = s.get("collapse")
    if not k or s["status"] != "failed" or "cannot apply" not in s["message"]:
        problems.append(f"on_collapse continue: {s['status']}: {s['message']}")
    for p in problems:
        print("FAIL:", p)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
