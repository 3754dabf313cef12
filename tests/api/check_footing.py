"""Physics check of examples/footing.json: a rigid smooth strip footing
pushed into weightless undrained (Tresca) clay, its load-settlement curve
from the footing's reaction (reactions.json, boundaries[3]).

Usage: check_footing.py EXAMPLE.json RESULTS_DIR

Closed form: Prandtl's limit pressure q_u = (2 + pi) c_u of a smooth strip.
On the half model the footing is the row of prescribed nodes x in [0, b];
the soil between the last prescribed node (x = b) and the first free one
(x = b + h) is dragged down by the shape functions of both, so the edge of
the equivalent rigid strip lies somewhere in [b, b + h]: at this resolution
(h = b/5) the limit load per metre F_u is bracketed by q_u b and q_u (b + h),
a +-9 % uncertainty about q_u (b + h/2) that only a finer grid narrows. The
bracket is widened by 2 % for what else the grid and the particle
quadrature leave (measured: F_u = 5.62 c_u b = 5.11 c_u (b + h/2) here,
5.16 c_u (b + h/2) with 5 cm cells, i.e. within 0.6 % of the tributary-width
value). Checked:
1. The plateau: over settlements 1.8 ... 2.6 cm (after the elastic rise,
   before the soil has moved a quarter of a cell from the fixed footing
   row), the load varies by less than 3 % of its mean (a limit load is
   reached, not a curve still rising; measured about 0.5 %).
2. The plateau's mean F_u lies in [0.98 q_u b, 1.02 q_u (b + h)].
3. The start is elastic: at 0.1 % of B settlement the load is below a
   third of the limit load (a rigid-plastic jump would fail this).
The settlement is the integral of the prescribed velocity (the spec's
formula, evaluated here).
"""
import math
import sys

import example_results


def main():
    spec, _, read = example_results.load()
    reactions = read("reactions.json")
    clay = spec["materials"]["clay"]
    c_u = clay["cohesion"]
    assert clay["friction_angle"] == 0.0, "the check is Prandtl's Tresca solution"
    footing = spec["boundaries"][3]
    b = footing["nodes"]["box"]["max"][0]
    grid = spec["grid"]
    h = (grid["max"][0] - grid["min"][0]) / grid["cells"][0]
    formula = footing["velocity"][1]

    def velocity(t):
        return eval(formula, {"__builtins__": {}}, {"min": min, "t": t})  # muParser syntax is Python's here

    def settlement(t, n=2000):
        return -sum(velocity((k + 0.5) * t / n) for k in range(n)) * t / n

    times = reactions["time"]
    force = [-f[1] for f in next(e for e in reactions["boundaries"] if e["index"] == 3)["force"]]
    s = [settlement(t) for t in times]
    q_u = (2 + math.pi) * c_u
    problems = []
    for t, sk, fk in zip(times, s, force):
        print(f"t = {t:.3f} s  settlement {1000 * sk:6.2f} mm  F/(c_u b) = {fk / (c_u * b):.3f}")
    plateau = [fk for sk, fk in zip(s, force) if 0.018 <= sk <= 0.026]
    if len(plateau) < 4:
        problems.append(f"only {len(plateau)} samples on the plateau")
    else:
        mean = sum(plateau) / len(plateau)
        spread = (max(plateau) - min(plateau)) / mean
        print(f"plateau: F_u = {mean / (c_u * b):.3f} c_u b = {mean / (c_u * (b + h / 2)):.3f} "
              f"c_u (b + h/2) (Prandtl: {2 + math.pi:.3f}); spread {100 * spread:.2f} %")
        if spread > 0.03:
            problems.append(f"the load still varies by {100 * spread:.1f} % on the plateau")
        lo, hi = 0.98 * q_u * b, 1.02 * q_u * (b + h)
        if not lo <= mean <= hi:
            problems.append(f"F_u = {mean:.1f} N/m outside [{lo:.1f}, {hi:.1f}]")
    early = [fk for sk, fk in zip(s, force) if sk <= 0.001 * 2 * b]
    if not early or max(early) > q_u * b / 3:
        problems.append(f"no elastic start: loads {early} at settlements below {2 * b} mm (0.1 % of B)")
    for p in problems:
        print("FAIL:", p)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
