#!/usr/bin/env python3
"""Runs the verification examples with `hmpm run` and plots them against
their closed forms: the figures and the error table of docs/verification.md.

    python3 scripts/verification_figures.py [--hmpm build/bin/hmpm] [--out docs/figures]

Prints the error table as Markdown on stdout. Needs numpy and matplotlib
(Debian: python3-numpy, python3-matplotlib; run it with /usr/bin/python3 or
`$(bash scripts/python.sh)`).
"""
import argparse
import json
import math
import pathlib
import subprocess
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

REPO = pathlib.Path(__file__).resolve().parent.parent
GAMMA_W = 1000.0 * 9.81


def run_example(hmpm, name, work):
    out = pathlib.Path(work) / name
    subprocess.run([str(hmpm), "run", str(REPO / "examples" / f"{name}.json"), "--out", str(out)],
                   check=True, capture_output=True)
    spec = json.loads((REPO / "examples" / f"{name}.json").read_text())
    series = json.loads((out / "series.json").read_text())
    return spec, series


# ------------------------------------------------------------ closed forms
def bar_exact(x, t, E, rho, L, v0):
    beta = math.pi / (2 * L)
    omega = beta * math.sqrt(E / rho)
    return v0 / omega * math.sin(omega * t) * math.sin(beta * x), v0 / omega


def darcy_exact(x, t, L, dp, c, terms=400):
    p = dp * (1 - x / L)
    for m in range(1, terms + 1):
        e = math.exp(-((m * math.pi / L) ** 2) * c * t)
        if e < 1e-300:
            break
        p -= 2 * dp / (m * math.pi) * math.sin(m * math.pi * x / L) * e
    return p


def terzaghi_exact(z, tv, H, q, terms=400):
    p = 0.0
    for m in range(terms):
        M = math.pi * (2 * m + 1) / 2
        e = math.exp(-M * M * tv)
        if e < 1e-300:
            break
        p += q * 2 / M * math.sin(M * z / H) * e
    return p


def mandel_roots(nu, nu_u, terms=400):
    """Positive roots of tan(a) = (1 - nu)/(nu_u - nu) a, one per ((n-1) pi, (n-1) pi + pi/2)."""
    k = (1 - nu) / (nu_u - nu)
    roots = []
    for n in range(1, terms + 1):
        lo, hi = (n - 1) * math.pi + 1e-9, (n - 1) * math.pi + math.pi / 2 - 1e-12
        f = lambda x: math.sin(x) - k * x * math.cos(x)  # noqa: E731
        lo_negative = f(lo) < 0
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            if (f(mid) < 0) == lo_negative:
                lo = mid
            else:
                hi = mid
        roots.append(0.5 * (lo + hi))
    return roots


def mandel_exact(x, T, a, p0, roots):
    """Mandel (1953), Abousleiman et al. (1996): pore pressure at x, T = c t / a^2."""
    s = 0.0
    for r in roots:
        e = math.exp(-r * r * T)
        if e < 1e-300:
            break
        s += math.sin(r) / (r - math.sin(r) * math.cos(r)) * (math.cos(r * x / a) - math.cos(r)) * e
    return 2 * p0 * s


# ------------------------------------------------------------ figures
def bar_figure(spec, series, out):
    mat = next(iter(spec["materials"].values()))
    E, rho = mat["youngs_modulus"], mat["density"]
    L = spec["bodies"][0]["box"]["max"][0]
    v0 = 0.1
    t = series["time"]
    fig, ax = plt.subplots(figsize=(7, 4))
    worst, sum2, count = 0.0, 0.0, 0
    for p in series["particles"]:
        x = p["initial_position"][0]
        u = [row[0] for row in p["displacement"]]
        ue = [bar_exact(x, ti, E, rho, L, v0)[0] for ti in t]
        amp = bar_exact(x, 0, E, rho, L, v0)[1]
        sq = sum((a - b) ** 2 for a, b in zip(u, ue))
        sum2, count = sum2 + sq, count + len(u)
        worst = max(worst, math.sqrt(sq / len(u)) / amp)
        line, = ax.plot(t, u, "o", ms=2.5, label=f"particle {p['index'] + 1} (hmpm)")
        ax.plot(t, ue, "-", color=line.get_color(), lw=1)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("displacement (m)")
    ax.set_title("Vibrating bar: particles 1, 4, 7, 13 (dots) vs exact (lines)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "bar-vibration.png", dpi=110)
    plt.close(fig)
    pooled = math.sqrt(sum2 / count) / bar_exact(0, 0, E, rho, L, v0)[1]
    return [("Vibrating bar (paper Fig. 3)", "RMS displacement error / amplitude v0/w, particles 1, 4, 7, 13 together",
             f"{100 * pooled:.2f} %", "1 %"),
            ("Vibrating bar (paper Fig. 3)", "worst single particle: RMS error / v0/w (particle 13)",
             f"{100 * worst:.2f} %", "(see text)")]


def darcy_figures(spec, series, out):
    mat = next(iter(spec["materials"].values()))
    h = mat["hydraulic"]
    L = spec["grid"]["max"][0]
    dp = 100.0
    c = h["hydraulic_conductivity"] / (GAMMA_W * h["porosity"] / h["fluid_bulk_modulus"])
    t = series["time"]
    xs = [p["initial_position"][0] for p in series["particles"]]
    fig, ax = plt.subplots(figsize=(7, 4))
    worst = 0.0
    for target in [0.0002, 0.0005, 0.001, 0.002, 0.005, 0.02]:
        row = min(range(len(t)), key=lambda i: abs(t[i] - target))
        pp = [p["pore_pressure"][row] for p in series["particles"]]
        pe = [darcy_exact(x, t[row], L, dp, c) for x in xs]
        if c * t[row] / L ** 2 >= 0.02:
            worst = max(worst, max(abs(a - b) for a, b in zip(pp, pe)) / dp)
        line, = ax.plot(xs, pp, "o", ms=3, label=f"t = {t[row] * 1000:.1f} ms")
        fine = [i / 200 * L for i in range(201)]
        ax.plot(fine, [darcy_exact(x, t[row], L, dp, c) for x in fine], "-", color=line.get_color(), lw=1)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("pore pressure (Pa)")
    ax.set_title("Darcy flow: pressure along the sample (dots) vs series solution (lines)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "darcy-pressure.png", dpi=110)
    plt.close(fig)

    w_exact = h["hydraulic_conductivity"] * dp / (GAMMA_W * L)
    fig, ax = plt.subplots(figsize=(7, 4))
    for idx in (0, 9, 19):
        p = series["particles"][idx]
        ax.plot([ti * 1000 for ti in t], [w[0] for w in p["darcy_velocity"]], label=f"particle {idx + 1}")
    ax.axhline(w_exact, color="k", ls="--", lw=1, label="steady k dp/(gamma_w L)")
    ax.set_xlabel("time (ms)")
    ax.set_ylabel("Darcy velocity (m/s)")
    ax.set_title("Darcy flow: Darcy velocity of particles 1, 10, 20")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "darcy-velocity.png", dpi=110)
    plt.close(fig)
    steady_p = max(abs(p["pore_pressure"][-1] - dp * (1 - x / L)) for p, x in zip(series["particles"], xs)) / dp
    steady_w = max(abs(p["darcy_velocity"][-1][0] - w_exact) for p in series["particles"]) / w_exact
    return [("Darcy flow (paper Fig. 6)", "max |p - p_exact| / dp, all particles, c t/L^2 >= 0.02",
             f"{100 * worst:.2f} %", "1 %"),
            ("Darcy flow, steady (Fig. 6, 7)", "max relative error of p and w at every particle",
             f"{max(steady_p, steady_w):.1e}", "1e-6")]


def terzaghi_figure(spec, series, out, snapshots_dir=None):
    mat = next(iter(spec["materials"].values()))
    h = mat["hydraulic"]
    E, nu = mat["youngs_modulus"], mat["poisson_ratio"]
    H = spec["grid"]["max"][0]
    q = 1000.0
    m_v = (1 + nu) * (1 - 2 * nu) / (E * (1 - nu))
    Q = h["porosity"] / h["fluid_bulk_modulus"]
    cv = h["hydraulic_conductivity"] / (GAMMA_W * (m_v + Q))
    t = series["time"]
    fig, ax = plt.subplots(figsize=(7, 4))
    worst = 0.0
    for p in series["particles"]:
        z = H - p["initial_position"][0]
        tv = [ti * cv / H ** 2 for ti in t]
        pe = [terzaghi_exact(z, v, H, q) for v in tv]
        for v, a, b in zip(tv, p["pore_pressure"], pe):
            if v >= 0.05:
                worst = max(worst, abs(a - b) / q)
        line, = ax.plot(tv, p["pore_pressure"], "o", ms=2.5, label=f"z = {z:.3f} m")
        ax.plot(tv, pe, "-", color=line.get_color(), lw=1)
    ax.set_xlabel("time factor T_v = c_v t / H^2")
    ax.set_ylabel("excess pore pressure (Pa)")
    ax.set_title("Terzaghi consolidation: hmpm (dots) vs closed form (lines)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "terzaghi.png", dpi=110)
    plt.close(fig)
    return [("Terzaghi (verification 3)", "max |p - p_exact| / q, series particles, T_v >= 0.05",
             f"{100 * worst:.2f} %", "1 %")]


def mandel_figure(spec, series, out):
    mat = next(iter(spec["materials"].values()))
    h = mat["hydraulic"]
    E, nu, n = mat["youngs_modulus"], mat["poisson_ratio"], h["porosity"]
    a = spec["bodies"][0]["box"]["max"][0]
    q = -spec["tractions"][0]["traction"][1]
    G = E / (2 * (1 + nu))
    K = E / (3 * (1 - 2 * nu))
    M = h["fluid_bulk_modulus"] / n  # incompressible grains: Biot modulus Kf/n
    E_oed = K + 4 * G / 3
    B = M / (K + M)
    nu_u = (3 * (K + M) - 2 * G) / (2 * (3 * (K + M) + G))
    c = h["hydraulic_conductivity"] / GAMMA_W / (1 / M + 1 / E_oed)
    p0 = q * B * (1 + nu_u) / 3
    roots = mandel_roots(nu, nu_u)
    T = [ti * c / a ** 2 for ti in series["time"]]
    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    ax = axes[0]
    worst_centre, peak = 0.0, 0.0
    for k, p in enumerate(series["particles"][:1] + series["particles"][3::3]):
        x = p["initial_position"][0]
        pe = [mandel_exact(x, v, a, p0, roots) if v > 0 else p0 for v in T]
        pp = p["pore_pressure"]
        if k == 0:
            worst_centre = max(abs(u - w) for u, w in zip(pp, pe)) / p0
            peak = max(pp) / p0
        line, = ax.plot(T, [u / p0 for u in pp], "o", ms=2, label=f"x = {x / a:.3f} a")
        fine = [0.0005 * i for i in range(1, 1001)]
        ax.plot(fine, [mandel_exact(x, v, a, p0, roots) / p0 for v in fine], "-", color=line.get_color(), lw=1)
    ax.axhline(1.0, color="k", lw=0.5)
    ax.set_xlabel("T = c t / a^2")
    ax.set_ylabel("p / p0")
    ax.set_title("Mandel: pore pressure, hmpm (dots) vs closed form (lines)", fontsize=9)
    ax.legend(fontsize=8)
    ax = axes[1]
    xs = [p["initial_position"][0] for p in series["particles"]]
    for target in (0.01, 0.05, 0.1, 0.2, 0.5):
        row = min(range(len(T)), key=lambda i: abs(T[i] - target))
        line, = ax.plot([x / a for x in xs], [p["pore_pressure"][row] / p0 for p in series["particles"]], "o", ms=3,
                        label=f"T = {T[row]:.2f}")
        fine = [i / 100 * a for i in range(101)]
        ax.plot([x / a for x in fine], [mandel_exact(x, T[row], a, p0, roots) / p0 for x in fine], "-",
                color=line.get_color(), lw=1)
    ax.set_xlabel("x / a")
    ax.set_ylabel("p / p0")
    ax.set_title("Mandel: profiles across the specimen", fontsize=9)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "mandel.png", dpi=110)
    plt.close(fig)
    fine = [0.0005 * i for i in range(1, 1001)]
    peak_exact = max(mandel_exact(xs[0], v, a, p0, roots) for v in fine) / p0
    return [("Mandel (verification 4)", "max |p - p_exact| / p0 at the centre particle, T in [0, 0.5]",
             f"{100 * worst_centre:.2f} %", "3 %"),
            ("Mandel (verification 4)", "Mandel-Cryer peak at the centre, p / p0 (closed form)",
             f"{peak:.4f} ({peak_exact:.4f})", "3 % of p0")]


# ------------------------------------------------------------ column collapse
def lube_2005(a):
    """Lube et al. (2005), quasi-2D, interpolated linearly for 1.8 < a < 2.8."""
    if a <= 1.8:
        return 1.2 * a
    if a >= 2.8:
        return 1.9 * a ** (2 / 3)
    lo, hi = 1.2 * 1.8, 1.9 * 2.8 ** (2 / 3)
    return lo + (a - 1.8) / (2.8 - 1.8) * (hi - lo)


def collapse_spec(base, a, dim, across):
    """The set-up of examples/column-collapse.json (and of
    tests/solver/test_collapse.cpp) for aspect ratio a: 2D with `across`
    cells across min(H0, L0), or the 3D quarter cylinder (staircase of
    whole cells, z up) with `across` cells across R0. Returns the spec, H0,
    L0 (or the equivalent radius R0) and the cell size."""
    h, rho, g = 0.01, 1800.0, 9.81
    spec = json.loads(json.dumps(base))
    mat = spec["materials"]["sand"]
    # 2D: the example's plane-strain angle (35.26 deg, sin phi = tan 30 deg);
    # 3D: 30 deg, as tests/solver/test_collapse.cpp (Davis's equivalence is
    # a plane-strain result).
    if dim == 3:
        mat["friction_angle"] = 30.0
    k0 = 1 - math.sin(math.radians(mat["friction_angle"]))
    if dim == 2:
        n_l = across if a >= 1 else round(across / a)
        n_h = round(n_l * a)
        expected = lube_2005(a)
        nx = math.ceil(n_l * (1 + 3 * expected)) + 4
        cells = [nx, n_h + 3]
        up, boxes = 1, [([0, 0], [n_l * h, n_h * h])]
        l0 = n_l * h
    else:
        n_h = round(across * a)
        expected = 1.24 * a
        nxy = math.ceil(across * (1 + 2 * expected)) + 4
        cells = [nxy, nxy, n_h + 3]
        up, boxes, count = 2, [], 0
        for j in range(across):
            row = 0
            while (row + 0.5) ** 2 + (j + 0.5) ** 2 <= across ** 2:
                row += 1
            if row:
                count += row
                boxes.append(([0, j * h, 0], [row * h, (j + 1) * h, n_h * h]))
        l0 = math.sqrt(4 * count * h * h / math.pi)
    h0 = n_h * h
    mat["youngs_modulus"] = rho * g * h0 / 1e-3
    spec["dimension"] = dim
    spec["grid"] = {"min": [0.0] * dim, "max": [c * h for c in cells], "cells": cells}
    axis = "xyz"[up]
    sv = f"-{rho}*{g}*({h0}-{axis})"
    stress = [f"-{k0}*{rho}*{g}*({h0}-{axis})"] * 3 + [0, 0, 0]
    stress[up] = sv
    spec["bodies"] = [{"material": "sand", "box": {"min": lo, "max": hi}, "particles_per_cell": 2,
                       "initial": {"effective_stress": stress}} for lo, hi in boxes]
    spec["gravity"] = [0.0] * dim
    spec["gravity"][up] = -g
    spec["boundaries"] = []
    for ax in range(dim):
        lo, hi = [0.0] * dim, [c * h for c in cells]
        hi[ax] = 0.0
        v = [None] * dim
        v[ax] = 0.0
        b = {"nodes": {"box": {"min": lo, "max": hi}}, "velocity": v}
        if ax == up:
            b["friction"] = "rough"
        spec["boundaries"].append(b)
    # At rest by then in every case (tests: at most 5.4 sqrt(H0/g) in 2D, 7 in 3D).
    spec["time"] = {"end": (8 if dim == 2 else 10) * math.sqrt(h0 / g)}
    spec["output"] = {"snapshots": {"interval": spec["time"]["end"], "fields": ["displacement"]}}
    return spec, h0, l0, h


def deposit_front(points, dim, h, h0):
    """The front of the deposit as in tests/solver/test_collapse.cpp: the end
    of the contiguous bins of width h from the wall (radial bins in 3D)
    whose thickness (particle volume / plan area) is >= 2 % of H0, plus half
    a particle spacing (2 particles per cell)."""
    import numpy as np
    dp = h / 2
    r = points[:, 0] if dim == 2 else np.hypot(points[:, 0], points[:, 1])
    bins = (r / h).astype(int)
    volume = np.bincount(bins) * dp ** dim
    i = np.arange(len(volume))
    area = h * np.ones_like(volume) if dim == 2 else 0.25 * math.pi * ((i + 1) ** 2 - i ** 2) * h * h
    end = 0
    while end < len(volume) and volume[end] / area[end] >= 0.02 * h0:
        end += 1
    return r[r < end * h].max() + dp / 2


def deposit_toe(points, h, h0, l0):
    """The toe of a 2D deposit as in tests/solver/test_collapse.cpp: the
    thickness profile in bins max(h, min(H0, L0)/20) wide; from the wall the
    contiguous bins at least 10 % of the largest thickness; a line fitted to
    those at most 40 % of it, extrapolated to zero thickness."""
    import numpy as np
    dp = h / 2
    bw = max(h, 0.05 * min(h0, l0))
    x = points[:, 0]
    t = np.bincount((x / bw).astype(int)) * dp * dp / bw
    t_max = t.max()
    fit, k = [], 0
    while k < len(t) and t[k] >= 0.1 * t_max:
        if t[k] <= 0.4 * t_max:
            fit.append(k)
        k += 1
    slope, intercept = np.polyfit((np.array(fit) + 0.5) * bw, t[fit], 1)
    return -intercept / slope


def collapse_figure(hmpm, work, out, cells=(10, 20)):
    """2D at a = 0.5, 1, 2, 5 with each number of cells across in `cells`
    (the deposits drawn are those of the finest), and the 3D case."""
    import meshio
    base = json.loads((REPO / "examples" / "column-collapse.json").read_text())
    cases = [(a, 2, n) for n in cells for a in (0.5, 1, 2, 5)] + [(1.0, 3, 8)]
    results = []
    for a, dim, across in cases:
        spec, h0, l0, h = collapse_spec(base, a, dim, across)
        name = f"collapse-{dim}d-{a}-{across}"
        path = pathlib.Path(work) / f"{name}.json"
        path.write_text(json.dumps(spec))
        subprocess.run([str(hmpm), "run", str(path), "--out", str(pathlib.Path(work) / name)],
                       check=True, capture_output=True)
        last = sorted((pathlib.Path(work) / name).glob("snapshot_*.vtu"))[-1]
        pts = meshio.read(last).points
        front = deposit_toe(pts, h, h0, l0) if dim == 2 else deposit_front(pts, dim, h, h0)
        results.append((a, dim, across, (front - l0) / l0, pts / l0, front / l0))
    fig = plt.figure(figsize=(12, 5.5))
    grid = fig.add_gridspec(4, 2, width_ratios=[1.6, 1])
    ax2 = fig.add_subplot(grid[:, 1])
    panels = [r for r in results if r[1] == 2 and r[2] == max(cells)]
    for k, (a, dim, _, r, pts, front) in enumerate(panels):
        ax1 = fig.add_subplot(grid[k, 0])
        ax1.plot(pts[:, 0], pts[:, 1], ".", ms=1.0, color="tab:brown")
        ax1.axvline(front, color="k", lw=0.8, ls="--")
        ax1.axvline(1 + lube_2005(a), color="tab:blue", lw=0.8)
        ax1.set_xlim(0, 1.35 * (1 + lube_2005(a)))
        ax1.set_ylabel(f"a = {a:g}\ny / L0", fontsize=8)
        ax1.tick_params(labelsize=7)
        if k == 0:
            ax1.set_title(f"2D deposits, {max(cells)} cells across: toe measured (dashed), "
                          "Lube 2005 (blue)", fontsize=9)
        if k == len(panels) - 1:
            ax1.set_xlabel("x / L0")
    aa = [0.3 + 0.05 * i for i in range(100)]
    ax2.plot([x for x in aa if x <= 1.8], [1.2 * x for x in aa if x <= 1.8], "k-", lw=1,
             label="Lube 2005: 1.2 a, 1.9 a^(2/3)")
    ax2.plot([x for x in aa if x >= 2.8], [1.9 * x ** (2 / 3) for x in aa if x >= 2.8], "k-", lw=1)
    ax2.plot([1.8, 2.8], [lube_2005(1.8), lube_2005(2.8)], "k:", lw=1, label="interpolated")
    ax2.plot([0.3, 1.7], [1.24 * 0.3, 1.24 * 1.7], "b--", lw=1, label="Lube 2004 (axisymmetric): 1.24 a")
    markers = {n: m for n, m in zip(sorted(cells), ["o", "s", "^", "D"])}
    for n in sorted(cells):
        pts2 = [(a, r) for a, dim, across, r, *_ in results if dim == 2 and across == n]
        ax2.plot([p[0] for p in pts2], [p[1] for p in pts2], markers[n], color="k",
                 mfc="none" if n != max(cells) else "k", ms=5, ls="none", label=f"2D, {n} cells")
    for a, dim, _, r, *_ in results:
        if dim == 3:
            ax2.plot([a], [r], "bs", ms=5, label="3D, 8 cells across R0")
    ax2.set_xlabel("aspect ratio a = H0 / L0")
    ax2.set_ylabel("(L_inf - L0) / L0")
    ax2.set_title("runout: hmpm vs Lube")
    ax2.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "column-collapse.png", dpi=110)
    plt.close(fig)
    rows = []
    for a, dim, across, r, *_ in results:
        ref = lube_2005(a) if dim == 2 else 1.24 * a
        law = "Lube 2005" if dim == 2 else "Lube 2004, 3D quarter"
        bound = "15 %" if dim == 2 else "25 %"
        rows.append((f"Column collapse a = {a:g} ({law}, {across} cells)",
                     f"(L_inf - L0)/L0 vs {ref:.3f}", f"{r:.3f} ({100 * (r / ref - 1):+.1f} %)", bound))
    return rows


# ------------------------------------------------------------ saturated slope
def slope_figure(spec, series, out, run_dir):
    """The infinite slope of examples/slope-failure.json: pore pressures vs
    the quasi-steady closed form, the mid column's slope-parallel
    displacement vs the sliding block, the slope before and after."""
    import meshio  # noqa: PLC0415 (only this figure reads snapshots)
    import numpy as np  # noqa: PLC0415
    g_vec = spec["gravity"]
    g = math.hypot(*g_vec)
    beta = math.atan2(g_vec[0], -g_vec[1])
    mat = spec["materials"]["soil"]
    hy = mat["hydraulic"]
    n, rho_f = hy["porosity"], hy["fluid_density"]
    rho = (1 - n) * mat["density"] + n * rho_f
    E, nu = mat["youngs_modulus"], mat["poisson_ratio"]
    E_oed = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu))
    c_v = hy["hydraulic_conductivity"] / (rho_f * g) / (1 / E_oed + n / hy["fluid_bulk_modulus"])
    phi = math.radians(mat["friction_angle"])
    H = spec["bodies"][0]["box"]["max"][1]
    S = rho * g * math.cos(beta) * H
    base = next(b for b in spec["boundaries"] if "pore_pressure" in b and b["pore_pressure"] != 0)
    formula = base["pore_pressure"]  # muParser text that is also Python

    def r(t):
        return eval(formula, {"max": max, "abs": abs, "t": t}) / S  # noqa: S307

    def r_rate(t, dt=1e-6):
        return (r(t + dt) - r(t - dt)) / (2 * dt)

    def p_exact(d, t):  # quasi-steady: steady profile plus the lag of a ramp
        return r(t) * S * d / H + r_rate(t) * S / (6 * c_v * H) * (d ** 3 - H * H * d)

    mu_davis, mu_coulomb = math.sin(phi), math.tan(phi)
    r_f = 1 - math.tan(beta) / mu_davis
    times = series["time"]
    end = times[-1]

    def block(mu, dt=1e-4):
        x = v = 0.0
        ts, xs = [0.0], [0.0]
        t = 0.0
        while t < end:
            a = g * (math.sin(beta) - (1 - r(t)) * math.cos(beta) * mu)
            if v <= 0 and a < 0:
                a = v = 0.0
            v += a * dt
            x += v * dt
            t += dt
            ts.append(t)
            xs.append(x)
        return ts, xs

    fs = [(1 - r(t)) * mu_davis / math.tan(beta) for t in times]
    t_fail = next(0.001 * i for i in range(int(1000 * end)) if r(0.001 * i) >= r_f)
    parts = series["particles"]
    mean_u = [sum(p["displacement"][i][0] for p in parts) / len(parts) for i in range(len(times))]
    t_peak = max(times, key=r)
    worst_p = 0.0
    for p in parts:
        d = H - p["initial_position"][1]
        for i, t in enumerate(times):
            settled = abs(t - 0.5) > 5 * H * H / (math.pi ** 2 * c_v)
            if settled and fs[i] >= 1.05 and t < t_peak:
                worst_p = max(worst_p, abs(p["pore_pressure"][i] - p_exact(d, t)) / S)
    tb, ub = block(mu_davis)
    tc, uc = block(mu_coulomb)
    onset = next(t for t, u in zip(times, mean_u) if u > 0.01 * H)
    onset_block = next(t for t, u in zip(tb, ub) if u > 0.01 * H)
    runout = mean_u[-1]

    fig = plt.figure(figsize=(12, 7.5))
    ax = fig.add_subplot(2, 2, 1)
    for p in parts[::3]:
        d = H - p["initial_position"][1]
        line, = ax.plot(times, [v / S for v in p["pore_pressure"]], "o", ms=1.5, label=f"d = {d:.2f} m")
        ax.plot(times, [p_exact(d, t) / S for t in times], "-", lw=0.8, color=line.get_color())
    ax.axvline(t_fail, color="r", lw=0.7, ls="--")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("p / (rho_sat g H cos beta)")
    ax.set_title("pore pressure in the mid column, hmpm (dots) vs quasi-steady closed form (lines)", fontsize=8)
    ax.legend(fontsize=7)
    ax = fig.add_subplot(2, 2, 2)
    ax.plot(times, mean_u, "k-", lw=2, label="hmpm, mid column (mean)")
    top = max(parts, key=lambda p: p["initial_position"][1])
    ax.plot(times, [u[0] for u in top["displacement"]], "k:", lw=1, label="hmpm, surface particle of that column")
    ax.plot(tb, ub, "b--", lw=1, label="sliding block, mu = sin phi (Davis)")
    ax.plot(tc, uc, "g--", lw=1, label="sliding block, mu = tan phi (Coulomb)")
    ax.axvline(t_fail, color="r", lw=0.7, ls="--", label=f"FS = 1 (t = {t_fail:.2f} s)")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("slope-parallel displacement (m)")
    ax2 = ax.twinx()
    ax2.plot(times, fs, color="0.6", lw=0.8)
    ax2.axhline(1.0, color="0.6", lw=0.5, ls=":")
    ax2.set_ylabel("FS (grey)")
    ax.set_title("failure and runout", fontsize=8)
    ax.legend(fontsize=7, loc="upper left")
    ax = fig.add_subplot(2, 1, 2)
    snaps = sorted(pathlib.Path(run_dir).glob("snapshot_*.vtu"))
    cb, sb = math.cos(beta), math.sin(beta)

    def real(x, y):  # slope coordinates to real-world horizontal and vertical
        return x * cb + y * sb, -x * sb + y * cb

    m = meshio.read(snaps[-1])
    X, Z = real(m.points[:, 0], m.points[:, 1])
    sc = ax.scatter(X, Z, s=1, c=m.point_data["displacement"][:, 0], cmap="viridis")
    fig.colorbar(sc, ax=ax, label=f"slope-parallel displacement at t = {end:g} s (m)", shrink=0.8)
    L = spec["bodies"][0]["box"]["max"][0]
    X0, Z0 = real(np.array([0, L, L, 0, 0]), np.array([0, 0, H, H, 0]))
    ax.plot(X0, Z0, "r-", lw=0.8, label="t = 0")
    ax.legend(fontsize=7)
    ax.set_aspect("equal")
    ax.set_xlabel("horizontal (m)")
    ax.set_ylabel("vertical (m)")
    ax.set_title(f"the slope segment (beta = {math.degrees(beta):.0f} deg) before (red outline) and after the slide",
                 fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "slope-failure.png", dpi=110)
    plt.close(fig)
    return [("Saturated slope (infinite slope, pore-pressure pulse)",
             "max |p - p_exact| / (rho_sat g H cos beta), mid column, FS >= 1.05", f"{100 * worst_p:.2f} %", "1 %"),
            ("Saturated slope", "onset (mid column moved 0.01 H) vs sliding block, mu = sin phi",
             f"{onset:.2f} s ({onset_block:.2f} s; FS = 1 at {t_fail:.2f} s)", "0.2 s"),
            ("Saturated slope", "runout vs sliding block, mu = sin phi / tan phi",
             f"{runout:.3f} m ({ub[-1]:.3f} / {uc[-1]:.3f} m)", "between the two")]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--hmpm", default=str(REPO / "build" / "bin" / "hmpm"))
    ap.add_argument("--out", default=str(REPO / "docs" / "figures"))
    ap.add_argument("--only", choices=["bar", "darcy", "terzaghi", "mandel", "collapse", "slope"],
                    help="make one figure (and its table rows) only")
    ap.add_argument("--collapse-cells", default="10,20",
                    help="cells across min(H0, L0) of the 2D collapse runs, comma-separated "
                         "(10,20,40 reproduces the convergence table; 40 takes about an hour)")
    args = ap.parse_args()
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    with tempfile.TemporaryDirectory(prefix="hmpm-verification-") as work:
        def want(name):
            return args.only in (None, name)
        if want("bar"):
            rows += bar_figure(*run_example(args.hmpm, "bar-vibration", work), out)
        if want("darcy"):
            rows += darcy_figures(*run_example(args.hmpm, "darcy-flow", work), out)
        if want("terzaghi"):
            rows += terzaghi_figure(*run_example(args.hmpm, "terzaghi", work), out)
        if want("mandel"):
            rows += mandel_figure(*run_example(args.hmpm, "mandel", work), out)
        if want("collapse"):
            cells = tuple(int(n) for n in args.collapse_cells.split(","))
            rows += collapse_figure(args.hmpm, work, out, cells)
        if want("slope"):
            rows += slope_figure(*run_example(args.hmpm, "slope-failure", work), out,
                                 pathlib.Path(work) / "slope-failure")
    print("| problem | measure | hmpm | bound |")
    print("|---|---|---|---|")
    for r in rows:
        print("| " + " | ".join(r) + " |")


if __name__ == "__main__":
    main()
