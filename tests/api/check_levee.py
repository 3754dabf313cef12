"""Physics check of examples/levee.json: a river levee on a clay blanket over
a sand aquifer, the river rising against it (issue 17). Reads the run's
profiles.json, series.json and summary.json back.

Usage: check_levee.py EXAMPLE.json RESULT_DIR
RESULT_DIR is what `hmpm run EXAMPLE.json --out RESULT_DIR` wrote (the CTest
entry api_example_levee). Soil constants and geometry come from the spec.

Reference: Bennett's blanket theory (1946; the basis of the US Army Corps of
Engineers' underseepage analysis). Flow in the aquifer (thickness D,
conductivity k_a) is horizontal, flow through the blanket (thickness z_b,
conductivity k_b) vertical, so the aquifer's head phi(x) obeys
    k_a D phi'' = (k_b / z_b) (phi - phi_top(x))
with phi_top the head above the blanket: the river's level h on the
riverside (x < toe), the ground surface on the landside (x > toe: a seepage
face, p = 0), and no leakage under the levee (its fill is 10x less permeable
than the blanket); phi(0) = h (the river meets the aquifer at the left wall)
and phi'(L) = 0 (the right wall is impermeable). The script solves it by
finite differences on 4000 intervals (a converged reference: halving them
changes phi by < 1e-6 m). Head phi = p / gamma_w + y.

Checked:
- after the gravity-loading stage (t = 2 days, before the river rises): the
  head along the aquifer (profile 0) is the initial water table, 6 m, within
  0.01 m, 0.4 % of the river's later rise (measured 0.0027 m: the levee's
  fill, 10x less permeable than the blanket, is still draining the excess
  its own weight caused, into the aquifer; a single step of the two days
  left 0.10 m, which is why the stage takes 12 growing steps);
- at the end (the river held at 8.5 m for a day): the head along the
  aquifer against the blanket theory within 2 % of the river's rise
  (measured 1.37 % with 0.5 m cells, 1.34 % with 0.25 m cells, and 1.37 %
  after five days of holding instead of one: neither the grid nor the
  transient; it is the theory's own approximation, horizontal flow in an
  aquifer whose thickness is 1/7 of the leakage length
  sqrt(k_a D z_b / k_b) = 28 m and vertical flow in the blanket, worst at
  the landside toe where the flow turns up);
- the uplift beyond the landside toe: the upward Darcy velocity at the top
  of the blanket (profile 1, its top row of particles) equals the blanket
  theory's k_b (phi - 6) / z_b with the measured aquifer head, within 3 %
  from 2 m beyond the toe (measured 1.08 % with 0.5 m cells, 0.88 % with
  0.25 m; at the toe itself the flow converges from under the levee and is
  2D);
- the riverside: water enters the blanket from the river (downward Darcy
  velocity at the blanket top under the river);
- the seepage face: the top row of the landside blanket, h/4 below the
  face, has the pressure of the upward flow beneath a face at p = 0,
  gamma_w d (1 + i) with d its depth and i = (phi - 6) / z_b the upward
  gradient, within 5 % (measured 1.1 % with 0.5 m cells, 2.5 % with
  0.25 m, where the row is h/4 = 6 cm deep and the pressure's linear
  interpolation near the face weighs more): the face holds p = 0;
- the run is successful, in 2 stages.
"""
import sys

import example_results

GAMMA_W = 9810.0


def blanket_theory(h, length, toe_river, toe_land, k_a, thickness, k_b, z_b, ground, n=4000):
    """phi(x) on [0, length] by finite differences (Thomas algorithm)."""
    dx = length / n
    trans = k_a * thickness
    lower, diag, upper, rhs = [0.0] * (n + 1), [0.0] * (n + 1), [0.0] * (n + 1), [0.0] * (n + 1)
    diag[0], rhs[0] = 1.0, h
    for i in range(1, n + 1):
        x = i * dx
        if x < toe_river:
            leak, top = k_b / z_b, h
        elif x <= toe_land:
            leak, top = 0.0, 0.0
        else:
            leak, top = k_b / z_b, ground
        a = trans / dx ** 2
        lower[i] = 2 * a if i == n else a  # phi'(L) = 0 by a mirrored node
        upper[i] = 0.0 if i == n else a
        diag[i] = -2 * a - leak
        rhs[i] = -leak * top
    for i in range(1, n + 1):
        m = lower[i] / diag[i - 1]
        diag[i] -= m * upper[i - 1]
        rhs[i] -= m * rhs[i - 1]
    phi = [0.0] * (n + 1)
    phi[n] = rhs[n] / diag[n]
    for i in range(n - 1, -1, -1):
        phi[i] = (rhs[i] - upper[i] * phi[i + 1]) / diag[i]
    return lambda x: phi[min(n, max(0, int(round(x / dx))))]


def main():
    spec, _, read = example_results.load()
    profiles, summary = read("profiles.json"), read("summary.json")
    problems = []
    if summary["status"] != "successful" or "in 2 stages" not in summary["message"]:
        problems.append(f"the run: {summary['status']}: {summary['message']}")

    mats = spec["materials"]
    k_a = mats["aquifer sand"]["hydraulic"]["hydraulic_conductivity"]
    k_b = mats["blanket clay"]["hydraulic"]["hydraulic_conductivity"]
    aquifer = next(b for b in spec["bodies"] if b["material"] == "aquifer sand")["box"]
    blanket = next(b for b in spec["bodies"] if b["material"] == "blanket clay")["box"]
    levee = next(b for b in spec["bodies"] if b["material"] == "levee fill")["polygon"]
    thickness = aquifer["max"][1] - aquifer["min"][1]
    z_b = blanket["max"][1] - blanket["min"][1]
    ground = blanket["max"][1]
    toe_river, toe_land = min(v[0] for v in levee), max(v[0] for v in levee)
    length = spec["grid"]["max"][0] - spec["grid"]["min"][0]
    day = spec["time"]["end"]
    river_end = ground + 2.5  # the river's level once it has risen (the formula's 6 + 2.5)

    times = profiles["time"]
    deep, top = profiles["profiles"][0], profiles["profiles"][1]

    def row_at(t):
        return min(range(len(times)), key=lambda r: abs(times[r] - t))

    # After the gravity loading: hydrostatic.
    r0 = row_at(day)
    worst0 = max(abs(p / GAMMA_W + x[1] - ground)
                 for x, p in zip(deep["initial_positions"], deep["pore_pressure"][r0]))
    if abs(times[r0] - day) > 1e-6 * day or worst0 > 0.01:
        problems.append(f"after the gravity loading (t = {times[r0]} s) the aquifer's head is "
                        f"off the water table by {worst0:.3g} m")

    # At the end: the aquifer's head against the blanket theory.
    r = len(times) - 1
    theory = blanket_theory(river_end, length, toe_river, toe_land, k_a, thickness, k_b, z_b,
                            ground)
    rise = river_end - ground
    worst_head, at_head = 0.0, None
    heads = []
    for x, p in zip(deep["initial_positions"], deep["pore_pressure"][r]):
        phi = p / GAMMA_W + x[1]
        heads.append(phi)
        err = abs(phi - theory(x[0])) / rise
        if err > worst_head:
            worst_head, at_head = err, x[0]
    if worst_head > 0.02:
        problems.append(f"aquifer head off the blanket theory by {100 * worst_head:.2f} % of the "
                        f"river's rise at x = {at_head:.2f} m")

    # The blanket's top row: uplift (landside) and inflow (riverside).
    worst_w, worst_p, landside, riverside = 0.0, 0.0, 0, 0
    for k, (x, p, w) in enumerate(zip(top["initial_positions"], top["pore_pressure"][r],
                                      top["darcy_velocity"][r])):
        phi = heads[k]
        if x[0] < toe_river:
            riverside += 1
            if w[1] >= 0 and x[0] > 1.0:  # next to the left wall the flow is horizontal
                problems.append(f"x = {x[0]:.2f} m under the river: Darcy velocity {w[1]:.3g} m/s "
                                f"is not downward")
        elif x[0] > toe_land + 2.0:
            landside += 1
            gradient = (phi - ground) / z_b
            expected = k_b * gradient
            worst_w = max(worst_w, abs(w[1] - expected) / expected)
            depth = ground - x[1]
            expected_p = GAMMA_W * depth * (1 + gradient)
            worst_p = max(worst_p, abs(p - expected_p) / expected_p)
    if landside < 5 or riverside < 5:
        problems.append(f"profile 1 has {landside} landside and {riverside} riverside points")
    if worst_w > 0.03:
        problems.append(f"landside uplift flow off k_b i by {100 * worst_w:.2f} %")
    if worst_p > 0.05:
        problems.append(f"landside blanket top pressure off the seepage face's by "
                        f"{100 * worst_p:.2f} %")
    toe_head = theory(toe_land)
    print(f"levee: after gravity loading |head - {ground}| <= {worst0:.2g} m; at the end "
          f"(river {river_end} m) the aquifer head within {100 * worst_head:.2f} % of the river's "
          f"rise of the blanket theory (worst at x = {at_head:.2f} m; head at the landside toe "
          f"{toe_head:.3f} m, uplift gradient {(toe_head - ground) / z_b:.3f}); landside "
          f"upward flow within {100 * worst_w:.2f} % of k_b i, top-row pressure within "
          f"{100 * worst_p:.2f} % of the seepage face's")
    for line in problems[:20]:
        print(line)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
