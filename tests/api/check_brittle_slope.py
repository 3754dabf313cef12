"""examples/brittle-slope.json against its perfectly plastic twin
(examples/slope-failure.json) and the sliding block (docs/worked-examples.md
"Brittle slope"; docs/verification.md "Strain softening").

Usage: check_brittle_slope.py PLAIN_RESULTS EXAMPLE.json RESULTS [--figure FILE.png]

PLAIN_RESULTS is slope-failure.json's result directory (the example run
of the test suite), RESULTS brittle-slope.json's. Both slopes have the
peak friction 30 degrees; the brittle one softens to 24 degrees. Checked:
- onset (mean slope-parallel displacement of the mid column 0.01 m) within
  0.15 s of the perfectly plastic slope's: the peak decides it (the pore
  pressure rises 0.015 in 0.15 s: FS = 1 +- 0.05);
- the brittle slope runs out at least 1.5x as far (the basal band loses
  a fifth of its friction: sin 24 / sin 30 = 0.81), yet less than the
  sliding block with the residual friction sin(24 deg) from the onset on
  (the most mobile the brittle slope could be: the block bounds the
  perfectly plastic slope as well, 0.94 m against its 0.47 m);
- it has stopped (under 5 mm in the last 0.5 s), after the pore pressure
  fell below the residual strength's limit;
- the softening happened in the basal band: the largest plastic strain at
  the base is past 3/eta (95 % softened) and the top half of the layer
  stays at most a tenth of it.
With --figure, the runouts against time (both slopes, both blocks) and the
plastic strain over the depth at the end.
"""
import json
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import random_support as rs  # noqa: E402  (its VTU reader)


def mean_displacement(results):
    """Times and the mean slope-parallel displacement of the series particles."""
    with open(os.path.join(results, "series.json")) as f:
        s = json.load(f)
    parts = s["particles"]
    return s["time"], [sum(p["displacement"][i][0] for p in parts) / len(parts)
                       for i in range(len(s["time"]))]


def first_above(t, u, level):
    for ti, ui in zip(t, u):
        if ui > level:
            return ti
    return math.nan


def block_runout(spec, mu, end, dt=1e-4):
    """Sliding-block kinematics of the layer under the example's base pressure."""
    g = math.hypot(*spec["gravity"][:2])
    beta = math.atan2(spec["gravity"][0], -spec["gravity"][1])
    soil = spec["materials"]["soil"]
    n = soil["hydraulic"]["porosity"]
    rho = (1 - n) * soil["density"] + n * soil["hydraulic"]["fluid_density"]
    r0 = soil["hydraulic"]["fluid_density"] / rho
    x = v = 0.0
    t = 0.0
    history = []
    while t <= end + dt / 2:
        r = r0 + 0.1 * max(0.0, 2.45 - abs(t - 2.95))
        a = g * (math.sin(beta) - (1 - r) * math.cos(beta) * mu)
        if v <= 0 and a < 0:
            a = v = 0.0
        v += a * dt
        x += v * dt
        history.append((t, x))
        t += dt
    return history


def main():
    plain, example, results = sys.argv[1:4]
    figure = sys.argv[sys.argv.index("--figure") + 1] if "--figure" in sys.argv else None
    with open(example) as f:
        spec = json.load(f)
    soft = spec["materials"]["soil"]["softening"]
    phi_p = spec["materials"]["soil"]["friction_angle"]
    phi_r = soft["residual_friction_angle"]
    with open(os.path.join(results, "summary.json")) as f:
        summary = json.load(f)
    failures = []
    if summary.get("status") != "successful":
        failures.append(f"status {summary.get('status')}: {summary.get('message')}")
    tp, up = mean_displacement(plain)
    tb, ub = mean_displacement(results)
    onset_p, onset_b = first_above(tp, up, 0.01), first_above(tb, ub, 0.01)
    runout_p, runout_b = up[-1], ub[-1]
    end = spec["time"]["end"]
    block_r = block_runout(spec, math.sin(math.radians(phi_r)), end)
    block_p = block_runout(spec, math.sin(math.radians(phi_p)), end)
    last = [u for t, u in zip(tb, ub) if t >= tb[-1] - 0.5]
    late = last[-1] - last[0]
    print(f"onset: perfectly plastic {onset_p:.3f} s, brittle {onset_b:.3f} s")
    print(f"runout: perfectly plastic {runout_p:.4f} m, brittle {runout_b:.4f} m "
          f"(x{runout_b / runout_p:.2f}); blocks: sin {phi_p} {block_p[-1][1]:.4f} m, "
          f"sin {phi_r} {block_r[-1][1]:.4f} m; motion in the last 0.5 s {late:.2g} m")
    if not abs(onset_b - onset_p) <= 0.15:
        failures.append(f"onset {onset_b:.3f} s is not within 0.15 s of {onset_p:.3f} s")
    if not runout_b >= 1.5 * runout_p:
        failures.append(f"runout {runout_b:.4f} m is not 1.5x the plastic {runout_p:.4f} m")
    if not runout_b < block_r[-1][1]:
        failures.append(f"runout {runout_b:.4f} m beyond the residual block's {block_r[-1][1]:.4f}")
    if not abs(late) < 5e-3:
        failures.append(f"still moving: {late:.3g} m in the last 0.5 s")
    # The plastic strain over the depth, from the last snapshot.
    with open(os.path.join(results, "snapshots.pvd")) as f:
        pvd = f.read()
    last_vtu = pvd.split('file="')[-1].split('"')[0]
    snapshot = rs.read_vtu(os.path.join(results, last_vtu))
    points, kappa = snapshot["Points"], snapshot["plastic_strain"]
    cell = (spec["grid"]["max"][1] - spec["grid"]["min"][1]) / spec["grid"]["cells"][1]
    eta = soft["shape_factor"] * cell / soft.get("reference_cell_size", cell)
    base = max(k for k, p in zip(kappa, points) if p[1] < 0.15)
    top = max(k for k, p in zip(kappa, points) if p[1] > 0.5 + 0.02)
    print(f"plastic strain: basal band up to {base:.3f} (3/eta = {3 / eta:.3f}), top half "
          f"up to {top:.4f}")
    if not base > 3 / eta:
        failures.append(f"the basal band softened to only {base:.3f} < 3/eta {3 / eta:.3f}")
    if not top <= 0.1 * base:
        failures.append(f"the top half yielded ({top:.4f} > a tenth of the base's {base:.4f})")
    if figure:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.2))
        a.plot(tp, up, label=f"perfectly plastic, phi {phi_p} deg (slope-failure)")
        a.plot(tb, ub, label=f"brittle, phi {phi_p} -> {phi_r} deg (brittle-slope)")
        a.plot([h[0] for h in block_p[::100]], [h[1] for h in block_p[::100]], "--",
               label=f"sliding block, mu = sin {phi_p}")
        a.plot([h[0] for h in block_r[::100]], [h[1] for h in block_r[::100]], ":",
               label=f"sliding block, mu = sin {phi_r}")
        a.set_xlabel("t (s)")
        a.set_ylabel("mean slope-parallel displacement, mid column (m)")
        a.legend(fontsize=8)
        a.grid(alpha=0.3)
        mid = [(p[1], k) for k, p in zip(kappa, points) if abs(p[0] - sum(q[0] for q in points) / len(points)) < 0.2]
        b.scatter([k for _, k in mid], [y for y, _ in mid], s=6)
        b.axvline(3 / eta, color="grey", ls="--", label="3/eta: 95 % softened")
        b.set_xlabel("plastic strain at the end")
        b.set_ylabel("height of the particle (m)")
        b.legend(fontsize=8)
        b.grid(alpha=0.3)
        fig.tight_layout()
        fig.savefig(figure, dpi=110)
        print(f"figure: {figure}")
    for f in failures:
        print("FAIL:", f)
    print("OK" if not failures else f"{len(failures)} failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
