"""examples/rising-water-slope.json: the slope fails when Bishop's
simplified method, given the run's own pore pressures, says it must.

Usage: check_rising_water_slope.py EXAMPLE RESULT_DIR [--figure FILE.png]

At every snapshot of the rising-water stage the pore pressure of the
particles is interpolated (inverse-distance weights of the 4 nearest
particles on a lattice a quarter cell apart, bilinear between) at the base
of each slice, and Bishop's least factor
of safety over circular slip surfaces is searched (a grid of centres and
radii, 800 circles, then a pattern search from the best; 60 slices; slices weigh gamma_sat b h, the
saturated mixture's weight, as the u-p model has it; the effective normal
force W - u b is kept >= 0, no tension; circles less than a cell deep
are left out: the grid cannot resolve a mechanism thinner than that). The slide is measured by the mean
displacement of the particles whose initial positions lie inside the
critical circle of the last snapshot (the mechanism the stage ends
with). Checked:
- Bishop's factor falls from above 1.05 to below 0.95 during the stage
  (else the example tests nothing);
- at rest while Bishop's F >= 1.05: the slide has moved less than 1 cm
  (the elastic response to the rising water is 2-7 mm);
- moving once F <= 0.95: more than 1 cm, and more at every later snapshot
  (the slide does not stop while F stays below 1). The band 0.95-1.05 is
  the check's own spread: Bishop's simplified method against rigorous
  limit equilibrium and against strength reduction on the same slopes
  differs by a few per cent (docs/verification.md);
- no particle volume past the run's plausible range (the run has no
  volume warning) and the run successful;
- the solid mass conserved: sum (1 - n) V over the particles at the last
  snapshot equals the first within 1e-9 (the grains are incompressible).
Prints F, the head at the back and the slide's displacement at each
snapshot. With --figure: F and the displacement against time (the head on
top), and the displacement field at the end with the critical circle.
"""
import json
import math
import os
import re
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import random_support as rs  # noqa: E402


def surface_of(polygon):
    """The ground surface y(x) of a polygon whose top runs from x = 0 to the right edge."""
    top = {}
    for x, y in polygon:
        if y > 0:
            top[x] = max(top.get(x, 0.0), y)
    xs = sorted(top)
    ys = [top[x] for x in xs]
    return lambda x: float(np.interp(x, xs, ys))


def bishop(ground, u, c, tp, gamma, circle, x_end, min_depth, n=60):
    """Bishop's simplified F of a circle (xc, yc, r) for a slope facing +x; None if it cuts no soil
    or no deeper than min_depth (a mechanism thinner than a cell, which the grid cannot resolve)."""
    xc, yc, r = circle
    if yc - r < 0.0 or r <= 0:
        return None
    m = 300
    inside = [xc - r + 2 * r * (i + 0.5) / m for i in range(m)]
    inside = [x for x in inside if 0 <= x <= x_end and yc - math.sqrt(max(r * r - (x - xc) ** 2, 0)) < ground(x)]
    if not inside or inside[-1] - inside[0] < 0.5:
        return None
    x1, x2 = max(inside[0] - r / m, 0.0), min(inside[-1] + r / m, x_end)
    b = (x2 - x1) / n
    slices = []
    for i in range(n):
        x = x1 + (i + 0.5) * b
        d = r * r - (x - xc) ** 2
        if d <= 0:
            continue
        yb = yc - math.sqrt(d)
        h = ground(x) - yb
        if h > 0:
            w = gamma * b * h
            slices.append((w, max(w - u(x, yb) * b, 0.0), (xc - x) / r, math.sqrt(d) / r))
    drive = sum(w * s for w, _, s, _ in slices)
    if drive <= 0 or max(w for w, _, _, _ in slices) < gamma * b * min_depth:
        return None
    f = 1.0
    for _ in range(100):
        g = sum((c * b + nf * tp) / (co + s * tp / f) for _, nf, s, co in slices if co + s * tp / f > 0.05) / drive
        if abs(g - f) < 1e-7:
            break
        f = g
    return f


def least_circle(ground, u, c, tp, gamma, x_end, x_range, height, min_depth, guess=None):
    candidates = [guess] if guess else []
    for i in range(10):
        xc = x_range[0] + (x_range[1] - x_range[0]) * i / 9
        for j in range(8):
            yc = 0.5 * height + 2.5 * height * j / 7
            candidates += [(xc, yc, yc * k / 10) for k in range(1, 11)]
    best = (math.inf, None)
    for circle in candidates:
        f = bishop(ground, u, c, tp, gamma, circle, x_end, min_depth)
        if f is not None and f < best[0]:
            best = (f, circle)
    f, circle = best
    step = 1.0
    while step > 2e-2:
        better = False
        for d in ((step, 0, 0), (-step, 0, 0), (0, step, 0), (0, -step, 0), (0, 0, step), (0, 0, -step)):
            trial = tuple(a + b for a, b in zip(circle, d))
            g = bishop(ground, u, c, tp, gamma, trial, x_end, min_depth)
            if g is not None and g < f - 1e-12:
                f, circle, better = g, trial, True
        if not better:
            step /= 2
    return f, circle


def pressure_field(pos, p, grid, per_cell=4):
    """u(x, y): the particles' pore pressure on a lattice a quarter cell apart (inverse-distance
    weights of the 4 nearest particles), then bilinear between its points."""
    lo, hi, cells = grid["min"], grid["max"], grid["cells"]
    dx = (hi[0] - lo[0]) / cells[0] / per_cell
    dy = (hi[1] - lo[1]) / cells[1] / per_cell
    xs = lo[0] + dx * np.arange(cells[0] * per_cell + 1)
    ys = lo[1] + dy * np.arange(cells[1] * per_cell + 1)
    gx, gy = np.meshgrid(xs, ys, indexing="ij")
    q = np.stack([gx.ravel(), gy.ravel()], axis=1)
    d2 = ((q[:, None, :] - pos[None, :, :]) ** 2).sum(axis=2)
    near = np.argpartition(d2, 4, axis=1)[:, :4]
    w = 1.0 / (np.take_along_axis(d2, near, axis=1) + 1e-12)
    values = ((w * p[near]).sum(axis=1) / w.sum(axis=1)).reshape(gx.shape).tolist()
    nx, ny = len(xs) - 1, len(ys) - 1

    def u(x, y):
        fx = min(max((x - lo[0]) / dx, 0.0), nx - 1e-9)
        fy = min(max((y - lo[1]) / dy, 0.0), ny - 1e-9)
        i, j = int(fx), int(fy)
        a, b = fx - i, fy - j
        return ((1 - a) * (1 - b) * values[i][j] + a * (1 - b) * values[i + 1][j] +
                (1 - a) * b * values[i][j + 1] + a * b * values[i + 1][j + 1])

    return u


def snapshot_time(path):
    with open(path) as fh:
        return float(re.search(r'TimeValue"[^>]*>([^<]*)', fh.read()).group(1))


def main():
    example, results = sys.argv[1:3]
    figure = sys.argv[sys.argv.index("--figure") + 1] if "--figure" in sys.argv else None
    with open(example) as fh:
        spec = json.load(fh)
    with open(os.path.join(results, "summary.json")) as fh:
        summary = json.load(fh)
    problems = []
    if summary["status"] != "successful":
        problems.append(f"the run is {summary['status']}: {summary['message']}")
    volume_warnings = [w for w in summary.get("warnings", []) if "particle volumes outside" in w]
    if volume_warnings:
        problems.append(f"a particle volume left its plausible range: {volume_warnings[0][:300]}")
    polygon = spec["bodies"][0]["polygon"]
    ground = surface_of(polygon)
    height = max(y for _, y in polygon)
    mat = spec["materials"][spec["stages"][0]["body_materials"][0]["material"]]
    n = mat["hydraulic"]["porosity"]
    rho_f = mat["hydraulic"].get("fluid_density", 1000.0)
    gamma = ((1 - n) * mat["density"] + n * rho_f) * abs(spec["gravity"][1])
    c, tp = mat["cohesion"], math.tan(math.radians(mat["friction_angle"]))
    x_end = spec["grid"]["max"][0]
    cell = (spec["grid"]["max"][1] - spec["grid"]["min"][1]) / spec["grid"]["cells"][1]
    stage_start = spec["time"]["end"]
    head = spec["surface_pressures"][0]["pore_pressure"]  # "9810*(H(t)-y)"
    head_of = eval("lambda t: " + head[len("9810*("):-len("-y)")], {"min": min, "max": max})  # noqa: S307

    files = [os.path.join(results, f) for f in sorted(os.listdir(results)) if f.startswith("snapshot_")]
    rows, guess, solids = [], None, []
    for path in files:
        t = snapshot_time(path)
        snap = rs.read_vtu(path)
        pos = np.array(snap["Points"])[:, :2]
        disp = np.array(snap["displacement"])[:, :2]
        solids.append(float(np.sum((1 - np.array(snap["porosity"])) * np.array(snap["volume"]))))
        if t < stage_start + 1e-9:
            continue
        u = pressure_field(pos, np.array(snap["pore_pressure"]), spec["grid"])

        f, circle = least_circle(ground, u, c, tp, gamma, x_end, (0.0, x_end * 0.75), height, cell, guess)
        guess = circle
        rows.append([t, head_of(t), f, disp, circle, path, pos - disp])

    # The slide: the particles starting inside the last snapshot's critical
    # circle (the mechanism the stage ends with), the same set at every time.
    if rows:
        xc, yc, r = rows[-1][4]
        start = rows[-1][6]
        inside = (start[:, 0] - xc) ** 2 + (start[:, 1] - yc) ** 2 < r * r
    for row in rows:
        disp = row[3]
        row[3] = float(np.mean(np.hypot(disp[inside, 0], disp[inside, 1]))) if inside.any() else 0.0
        t, h, f, moved, circle = row[:5]
        print(f"t = {t:6.2f} s  head {h:5.2f} m  Bishop F {f:6.3f}  circle ({circle[0]:.2f}, "
              f"{circle[1]:.2f}, r {circle[2]:.2f})  slide moved {1000 * moved:7.1f} mm")

    if not rows or min(r[2] for r in rows) > 0.95 or rows[0][2] < 1.05:
        problems.append("Bishop's factor does not fall from above 1.05 to below 0.95 during the stage")
    rest = [r for r in rows if r[2] >= 1.05]
    failing = [r for r in rows if r[2] <= 0.95]
    for t, h, f, moved, *_ in rest:
        if moved >= 0.01:
            problems.append(f"t = {t:.2f} s: moved {moved:.4f} m while Bishop's F = {f:.3f} >= 1.05")
    for k, (t, h, f, moved, *_) in enumerate(failing):
        if moved <= 0.01:
            problems.append(f"t = {t:.2f} s: moved only {moved:.4f} m while Bishop's F = {f:.3f} <= 0.95")
        if k and moved <= failing[k - 1][3]:
            problems.append(f"t = {t:.2f} s: the slide stopped ({moved:.4f} m) while F = {f:.3f} < 1")
    onset = next((r for r in rows if r[3] > 0.01), None)
    crossing = next((k for k in range(1, len(rows)) if rows[k][2] < 1 <= rows[k - 1][2]), None)
    if onset and crossing:
        a, b = rows[crossing - 1], rows[crossing]
        t1 = a[0] + (b[0] - a[0]) * (a[2] - 1) / (a[2] - b[2])
        print(f"Bishop's F = 1 at t = {t1:.2f} s (head {head_of(t1):.2f} m); the critical mass passed 1 cm "
              f"at t = {onset[0]:.2f} s (head {onset[1]:.2f} m, F = {onset[2]:.3f})")
    drift = abs(solids[-1] - solids[0]) / solids[0]
    print(f"solid volume sum (1 - n) V: first {solids[0]:.9g}, last {solids[-1]:.9g} m2/m (relative {drift:.2e})")
    if drift > 1e-9:
        problems.append(f"the solid volume changed by {drift:.2e} of itself")

    if figure and rows:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, (a1, a2) = plt.subplots(1, 2, figsize=(13, 4.2), gridspec_kw={"width_ratios": [1, 1.6]})
        times = [r[0] for r in rows]
        a1.plot(times, [r[2] for r in rows], "k-o", ms=3, label="Bishop's F from the run's pore pressures")
        a1.axhspan(0.95, 1.05, color="0.85", label="the check's spread, F = 0.95-1.05")
        a1.set_xlabel("time (s); the head at the back on top (m)")
        a1.set_ylabel("factor of safety")
        top = a1.twiny()
        top.set_xlim(a1.get_xlim())
        ticks = list(range(5 * math.ceil(times[0] / 5), int(times[-1]) + 1, 5))
        top.set_xticks(ticks)
        top.set_xticklabels([f"{head_of(t):.2f}" for t in ticks], fontsize=8)
        a1b = a1.twinx()
        a1b.plot(times, [1000 * r[3] for r in rows], "r-s", ms=3, label="the slide's mean displacement")
        a1b.set_ylabel("the slide's mean displacement (mm)", color="r")
        lines = a1.get_legend_handles_labels()
        extra = a1b.get_legend_handles_labels()
        a1.legend(lines[0] + extra[0], lines[1] + extra[1], loc="upper right", fontsize=8)
        last = rows[-1]
        snap = rs.read_vtu(last[5])
        pos = np.array(snap["Points"])
        disp = np.array(snap["displacement"])
        sc = a2.scatter(pos[:, 0], pos[:, 1], c=np.hypot(disp[:, 0], disp[:, 1]), s=4, cmap="viridis")
        plt.colorbar(sc, ax=a2, label="|u| (m)")
        xc, yc, r = last[4]
        th = np.linspace(-math.pi, 0, 200)
        a2.plot(xc + r * np.cos(th), yc + r * np.sin(th), "r-", lw=1.5, zorder=5)
        p = np.array(snap["pore_pressure"])
        a2.tricontour(pos[:, 0], pos[:, 1], p, levels=[0.0], colors="c", linewidths=1)
        a2.set_aspect("equal")
        a2.set_ylim(0, max(height + 1, yc + 0.2))
        a2.set_title(f"t = {last[0]:.0f} s: displacement, Bishop's critical circle (red), p = 0 (cyan)", fontsize=9)
        fig.tight_layout()
        fig.savefig(figure, dpi=110)

    for msg in problems:
        print("FAIL:", msg)
    print("OK" if not problems else f"{len(problems)} problem(s)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
