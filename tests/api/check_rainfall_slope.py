"""Physics check of examples/rainfall-slope.json: rain on a saturated slope
with a toe, a seepage face at the toe, and a walled-off control column
(issue 17: fluxes, seepage faces, stages). Reads the run's snapshots
(snapshot_NNNN.vtu, base64 binary, parsed here with the standard library),
series.json, profiles.json and summary.json back.

Usage: check_rainfall_slope.py EXAMPLE.json RESULT_DIR
RESULT_DIR is what `hmpm run EXAMPLE.json --out RESULT_DIR` wrote. Geometry,
soil constants, the water table, the rain and the stage times come from the
spec, so the checks describe the job that was run.

Quantities. gamma_w = rho_f g = 9810 N/m3. The water stored in the ground
since the rain began (t_on): with incompressible grains the pore volume of
a particle changes with its volume V (a swelling skeleton takes water in)
and the water it holds is compressed by n dp / K_w, so
    stored(t) = sum_p [ V_p(t) - V_p(t_on) ] + sum_p V_p n_p / K_w [ p_p(t) - p_p(t_on) ]
(per metre of slope; volume, porosity and pore pressure from the snapshots;
the second term is 0.4 % of the first). The quasi-static scheme's mass
balance is this sum to the Newton tolerance: each step's equation at a
node is sum V (Q dp + div du) = dt (Darcy flux + rain), the Darcy and the
stabilisation terms cancel over the nodes, and the particles' volumes
change by det(I + grad du), which differs from 1 + div du by second-order
terms. The rain that entered: rate x (t - t_on) x the loaded face length,
the selected particles' count x the sub-cell size s (each loaded face is
a particle's top face of length V0 / (initial length) = s; the script
rebuilds the particles from the spec, and checks that each rained particle
is the top one of its column, so the thin polygon along the crest and the
slope does rain on the surface's staircase once per column).

Checked (measured values at the example's 1 m cells, then with the same
job at 0.5 m and 0.25 m cells, 2 x 2 particles per cell, steps during the
rain capped at 600, 300 and 150 s; each tolerance is a margin over the
largest of them, for the reason given):
1. The run is successful, in 3 stages.
2. The gravity loading (stage 1: the pore pressure held hydrostatic at
   every node, so the skeleton takes its weight drained) leaves, when the
   rain begins, the hydrostatic state of the initial water table at the
   particles' positions, p = gamma_w (y_w - y), within 0.05 Pa (measured
   0.0043, 0.0044, 0.0044 Pa). A particle's pressure is its cell's nodal
   values interpolated where the step started; linear shape functions
   reproduce the linear field exactly, so what is left is the motion of
   the last loading step: the first step settles the ground by 4 cm, the
   second corrects the equilibrium of the moved configuration by about
   2e-5 m, the third by 4e-7 m (with two steps the state was 0.8 Pa off).
3. Water balance of the control column (it has no way out): the water
   stored equals the rain that entered at every snapshot from the rain's
   start to the end, within 5e-5 of the column's total rain (measured
   4.7e-6, 4.6e-6, 4.5e-6). What is left is the Newton tolerance: each
   step stops when the mass balance's residual is below 1e-8 of the sum of
   the magnitudes of its terms, which the Darcy flux's two hydrostatic
   parts dominate (about 100 times a step's storage terms), and the second
   iteration is needed (the Jacobian leaves the Jaumann term out), so it is
   reached at that tolerance, not at round-off; the tolerance is the whole
   run's and the column's rain is 1/24 of the slope's.
4. Water balance of the slope, before any water leaves: at every snapshot
   before the seepage face's first step at p = 0 (item 5: after 5.5 h of
   rain), the water stored equals the rain within 1e-5 of the slope's
   total rain (measured 1.3e-6, 6.5e-7, 9.2e-7: the origin of item 3).
   Afterwards the outflow, rain minus stored, never falls by more than
   that tolerance between snapshots (the face lets no water in: measured
   1.5e-6, 1.1e-6, 8.8e-7), and by the end more than a tenth of the rain
   has left (measured 36.0, 35.9, 35.9 %).
5. The seepage face: its nodal pore pressure is never above zero, at most
   1e-6 Pa at every node of the face that holds water, at every step
   (measured 6e-11, 8e-11, 4e-11 Pa: round-off); and the face acts (some
   node at -1 Pa or above) during the run (first after 5.5 h of rain at
   all three resolutions). The nodal values are recovered from the series
   (the particles of a band 1.5 cells deep under the face, every step): a
   particle's new pressure is the bilinear interpolation of its cell's
   nodal values at its position at the step's start, which is the series'
   position one row before; a cell with four particles gives its four
   nodes, and the cells the slope cuts give the nodes they still miss from
   those (nodal_pressures), so every node of the face with water is
   recovered (25, 49, 97 of them).
6. The control column against the closed form of a 1D column of height H
   with an impermeable base under an influx r from t_on to t_off (the
   superposition of switching it on and off): the excess pore pressure
     u(z, t) = G [ c_v t / H + (H - z)^2 / (2 H) - H / 6
                   - (2 H / pi^2) sum_n cos(n pi z / H) exp(-n^2 pi^2 c_v t / H^2) / n^2 ]
   with z the depth, G = r gamma_w / k (the gradient that carries r), c_v
   = k / (gamma_w (m_v + n / K_w)), m_v = 1 / E_oed, H and z those of the
   column settled by the gravity loading (4 cm shorter). The particles move
   (the column swells by 14 mm), so a particle's pressure changes by
   u - gamma_w dy, dy its rise since t_on. At every profile sample with
   T_v = c_v (t - t_on) / H^2 >= 0.05 and every point of the column:
   |p - p(t_on) + gamma_w dy - u| <= 2.5 % of G H (G H = 24.4 kPa; the
   excess reaches 46 kPa at the top). Measured 1.55, 1.20, 1.17 %, worst
   near the surface 30-60 min after the rain stops, where the profile is
   steepest. The spatial error falls with h (at the rain's start, T_v =
   0.1: 0.64, 0.58, 0.48 %; at rest at the end: 0.32, 0.20, 0.18 %); after
   the stop the drainage stage's steps, restarting at 60 s and growing 1.5
   times a step to 30 min, take over below 1 m cells (the column run alone
   at 0.25 m with growth 1.1: 0.64 %). Smaller steps do not help at 1 m
   cells (growth 1.1 there: 1.99 %): the quasi-static scheme's pressure
   stabilisation holds a column at rest off hydrostatic at its ends by
   about h^3 / dt x 50 kPa s / m^3 for this soil (90 Pa with 1 m cells and
   600 s steps, 830 Pa with 60 s steps, measured on this column without
   rain). The slope's own crest is not a 1D column: a crest 4 H wide (40 m,
   tried) still followed the closed form only within 1-2 % of the excess,
   as the slope's outward swelling and the drainage to the toe reach its
   far wall; hence the control column.
7. The final state: the water drains through the face until the ground is
   at rest with its water table at the face's foot, the valley floor y_f:
   p = gamma_w (y_f - y) at every particle of the slope at the end, within
   1 % of the table's rise gamma_w (y_f - y_w) = 19.6 kPa (measured 0.38,
   0.42, 0.44 %: the rest of the drainage, which falls by e in 20 h:
   4.3 % after 3 days, 1.3 % after 4, 0.38 % after 5; the grid reproduces
   a hydrostatic field exactly). A face that held another pressure, took
   water in or let none out would leave the table elsewhere by metres (a
   face of p = 0 prescribed instead of a seepage face: 189 % off, with
   water drawn in; a seepage face of one node: 14 %).
8. The rain raises the pore pressure at every particle (by 14.6 to
   46 kPa; checked > 1 Pa), and the rained particles of the level crest
   and of the column stay in suction, p < 0, throughout (at most -9.7,
   -10.7, -11.2 kPa): the model has no unsaturated zone and no ponding, so
   a rained surface at p > 0 would be outside what the example describes.
   (On the lower slope the water table does reach the surface: that part
   is the seepage face, and the pressure under it is positive.)
"""
import base64
import math
import os
import re
import struct
import sys

import example_results

GAMMA_W = 9810.0


def read_vtu(path):
    """The arrays of one snapshot: name -> list of values (tuples for vectors)."""
    with open(path) as f:
        text = f.read()
    types = {"Float64": ("d", 8), "Int32": ("i", 4), "Int64": ("q", 8), "UInt8": ("B", 1)}
    arrays = {}
    for m in re.finditer(r"<DataArray([^>]*)>(.*?)</DataArray>", text, re.S):
        attrs = dict(re.findall(r'(\w+)="([^"]*)"', m.group(1)))
        if attrs.get("format") == "ascii":
            arrays[attrs["Name"]] = [float(v) for v in m.group(2).split()]
            continue
        raw = base64.b64decode("".join(m.group(2).split()))
        (size,) = struct.unpack_from("<Q", raw, 0)  # header_type UInt64: the byte count
        code, width = types[attrs["type"]]
        values = struct.unpack_from("<%d%s" % (size // width, code), raw, 8)
        comps = int(attrs.get("NumberOfComponents", "1"))
        arrays[attrs["Name"]] = ([values[i:i + comps] for i in range(0, len(values), comps)]
                                 if comps > 1 else list(values))
    return arrays


def snapshot_files(results):
    with open(os.path.join(results, "snapshots.pvd")) as f:
        pvd = f.read()
    return [(float(t), os.path.join(results, name))
            for t, name in re.findall(r'timestep="([^"]*)"[^>]*file="([^"]*)"', pvd)]


def in_polygon(poly, x, y, eps):
    """Inside the polygon or on its boundary within eps (as the solver selects)."""
    inside = False
    for i, (x1, y1) in enumerate(poly):
        x2, y2 = poly[(i + 1) % len(poly)]
        dx, dy = x2 - x1, y2 - y1
        f = max(0.0, min(1.0, ((x - x1) * dx + (y - y1) * dy) / (dx * dx + dy * dy)))
        if math.hypot(x - x1 - f * dx, y - y1 - f * dy) <= eps:
            return True
        if (y1 > y) != (y2 > y) and x < x1 + (y - y1) * dx / dy:
            inside = not inside
    return inside


def in_box(box, x, y, eps):
    return all(box["min"][a] - eps <= v <= box["max"][a] + eps for a, v in enumerate((x, y)))


def body_particles(spec, body):
    """Sub-cell centres of a polygon body (inside or on its boundary) or of
    the whole cells inside a box body, in the solver's numbering order."""
    grid = spec["grid"]
    h = [(grid["max"][a] - grid["min"][a]) / grid["cells"][a] for a in range(2)]
    n = body.get("particles_per_cell", 2)
    eps = 1e-9 * min(h)
    out = []
    for j in range(grid["cells"][1] * n):
        for i in range(grid["cells"][0] * n):
            x = grid["min"][0] + (i + 0.5) * h[0] / n
            y = grid["min"][1] + (j + 0.5) * h[1] / n
            if "polygon" in body:
                keep = in_polygon(body["polygon"], x, y, eps)
            else:  # the cell of the sub-cell must lie inside the box
                cx = grid["min"][0] + (i // n) * h[0]
                cy = grid["min"][1] + (j // n) * h[1]
                keep = (in_box(body["box"], cx, cy, eps)
                        and in_box(body["box"], cx + h[0], cy + h[1], eps))
            if keep:
                out.append((x, y))
    return out


def solve(a, b):
    """a x = b by Gaussian elimination with partial pivoting (n <= 4 here)."""
    n = len(b)
    m = [row[:] + [v] for row, v in zip(a, b)]
    for c in range(n):
        piv = max(range(c, n), key=lambda r: abs(m[r][c]))
        m[c], m[piv] = m[piv], m[c]
        for r in range(n):
            if r != c:
                f = m[r][c] / m[c][c]
                for k in range(c, n + 1):
                    m[r][k] -= f * m[c][k]
    return [m[i][n] / m[i][i] for i in range(n)]


def nodal_pressures(cells, h, row):
    """The nodal pore pressures that the particles of `cells` ((i, j) ->
    series particles) interpolated at step `row`: each particle's value is
    the bilinear interpolation of its cell's four nodes at its position at
    the step's start (the series' position one row before). Each full cell
    (four particles) gives its four nodes on its own; then the cut cells
    along the slope give the nodes they still miss from the nodes known
    around them, as long as they hold a particle per missing node. Returns
    {(i, j): p} by node index."""
    def solve_cell(i, j, quad, known):
        corners = [(i, j), (i + 1, j), (i, j + 1), (i + 1, j + 1)]
        unknown = [c for c in corners if c not in known]
        a, b = [], []
        for q in quad[:len(unknown)]:
            x, y = q["position"][row - 1]
            u, v = x / h - i, y / h - j
            w = dict(zip(corners, [(1 - u) * (1 - v), u * (1 - v), (1 - u) * v, u * v]))
            a.append([w[c] for c in unknown])
            b.append(q["pore_pressure"][row] - sum(w[c] * known[c] for c in corners
                                                   if c in known))
        return dict(zip(unknown, solve(a, b)))

    known = {}
    for (i, j), quad in cells.items():
        if len(quad) == 4:
            for node, value in solve_cell(i, j, quad, {}).items():
                known.setdefault(node, value)
    progress = True
    while progress:
        progress = False
        for (i, j), quad in cells.items():
            missing = [c for c in ((i, j), (i + 1, j), (i, j + 1), (i + 1, j + 1))
                       if c not in known]
            if missing and len(quad) >= len(missing):
                try:
                    known.update(solve_cell(i, j, quad, known))
                except ZeroDivisionError:  # its particles cannot tell those nodes apart
                    continue
                progress = True
    return known


def column_excess(z, t, height, grad, c_v):
    """Excess pore pressure at depth z, time t after a constant influx
    (giving the gradient grad = r gamma_w / k) starts on a column of height
    `height` with an impermeable base."""
    if t <= 0:
        return 0.0
    tv = c_v * t / height ** 2
    series = 0.0
    for n in range(1, 5000):
        e = math.exp(-(n * math.pi) ** 2 * tv)
        if e < 1e-17:
            break
        series += math.cos(n * math.pi * z / height) * e / n ** 2
    return grad * (c_v * t / height + (height - z) ** 2 / (2 * height) - height / 6
                   - 2 * height / math.pi ** 2 * series)


def main():
    spec, results, read = example_results.load()
    summary, series, profiles = read("summary.json"), read("series.json"), read("profiles.json")
    problems = []

    # ---- the job, from the spec
    grid = spec["grid"]
    h = (grid["max"][0] - grid["min"][0]) / grid["cells"][0]
    slope_body, column_body = spec["bodies"]
    s = h / slope_body.get("particles_per_cell", 2)
    material = spec["materials"][slope_body["material"]]
    hyd = material["hydraulic"]
    k, porosity, k_w = hyd["hydraulic_conductivity"], hyd["porosity"], hyd["fluid_bulk_modulus"]
    e_mod, nu = material["youngs_modulus"], material["poisson_ratio"]
    m_v = (1 + nu) * (1 - 2 * nu) / (e_mod * (1 - nu))
    c_v = k / (GAMMA_W * (m_v + porosity / k_w))
    table = re.fullmatch(r"\s*9810\s*\*\s*\(\s*([-+0-9.eE]+)\s*-\s*y\s*\)\s*",
                         slope_body["initial"]["pore_pressure"])
    if not table:
        print("the slope's initial pore pressure is not 9810*(y_w - y)")
        return 1
    y_w = float(table.group(1))
    rain_stage, last_stage = spec["stages"][0], spec["stages"][-1]
    t_on, t_off, t_end = spec["time"]["end"], rain_stage["end"], last_stage["end"]
    polygon = slope_body["polygon"]
    face = next(b for b in rain_stage["boundaries"] if b.get("seepage"))
    # the face's foot: the valley floor, the lowest vertex of its node polygon
    y_f = min(v[1] for v in face["nodes"]["polygon"])
    if any(v != 0 for v in grid["min"]):
        print("the grid must start at the origin (nodal_pressures counts cells from it)")
        return 1
    column_height = column_body["box"]["max"][1] - column_body["box"]["min"][1]

    slope_pts = body_particles(spec, slope_body)
    column_pts = body_particles(spec, column_body)
    bodies = {"slope": slope_pts, "column": column_pts}
    rain = {"slope": 0.0, "column": 0.0}
    rained = {"slope": [], "column": []}
    for flux in rain_stage["fluxes"]:
        if flux["face"] != "y+" or not isinstance(flux["rate"], (int, float)):
            problems.append(f"flux {flux}: expected a constant rate on face y+")
            continue
        sel = flux["particles"]
        for name, pts in bodies.items():
            hit = [p for p in pts
                   if (in_polygon(sel["polygon"], p[0], p[1], 1e-6 * h) if "polygon" in sel
                       else in_box(sel["box"], p[0], p[1], 1e-6 * h))]
            rain[name] += flux["rate"] * s * len(hit)  # m2/s per metre
            rained[name] += hit
    for name, pts in bodies.items():
        top = {}
        for x, y in pts:
            top[x] = max(top.get(x, -1e300), y)
        cols = {}
        for x, y in rained[name]:
            cols.setdefault(x, []).append(y)
        wrong = [x for x, ys in cols.items() if len(ys) != 1 or ys[0] != top[x]]
        if wrong or not cols:
            problems.append(f"{name}: the rain is not on exactly the top particle of each "
                            f"rained column (columns at x = {wrong[:5]})")
    rate = rain_stage["fluxes"][0]["rate"]
    print(f"rainfall slope: {len(slope_pts)} slope and {len(column_pts)} column particles; "
          f"rain {rate * 3600e3:.2f} mm/h for {(t_off - t_on) / 3600:g} h on "
          f"{rain['slope'] / rate:g} m of slope and {rain['column'] / rate:g} m of column; "
          f"water table {y_w:g} m, seepage face (toe) at {y_f:g} m")

    # ---- 1. the run
    if summary.get("status") != "successful":
        problems.append(f"status {summary.get('status')}: {summary.get('message')}")
    if "in 3 stages" not in summary.get("message", ""):
        problems.append(f"summary message {summary.get('message')!r}: not 3 stages")

    # ---- snapshots: stored water, the initial state, the final state
    n_slope = len(slope_pts)
    snaps = snapshot_files(results)
    rows, start, end_state, rain_end = [], None, None, None
    worst_suction = -1e300
    # the rained particles of the level crest and of the column (the lower
    # slope becomes a seepage face: p > 0 under it is the water leaving)
    crest = max(v[1] for v in polygon)
    crest_end = max(v[0] for v in polygon if abs(v[1] - crest) < 1e-9)
    level = set(p for p in rained["slope"] if p[0] < crest_end) | set(rained["column"])
    rained_idx = [i for i, p in enumerate(slope_pts + column_pts) if p in level]
    for t, path in snaps:
        if t < t_on - 1e-6:
            continue
        d = read_vtu(path)
        if len(d["volume"]) != n_slope + len(column_pts):
            problems.append(f"snapshot at t = {t:g} s has {len(d['volume'])} particles")
            return report(problems)
        sums = []
        for lo, hi in ((0, n_slope), (n_slope, len(d["volume"]))):
            vol = sum(d["volume"][lo:hi])
            comp = sum(v * n / k_w * p for v, n, p in
                       zip(d["volume"][lo:hi], d["porosity"][lo:hi], d["pore_pressure"][lo:hi]))
            sums.append((vol, comp))
        if start is None:
            start = (t, sums, d)
        stored = [sums[b][0] - start[1][b][0] + sums[b][1] - start[1][b][1] for b in (0, 1)]
        duration = max(0.0, min(t, t_off) - t_on)
        rows.append((t, rain["slope"] * duration, stored[0], rain["column"] * duration, stored[1]))
        for i in rained_idx:
            worst_suction = max(worst_suction, d["pore_pressure"][i])
        if abs(t - t_off) < 1e-6:
            rain_end = d
        end_state = (t, d)
    if start is None or abs(start[0] - t_on) > 1e-6 or rain_end is None:
        problems.append("no snapshots at the rain's start and end (snapshots.interval must "
                        "divide the stage times)")
        return report(problems)

    # ---- 2. the gravity-loaded state at the rain's start
    d0 = start[2]
    hydro = max(abs(p - GAMMA_W * (y_w - x[1])) for p, x in zip(d0["pore_pressure"], d0["Points"]))
    print(f"  at the rain's start: max |p - gamma_w (y_w - y)| = {hydro:.3g} Pa")
    if hydro > 0.05:
        problems.append(f"the gravity-loaded state is not hydrostatic: {hydro:.3g} Pa off")

    # ---- 5. the seepage face, every step (needed first: it dates item 4's window)
    face_poly = face["nodes"]["polygon"]
    cells = {}
    for q in series["particles"]:
        x0, y0 = q["initial_position"]
        cells.setdefault((math.floor(x0 / h + 1e-9), math.floor(y0 / h + 1e-9)), []).append(q)
    # the face's nodes that hold water: corners of a cell with slope particles
    wet = set()
    for x, y in slope_pts:
        i, j = math.floor(x / h), math.floor(y / h)
        wet.update((i + a, j + b) for a in (0, 1) for b in (0, 1))
    face_nodes = sorted(n for n in wet if in_polygon(face_poly, n[0] * h, n[1] * h, 1e-6 * h))
    face_max, face_at, first_active, missing = -1e300, None, None, set()
    times = series["time"]
    for r in range(1, len(times)):
        if times[r] <= t_on + 1e-9:
            continue
        nodal = nodal_pressures(cells, h, r)
        missing.update(n for n in face_nodes if n not in nodal)
        top = max(nodal[n] for n in face_nodes if n in nodal)
        if top > face_max:
            face_max, face_at = top, times[r]
        if first_active is None and top >= -1.0:
            first_active = times[r]
    print(f"  seepage face: {len(face_nodes)} nodes with water, recovered from the series every "
          f"step; highest nodal pore pressure over {len(times) - 1} steps {face_max:.3g} Pa "
          f"(t = {(face_at or 0) / 3600:.2f} h); first at p = 0 at t = "
          + (f"{first_active / 3600:.2f} h" if first_active else "never"))
    if missing:
        problems.append(f"face nodes {sorted(missing)[:6]} not recovered from the series")
    if face_max > 1e-6:
        problems.append(f"the seepage face holds p = {face_max:.4g} Pa > 0 at t = {face_at:g} s")
    if first_active is None:
        problems.append("the seepage face never reaches p = 0: no water left the slope")

    # ---- 3. and 4. water balance
    total_slope, total_column = rain["slope"] * (t_off - t_on), rain["column"] * (t_off - t_on)
    worst_column = max(abs(r[3] - r[4]) for r in rows) / total_column
    before = [r for r in rows if first_active is None or r[0] < first_active - 1e-6]
    worst_slope = max(abs(r[1] - r[2]) for r in before) / total_slope
    outflow = [r[1] - r[2] for r in rows]
    drop = max(max(0.0, a - b) for a, b in zip(outflow, outflow[1:])) / total_slope
    left = outflow[-1] / total_slope
    print(f"  control column: |rain - stored| <= {worst_column:.3g} of its rain "
          f"({total_column:.5g} m2/m) over {len(rows)} snapshots")
    print(f"  slope: |rain - stored| <= {worst_slope:.3g} of its rain ({total_slope:.5g} m2/m) "
          f"at the {len(before)} snapshots before the face acts (t = "
          f"{', '.join(f'{r[0] / 3600:g}' for r in before)} h); outflow never falls by more "
          f"than {drop:.3g}; at the end {100 * left:.1f} % of the rain has left")
    if worst_column > 5e-5:
        problems.append(f"the control column's water balance is off by {worst_column:.3g}")
    if len(before) < 3:
        problems.append(f"only {len(before)} snapshots before the face acts")
    if worst_slope > 1e-5:
        problems.append(f"the slope's water balance before outflow is off by {worst_slope:.3g}")
    if drop > 1e-5:
        problems.append(f"the outflow falls by {drop:.3g} of the rain: water entered the face")
    if left < 0.1:
        problems.append(f"only {100 * left:.2f} % of the rain left the slope")

    # ---- 6. the control column against the 1D closed form
    line = next(p for p in profiles["profiles"]
                if abs(p["initial_positions"][0][0] - column_pts[0][0]) < 1e-9)
    ptimes = profiles["time"]
    r0 = min(range(len(ptimes)), key=lambda i: abs(ptimes[i] - t_on))
    settled = [d[1] for d in line["displacement"][r0]]
    top_row = max(range(len(settled)), key=lambda i: line["initial_positions"][i][1])
    height = column_height + settled[top_row]
    grad = rate * GAMMA_W / k
    worst_1d, worst_at, samples = 0.0, (0.0, 0.0), 0
    for row, t in enumerate(ptimes):
        tv = c_v * (t - t_on) / height ** 2
        if tv < 0.05:
            continue
        samples += 1
        for x0, p, p0, dy, disp in zip(line["initial_positions"], line["pore_pressure"][row],
                                       line["pore_pressure"][r0], settled,
                                       line["displacement"][row]):
            z = height - (x0[1] + dy)
            exact = (column_excess(z, t - t_on, height, grad, c_v)
                     - column_excess(z, t - t_off, height, grad, c_v))
            # the particle rose by disp - dy through the hydrostatic gradient
            err = (p - p0 + GAMMA_W * (disp[1] - dy) - exact) / (grad * height)
            if abs(err) > abs(worst_1d):
                worst_1d, worst_at = err, (tv, z)
    print(f"  control column vs the 1D closed form: {samples} samples, c_v = {c_v:.4g} m2/s, "
          f"H = {height:.4f} m, G H = {grad * height:.0f} Pa; worst {100 * worst_1d:+.2f} % of "
          f"G H at T_v = {worst_at[0]:.3f}, depth {worst_at[1]:.2f} m")
    if abs(worst_1d) > 0.025 or samples < 10:
        problems.append(f"control column: {100 * worst_1d:.2f} % of G H from the closed form "
                        f"({samples} samples)")

    # ---- 7. the final state: at rest, the table at the face
    t_last, d = end_state
    rise = GAMMA_W * (y_f - y_w)
    final = max(abs(p - GAMMA_W * (y_f - x[1]))
                for p, x in zip(d["pore_pressure"][:n_slope], d["Points"][:n_slope]))
    print(f"  at the end (t = {t_last / 86400:g} days): max |p - gamma_w (y_f - y)| = "
          f"{final:.1f} Pa = {100 * final / rise:.2f} % of the table's rise")
    if abs(t_last - t_end) > 1e-6:
        problems.append(f"the last snapshot is at t = {t_last:g} s, not the end {t_end:g} s")
    if final > 0.01 * rise:
        problems.append(f"the slope is not at rest with its table at the face: "
                        f"{100 * final / rise:.2f} % of the rise off")

    # ---- 8. the rain raises the pore pressure, the surface stays in suction
    change = [p - p0 for p0, p in zip(start[2]["pore_pressure"], rain_end["pore_pressure"])]
    print(f"  during the rain the pore pressure rose at every particle, by {min(change):.0f} to "
          f"{max(change):.0f} Pa; the rained crest and column surface at most at "
          f"{worst_suction:.0f} Pa")
    if min(change) < 1.0:
        problems.append(f"the pore pressure rose by only {min(change):.4g} Pa somewhere during "
                        "the rain")
    if not worst_suction < 0:
        problems.append(f"a rained particle of the crest or the column reached p = "
                        f"{worst_suction:.4g} Pa >= 0")
    return report(problems)


def report(problems):
    for p in problems[:20]:
        print("FAIL:", p)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
