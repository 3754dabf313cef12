"""examples/cam-clay-embankment.json: a Modified Cam-Clay layer under a wide
embankment, consolidating over ten years (docs/worked-examples.md "Cam-Clay
embankment"; docs/verification.md "Modified Cam-Clay").

Usage: check_cam_clay_embankment.py HMPM EXAMPLE.json RESULTS [--figure FILE.png]

RESULTS is the example's result directory (the example run of the test
suite). The check runs two more jobs derived from the example with HMPM:
its centre column in 1D (the same clay, load and drainage: the oedometric
limit of a load much wider than the layer) and its linear-elastic twin (E
the clay's unload-reload stiffness at mid-depth). Checked:
- the geostatic start under the centre: sigma'_v = gamma' depth within 1 %
  of the base's (the MPM quadrature of the weight: a quarter cell);
- drained at the end: |excess pore pressure| under the centre below 1 % of q;
- equilibrium at the end: the increase of sigma'_v under the centre is the
  load less gamma_w times the particle's settlement (the water table stays
  at the original surface while the clay settles below it: the submergence
  every settlement calculation allows for), between a half-space's strip
  influence (the load spreading) and the 1D limit, within 1 % of q from 2 m
  down and 3 % above;
- the Cam-Clay volume law at every series particle and sample:
  e + kappa ln p' + (lambda - kappa) ln p'c is its initial value to 1e-9
  (elastic and plastic volume changes together, exact per step);
- the 1D column's settlement against an independent integration of the
  model along the oedometric (K0) path at each particle's depth, from its
  geostatic K0 state to sigma'_v + q - gamma_w u: every particle below the
  top cell within 2 % of the surface settlement, the top particle within 5 %
  (its cell carries the load); the 2D centre within 10 % of the 1D column
  (the load's spreading under a finite embankment);
- Newton: the last iterations of the worst step converge quadratically,
  r_{k+1} <= 1e3 r_k^2 for the last two (the spin and the pressure-dependent
  elasticity in the Jacobian, solver/src/schemes/quasi_static_scheme.hpp);
- the yielded zone (p'c grown by more than 1 %): under the load at the
  surface, and nowhere beyond x = b + H;
- the elastic twin settles less (the clay's plastic compression is most of
  its settlement), reported as a ratio.
With --figure: settlement and excess pore pressure under the centre against
time (both soils) and the yielded zone.
"""
import json
import math
import os
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import random_support as rs  # noqa: E402  (its VTU reader)

YEAR = 3.15576e7
GAMMA_W = 9810.0  # the example's water: 1000 kg/m3 x 9.81


def read(path):
    with open(path) as f:
        return json.load(f)


def run(hmpm, spec, out):
    path = out + ".json"
    with open(path, "w") as f:
        json.dump(spec, f)
    done = subprocess.run([hmpm, "run", path, "--out", out, "--threads", "1"],
                          capture_output=True, text=True)
    if done.returncode != 0:
        raise SystemExit(f"{path}: hmpm exit {done.returncode}: {done.stderr}")
    return read(os.path.join(out, "series.json")), read(os.path.join(out, "summary.json"))


def column_1d(spec):
    """The example's centre column in 1D: x is the height."""
    j = json.loads(json.dumps(spec))
    top = spec["grid"]["max"][1]
    cells = spec["grid"]["cells"][1]
    j["name"] = "cam-clay-embankment-1d"
    j["dimension"] = 1
    j["grid"] = {"min": [0.0], "max": [top], "cells": [cells]}
    clay = j["materials"]["soft clay"]
    clay["preconsolidation_pressure"] = clay["preconsolidation_pressure"].replace("y", "x")
    j["bodies"][0]["box"] = {"min": [0.0], "max": [top]}
    j["gravity"] = [spec["gravity"][1]]
    j["boundaries"] = [{"nodes": {"box": {"min": [0.0], "max": [0.0]}}, "velocity": [0.0]},
                       {"nodes": {"box": {"min": [top], "max": [top]}}, "pore_pressure": 0.0}]
    t = spec["tractions"][0]
    j["tractions"] = [{"particles": {"box": {"min": [t["particles"]["box"]["min"][1]],
                                             "max": [top]}},
                       "face": "x+", "traction": [t["traction"][1]]}]
    h = top / cells
    j["output"] = {"series": {"particles": list(range(2 * cells)),
                              "fields": ["displacement", "effective_stress", "void_ratio"]}}
    return j, h


def elastic_twin(spec, depth):
    """The example with linear elasticity: E at the unload-reload stiffness at `depth`."""
    j = json.loads(json.dumps(spec))
    clay = j["materials"]["soft clay"]
    kappa, e0, nu = clay["kappa"], clay["initial_void_ratio"], clay["poisson_ratio"]
    k0 = spec["initial_state"]["geostatic"]["k0"]["soft clay"]
    p_mid = gamma_effective(spec) * depth * (1 + 2 * k0) / 3
    e = 3 * (1 - 2 * nu) * (1 + e0) * p_mid / kappa
    j["name"] = "cam-clay-embankment-elastic"
    j["materials"]["soft clay"] = {"model": "linear_elastic", "density": clay["density"],
                                   "poisson_ratio": nu, "youngs_modulus": e,
                                   "hydraulic": clay["hydraulic"]}
    del j["output"]["snapshots"]
    return j, e


def gamma_effective(spec):
    clay = spec["materials"]["soft clay"]
    n = clay["hydraulic"]["porosity"]
    rho_w = clay["hydraulic"]["fluid_density"]
    rho = (1 - n) * clay["density"] + n * rho_w
    return (rho - rho_w) * -spec["gravity"][-1]


def oedometer(clay, k0, sv0, pc0, target, step=2e-6):
    """Modified Cam-Clay along the oedometric path (lateral strain zero),
    strain-driven in small increments with the continuum elastoplastic
    tangent (K = (1 + e) p'/kappa, G from the constant nu, associated flow,
    dp'c = p'c (1 + e)/(lambda - kappa) d eps_v^p), from sigma'_v = sv0,
    sigma'_h = k0 sv0 to sigma'_v = target. Returns the final void ratio."""
    lam, kap, m2 = clay["lambda"], clay["kappa"], clay["critical_state_ratio"] ** 2
    nu, e = clay["poisson_ratio"], clay["initial_void_ratio"]
    sf = 3 * (1 - 2 * nu) / (2 * (1 + nu))
    sa, sr, pc = sv0, k0 * sv0, pc0
    while True:
        p, q = (sa + 2 * sr) / 3, sa - sr
        k = (1 + e) * p / kap
        g = sf * k
        dv, dq = step, 2 * step / 3
        pt, qt = p + k * dv, q + 3 * g * dq
        if qt * qt / m2 + pt * (pt - pc) <= 0:
            dp, dqq, dpc = k * dv, 3 * g * dq, 0.0
        else:
            npp, nq = 2 * p - pc, 2 * q / m2
            h = p * pc * (1 + e) / (lam - kap) * npp
            dl = (npp * k * dv + nq * 3 * g * dq) / (npp * k * npp + nq * 3 * g * nq + h)
            dvp, dqp = dl * npp, dl * nq
            dp, dqq = k * (dv - dvp), 3 * g * (dq - dqp)
            dpc = pc * (1 + e) / (lam - kap) * dvp
        dsa = dp + 2 * dqq / 3
        if sa + dsa >= target:  # the last part of the increment, linearly
            f = (target - sa) / dsa
            return e - (1 + e) * dv * f
        sa, sr = sa + dsa, sr + dp - dqq / 3
        pc += dpc
        e -= (1 + e) * dv


def mean_stress(s):
    return -(s[0] + s[1] + s[2]) / 3


def main():
    hmpm, example, results = sys.argv[1:4]
    figure = sys.argv[sys.argv.index("--figure") + 1] if "--figure" in sys.argv else None
    spec = read(example)
    clay = spec["materials"]["soft clay"]
    lam, kap, e0 = clay["lambda"], clay["kappa"], clay["initial_void_ratio"]
    k0 = spec["initial_state"]["geostatic"]["k0"]["soft clay"]
    top = spec["grid"]["max"][1]
    gam = gamma_effective(spec)
    traction = spec["tractions"][0]
    q = 30000.0
    assert "30000" in traction["traction"][1], "the check reads q = 30 kPa"
    b = traction["particles"]["box"]["max"][0]
    pc_of = lambda y: eval(clay["preconsolidation_pressure"], {"y": y, "x": y})  # noqa: E731
    failures = []
    series, summary = read(os.path.join(results, "series.json")), read(os.path.join(results, "summary.json"))
    if summary.get("status") != "successful":
        failures.append(f"status {summary.get('status')}: {summary.get('message')}")
    times = series["time"]
    parts = series["particles"]
    # Geostatic start and the end under the centre.
    for p in parts:
        y = p["initial_position"][1]
        sv0 = -p["effective_stress"][0][1]
        expect = gam * (top - y)
        err = abs(sv0 - expect) / (gam * top)
        excess = p["excess_pore_pressure"][-1]
        dsv = -p["effective_stress"][-1][1] - sv0
        u = -p["displacement"][-1][1]
        expect_dsv = q - GAMMA_W * u  # the water table stays while the particle settles
        print(f"y {y:5.3f}: sigma'_v0 {sv0:8.0f} Pa (gamma' z {expect:8.0f}, {100 * err:.2f} % of "
              f"the base's); at the end excess {excess:7.1f} Pa, d sigma'_v {dsv:7.0f} Pa "
              f"(q - gamma_w u = {expect_dsv:7.0f} Pa: {100 * (dsv - expect_dsv) / q:+.2f} % of q), "
              f"settlement {u:.4f} m")
        if err > 0.01:
            failures.append(f"geostatic sigma'_v at y = {y}: {sv0:.0f} vs {expect:.0f} Pa")
        if abs(excess) > 0.01 * q:
            failures.append(f"not drained at the end: excess {excess:.0f} Pa at y = {y}")
        # Between a half-space's strip influence at the centre, I = (alpha +
        # sin alpha)/pi with alpha = 2 atan(b/z) (the load spreads), and the
        # 1D limit (a rigid base stops the spreading): within 1 % of q of that
        # band from 2 m down, 3 % in the first 2 m below the loaded row (the
        # surface has settled half a cell below its drained node row: the
        # nodal pressure there is not the soil's, docs/verification.md).
        z = top - y
        alpha = 2 * math.atan(b / z)
        low = (alpha + math.sin(alpha)) / math.pi * q - GAMMA_W * u
        slack = (0.01 if z >= 2.0 else 0.03) * q
        if z >= 0.5 and not low - slack <= dsv <= expect_dsv + slack:
            failures.append(f"d sigma'_v {dsv:.0f} Pa at y = {y} is outside [{low:.0f}, "
                            f"{expect_dsv:.0f}] Pa by more than {slack:.0f} Pa")
        # The volume law, at every sample.
        s0 = p["effective_stress"][0]
        law0 = e0 + kap * math.log(mean_stress(s0)) + (lam - kap) * math.log(p["preconsolidation_pressure"][0])
        worst = max(abs(e + kap * math.log(mean_stress(s)) + (lam - kap) * math.log(pc) - law0)
                    for e, s, pc in zip(p["void_ratio"], p["effective_stress"], p["preconsolidation_pressure"]))
        if worst > 1e-9:
            failures.append(f"volume law broken by {worst:.3g} at y = {y}")
    centre = max(parts, key=lambda p: p["initial_position"][1])
    settlement = -centre["displacement"][-1][1]

    work = tempfile.mkdtemp(prefix="cam-clay-embankment-")
    # The 1D column against the oedometric integration.
    one, h = column_1d(spec)
    s1, sum1 = run(hmpm, one, os.path.join(work, "1d"))
    layers = sorted(s1["particles"], key=lambda p: p["initial_position"][0])
    # Each particle's compression from the integration, to the effective
    # stress its settlement leaves (sigma'_v0 + q - gamma_w u, the water
    # table staying at the original surface); a particle's displacement is
    # the compression of the layers below it and half its own.
    below, worst, surface = 0.0, 0.0, None
    for i, p in enumerate(layers):
        y = p["initial_position"][0]
        sv0 = -p["effective_stress"][0][0]  # the geostatic start hmpm set
        u = -p["displacement"][-1][0]
        e_end = oedometer(clay, k0, sv0, pc_of(y), sv0 + q - GAMMA_W * u)
        own = (h / 2) * (1 - (1 + e_end) / (1 + e0))
        reference = below + own / 2
        below += own
        if i < len(layers) - 2:  # below the top cell, whose face carries the load
            worst = max(worst, abs(u - reference))
        surface = (u, reference)
    settlement_1d, reference = surface
    print(f"1D column: settlement of the top particle {settlement_1d:.4f} m; oedometric "
          f"integration {reference:.4f} m ({100 * (settlement_1d / reference - 1):+.2f} %); below "
          f"the top cell every particle's settlement within {worst * 1e3:.2f} mm "
          f"({100 * worst / reference:.2f} % of the surface's); 2D centre {settlement:.4f} m "
          f"({100 * (settlement / settlement_1d - 1):+.1f} % of the 1D)")
    if worst > 0.02 * reference:
        failures.append(f"1D settlements below the top cell off by {worst:.4f} m (> 2 %)")
    if abs(settlement_1d / reference - 1) > 0.05:
        failures.append(f"1D settlement {settlement_1d:.4f} m vs the integration {reference:.4f} m")
    if abs(settlement / settlement_1d - 1) > 0.10:
        failures.append(f"2D centre {settlement:.4f} m is not within 10 % of the 1D {settlement_1d:.4f}")

    # Newton's last iterations.
    res = summary["iterations"]["worst_residuals"]
    rates = [res[i + 1] / res[i] ** 2 for i in range(len(res) - 1)]
    print(f"Newton: {summary['iterations']['nonlinear']} iterations in {summary['steps']} steps, "
          f"at most {summary['iterations']['max_nonlinear']}; worst step "
          + " ".join(f"{r:.1e}" for r in res) + "; r_k+1/r_k^2 " + " ".join(f"{c:.3g}" for c in rates))
    if len(rates) < 2 or max(rates[-2:]) > 1e3:
        failures.append("Newton's last iterations are not quadratic: " + ", ".join(f"{c:.3g}" for c in rates))

    # The yielded zone: p'c above its initial value, from the snapshots.
    with open(os.path.join(results, "snapshots.pvd")) as f:
        files = [part.split('"')[0] for part in f.read().split('file="')[1:]]
    first = rs.read_vtu(os.path.join(results, files[0]))
    last = rs.read_vtu(os.path.join(results, files[-1]))
    x0 = first["Points"]
    grown = [i for i, (a, z) in enumerate(zip(first["preconsolidation_pressure"],
                                             last["preconsolidation_pressure"])) if z > 1.01 * a]
    reach = max((x0[i][0] for i in grown), default=0.0)
    under = [i for i in grown if x0[i][0] < b and x0[i][1] > top - 0.5]
    print(f"yielded: {len(grown)} of {len(x0)} particles, out to x = {reach:.2f} m "
          f"(b + H = {b + top:.1f} m), {len(under)} in the top half metre under the load")
    if not under:
        failures.append("nothing yielded under the load at the surface")
    if reach > b + top:
        failures.append(f"yielding reaches x = {reach:.2f} m, beyond b + H = {b + top}")

    # The elastic twin.
    twin, young = elastic_twin(spec, top / 2)
    se, sume = run(hmpm, twin, os.path.join(work, "elastic"))
    centre_e = max(se["particles"], key=lambda p: p["initial_position"][1])
    settlement_e = -centre_e["displacement"][-1][1]
    print(f"linear elastic twin (E = {young / 1e6:.3f} MPa): settlement {settlement_e:.4f} m; "
          f"Cam-Clay {settlement:.4f} m = {settlement / settlement_e:.2f} x")
    if not settlement > settlement_e:
        failures.append(f"the Cam-Clay clay settles {settlement:.4f} m, not more than the "
                        f"elastic twin's {settlement_e:.4f} m")

    if figure:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig = plt.figure(figsize=(13, 8.2))
        grid = fig.add_gridspec(2, 2, height_ratios=[1.15, 1])
        a, c, d = fig.add_subplot(grid[0, 0]), fig.add_subplot(grid[0, 1]), fig.add_subplot(grid[1, :])
        ty = [t / YEAR for t in times]
        a.plot(ty, [-u[1] for u in centre["displacement"]], label="Modified Cam-Clay")
        a.plot([t / YEAR for t in se["time"]], [-u[1] for u in centre_e["displacement"]],
               label=f"linear elastic, E = {young / 1e6:.2f} MPa")
        a.axhline(reference, color="grey", ls=":", label="1D: oedometric integration of the model")
        a.set_xscale("log")
        a.set_xlabel("time (years)")
        a.set_ylabel("settlement under the centre (m)")
        a.legend(fontsize=8)
        a.grid(alpha=0.3)
        for p in sorted(parts, key=lambda p: -p["initial_position"][1]):
            c.plot(ty, [v / 1e3 for v in p["excess_pore_pressure"]],
                   label=f"depth {top - p['initial_position'][1]:.2f} m")
        c.set_xscale("log")
        c.set_xlabel("time (years)")
        c.set_ylabel("excess pore pressure under the centre (kPa)")
        c.legend(fontsize=8)
        c.grid(alpha=0.3)
        ratio = [math.log(z / a_) for a_, z in zip(first["preconsolidation_pressure"],
                                                  last["preconsolidation_pressure"])]
        top_ratio = max(abs(r) for r in ratio)
        sc = d.scatter([p[0] for p in x0], [p[1] for p in x0], c=ratio, s=9, marker="s",
                       cmap="RdBu_r", vmin=-top_ratio, vmax=top_ratio)
        d.plot([0, b], [top + 0.15, top + 0.15], color="k", lw=4, solid_capstyle="butt")
        d.text(b / 2, top + 0.3, f"embankment, q = {q / 1e3:.0f} kPa", ha="center", fontsize=9)
        d.set_aspect("equal")
        d.set_ylim(-0.2, top + 0.8)
        d.set_xlabel("x (m), initial position (x = 0: the embankment's axis)")
        d.set_ylabel("y (m)")
        d.set_title("after 10 years: ln(p'c / p'c0), red: hardened by plastic compression "
                    f"({len(grown)} particles yielded), blue: softened (dry side)", fontsize=10)
        fig.colorbar(sc, ax=d, shrink=0.8, pad=0.01)
        fig.tight_layout()
        fig.savefig(figure, dpi=110)
        print(f"figure: {figure}")
    for f in failures:
        print("FAIL:", f)
    print("OK" if not failures else f"{len(failures)} failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
