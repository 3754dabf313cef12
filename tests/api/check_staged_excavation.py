"""Physics check of examples/staged-excavation.json: geostatic clay, a pit
dug in stage 2 (body 0 removed), then swelling under the pit.

Usage: check_staged_excavation.py EXAMPLE.json RESULTS_DIR

Checked:
1. Stage 1 is the geostatic closed form: at t = 0 every series particle has
   p = rho_f g (10 - y) (relative 1e-9: the closed form is set exactly).
2. Conservation of momentum at rest (the quasi-static scheme has no
   inertia): over stage 2 the base's vertical reaction (boundaries[0] of the
   stage) equals the weight of the soil left, rho_sat g (200 - 15) m^2 per
   metre, to 1e-6 relative (the Newton tolerance is 1e-8 of the load terms;
   measured 1e-10); the side walls and the p = 0 faces add no vertical force.
   Without the removal the base would carry 200 m^2: 8 % more.
3. The dug particle (in the pit) has values before the excavation and null
   after it; the others have values throughout.
4. Swelling: after the excavation the pore pressure under the pit's centre
   rises and the floor heaves, both monotonically (suction dissipating; a
   sign error in the removal or the drainage would reverse them).
"""
import sys

import example_results


def main():
    spec, _, read = example_results.load()
    series, reactions = read("series.json"), read("reactions.json")
    g = -spec["gravity"][1]
    clay = spec["materials"]["clay"]
    n = clay["hydraulic"]["porosity"]
    rho_sat = (1 - n) * clay["density"] + n * 1000.0
    stage_one = spec["time"]["end"]
    failures = []

    times = series["time"]
    for q in series["particles"]:
        y = q["initial_position"][1]
        p0 = q["pore_pressure"][0]
        exact = 1000.0 * g * (10.0 - y)
        if abs(p0 - exact) > 1e-9 * exact:
            failures.append(f"t = 0, y = {y}: p = {p0}, geostatic {exact}")
    in_pit = [q for q in series["particles"] if q["initial_position"][1] > 7.0]
    below = [q for q in series["particles"] if q["initial_position"][1] < 7.0]
    for q in in_pit:
        after = [v for t, v in zip(times, q["pore_pressure"]) if t > stage_one]
        if q["pore_pressure"][0] is None or any(v is not None for v in after):
            failures.append(f"pit particle {q['index']}: values after its removal")
    for q in below:
        p = [v for t, v in zip(times, q["pore_pressure"]) if t > stage_one]
        uy = [d[1] for t, d in zip(times, q["displacement"]) if t > stage_one]
        if any(v is None for v in p):
            failures.append(f"particle {q['index']}: null values")
            continue
        if any(b < a for a, b in zip(p, p[1:])) or any(b < a for a, b in zip(uy, uy[1:])):
            failures.append(f"particle {q['index']} at y = {q['initial_position'][1]}: "
                            "p or the heave not monotonically rising")
        if not uy[-1] > 0:
            failures.append(f"particle {q['index']}: no heave ({uy[-1]} m)")

    weight = rho_sat * g * (20.0 * 10.0 - 5.0 * 3.0)
    base = reactions["boundaries"][0]["force"]
    worst = max(abs(f[1] - weight) / weight for f in base)
    if worst > 1e-6:
        failures.append(f"base reaction differs from the weight left by {worst:.3g} (relative)")

    print(f"staged excavation: geostatic at t = 0 checked at {len(series['particles'])} points; "
          f"base reaction vs weight left ({weight:.6g} N/m) worst {worst:.3g} over "
          f"{len(base)} samples; final heave under the pit "
          f"{below[0]['displacement'][-1][1] * 1000:.2f} mm")
    for f in failures:
        print("FAIL:", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
