"""Worked example 3 (docs/worked-examples.md): examples/propped-excavation.json,
the prop force and the base heave, by statics and under refinement.

Usage: check_propped_excavation.py HMPM EXAMPLE WORK_DIR [--figure FILE.png]

The example (0.25 m cells) and the same job at 0.5 m and 0.125 m cells are
run (quasi-static, one step per stage, elastic). Checked:
- equilibrium of every stage's end (conservation of momentum at rest):
  the horizontal reactions of all boundaries (base, side rollers, prop)
  sum to 0 within 1e-6 of the largest, and the vertical ones to the weight
  of the soil and wall still in the run, sum of rho g A over the bodies,
  within 1e-6;
- the prop (boundaries[3], the wall's head held from stage 3 on) carries
  nothing before it is installed, and pushes the wall back (+x) after,
  with less than the at-rest thrust removed in front of the wall by the
  propped dig, K0 gamma (z2^2 - z1^2) / 2 from 2 to 4 m (the prop and the
  soil below the dig share that load);
- the prop force converges: the change from 0.25 m to 0.125 m cells is
  smaller than from 0.5 m to 0.25 m, and the example's is within 2 % of
  the finest;
- the heave of the pit's floor on the axis within 10 % of the 1D
  (oedometric) unloading of the clay below it, gamma d (H - d) / E_oed
  (an estimate, not a bound: the pit is 10 m wide over 6 m of clay on a
  rough base, and the removal of the at-rest K0 = 0.5 > nu / (1 - nu)
  horizontal stress in the pit adds some), at every resolution.
With --figure: the wall's horizontal displacement at each stage's end and
the prop force.
"""
import copy
import json
import os
import subprocess
import sys


def run(hmpm, spec, work, name):
    os.makedirs(work, exist_ok=True)
    path = os.path.join(work, name + ".json")
    with open(path, "w") as f:
        json.dump(spec, f)
    out = os.path.join(work, name)
    subprocess.run([hmpm, "run", path, "--out", out, "--threads", "2"], check=False,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    result = {}
    for name in ("summary", "reactions", "series", "profiles"):
        p = os.path.join(out, name + ".json")
        if os.path.exists(p):
            with open(p) as f:
                result[name] = json.load(f)
    return result


def area(box):
    return (box["max"][0] - box["min"][0]) * (box["max"][1] - box["min"][1])


def main():
    hmpm, example, work = sys.argv[1:4]
    figure = sys.argv[sys.argv.index("--figure") + 1] if "--figure" in sys.argv else None
    with open(example) as f:
        spec = json.load(f)
    g = -spec["gravity"][1]
    clay = spec["materials"]["clay"]
    E, nu = clay["youngs_modulus"], clay["poisson_ratio"]
    e_oed = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu))
    gamma = clay["density"] * g
    k0 = spec["initial_state"]["geostatic"]["k0"]
    H = spec["grid"]["max"][1]
    # bodies in the run at each stage's end: all, then less each stage's removals
    removed, in_run = set(), []
    for stage in [{}] + spec["stages"]:
        removed |= set(stage.get("remove_bodies", []))
        in_run.append([b for i, b in enumerate(spec["bodies"]) if i not in removed])
    weights = [sum(spec["materials"][b["material"]]["density"] * g * area(b["box"]) for b in bodies)
               for bodies in in_run]
    floor = min(b["box"]["min"][1] for i, b in enumerate(spec["bodies"]) if i in removed)
    depth = H - floor
    heave_1d = gamma * depth * floor / e_oed
    z1, z2 = H - spec["bodies"][0]["box"]["min"][1], depth
    thrust = k0 * gamma * (z2 ** 2 - z1 ** 2) / 2
    problems, props, results = [], {}, {}
    cells = spec["grid"]["cells"]
    for factor in (0.5, 1, 2):
        s = copy.deepcopy(spec)
        s["grid"]["cells"] = [int(cells[0] * factor), int(cells[1] * factor)]
        s["output"].pop("snapshots", None)
        h = H / s["grid"]["cells"][1]
        s["output"]["series"]["particles"][0] = {"near": [h / 4, floor - h / 4]}
        r = run(hmpm, s, work, f"propped-{s['grid']['cells'][0]}")
        label = f"{h:g} m cells"
        if r.get("summary", {}).get("status") != "successful":
            problems.append(f"{label}: {r.get('summary', {}).get('message', 'no summary')}")
            continue
        results[factor] = r
        forces = r["reactions"]["boundaries"]
        for k, t in enumerate(r["reactions"]["time"]):
            fx = [b["force"][k][0] for b in forces]
            fy = [b["force"][k][1] for b in forces]
            if abs(sum(fx)) > 1e-6 * max(abs(v) for v in fx):
                problems.append(f"{label}, t = {t}: horizontal reactions sum to {sum(fx):.4g} N/m")
            if abs(sum(fy) / weights[k] - 1) > 1e-6:
                problems.append(f"{label}, t = {t}: vertical reactions {sum(fy):.7g} N/m, weight {weights[k]:.7g}")
        prop = [f[0] for f in forces[3]["force"]]
        props[factor] = prop[-1]
        if any(abs(v) > 1e-9 for v in prop[:-1]):
            problems.append(f"{label}: the prop carries {prop[:-1]} before it is installed")
        if not 0 < prop[-1] < thrust:
            problems.append(f"{label}: prop force {prop[-1]:.4g} N/m outside (0, {thrust:.4g})")
        heave = r["series"]["particles"][0]["displacement"][-1][1]
        print(f"{label}: prop force {prop[-1] / 1000:.3f} kN/m (at-rest thrust removed {thrust / 1000:.1f}), "
              f"heave {heave * 1000:.2f} mm, 1D {heave_1d * 1000:.2f} mm (ratio {heave / heave_1d:.3f}), "
              f"reactions balance the weight {weights[-1] / 1000:.1f} kN/m")
        if not abs(heave / heave_1d - 1) <= 0.1:
            problems.append(f"{label}: heave {heave:.4g} m is not within 10 % of the 1D {heave_1d:.4g} m")
    if len(props) == 3:
        if not abs(props[2] - props[1]) < abs(props[1] - props[0.5]):
            problems.append(f"the prop force does not converge: {props}")
        if not abs(props[1] / props[2] - 1) <= 0.02:
            problems.append(f"the prop force {props[1]:.4g} is not within 2 % of the finest {props[2]:.4g}")
    if figure and 1 in results:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        pr = results[1]["profiles"]
        line = pr["profiles"][0]
        ys = [p[1] for p in line["initial_positions"]]
        fig, (ax, bx) = plt.subplots(1, 2, figsize=(8, 4.5), constrained_layout=True,
                                     gridspec_kw={"width_ratios": [2, 1]})
        names = ["at rest"] + [s.get("name", "") for s in spec["stages"]]
        for k, t in enumerate(pr["time"][1:], start=1):
            ux = [d[0] * 1000 for d in line["displacement"][k]]
            ax.plot(ux, [H - y for y in ys], "o-", ms=3, label=f"after '{names[k - 1] if k - 1 < len(names) else t}'")
        ax.invert_yaxis()
        ax.axhline(depth, color="0.5", ls=":", lw=1)
        ax.set_xlabel("wall's horizontal displacement, mm (negative: into the pit)")
        ax.set_ylabel("depth below the ground surface, m")
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3)
        prop = [f[0] / 1000 for f in results[1]["reactions"]["boundaries"][3]["force"]]
        bx.bar(range(len(prop)), prop, color="C3")
        bx.set_xticks(range(len(prop)), names[:len(prop)], rotation=20, fontsize=8)
        bx.set_ylabel("prop force, kN/m")
        fig.suptitle("Propped excavation: wall displacement and prop force (elastic clay)", fontsize=10)
        fig.savefig(figure, dpi=110)
    for p in problems:
        print("FAIL:", p)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
