"""docs/figures/random-field.png: the lognormal random fields of the two
issue-43 examples, read back from their snapshots (the `cohesion` field
of snapshot_0000.vtu, each particle's own c_u), with the field's
histogram of ln c_u and its correlation along x against the target's.

    /usr/bin/python3 scripts/random_field_figure.py [--hmpm build/bin/hmpm] [--out docs/figures]

Runs examples/random-bearing.json and examples/random-slope.json (2 s)
in a temporary directory. Prints the fields' statistics against the
target distribution (one field: sampling error, not a check).
"""
import argparse
import json
import math
import os
import statistics
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO / "tests" / "api"))
import random_support as rs  # noqa: E402


def field(hmpm, name, work):
    with open(REPO / "examples" / f"{name}.json") as f:
        spec = json.load(f)
    out, _ = rs.run(hmpm, work, name, spec, threads=2)
    snap = rs.read_vtu(rs.snapshots(out)[0][1])
    return spec, [p[0] for p in snap["Points"]], [p[1] for p in snap["Points"]], snap["cohesion"]


def correlation_along_x(xs, ys, c, lags):
    """The correlation of ln c between particles of one row at each lag (m)."""
    rows = {}
    for x, y, v in zip(xs, ys, c):
        rows.setdefault(round(y, 6), {})[round(x, 6)] = math.log(v)
    values = [v for r in rows.values() for v in r.values()]
    m, var = statistics.fmean(values), statistics.pvariance(values)
    out = []
    for lag in lags:
        prods = [(r[x] - m) * (r[round(x + lag, 6)] - m) for r in rows.values() for x in r if round(x + lag, 6) in r]
        out.append(statistics.fmean(prods) / var if prods else float("nan"))
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--hmpm", default=str(REPO / "build" / "bin" / "hmpm"))
    ap.add_argument("--out", default=str(REPO / "docs" / "figures"))
    args = ap.parse_args()
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.colors as colors
    import matplotlib.pyplot as plt

    with tempfile.TemporaryDirectory() as work:
        bearing = field(args.hmpm, "random-bearing", work)
        slope = field(args.hmpm, "random-slope", work)
    fig = plt.figure(figsize=(12, 7.6))
    grid = fig.add_gridspec(2, 6, height_ratios=[1, 1])
    panels = [(fig.add_subplot(grid[0, 0:3]), bearing, "random-bearing.json: c_u under the footing"),
              (fig.add_subplot(grid[0, 3:6]), slope, "random-slope.json: c_u of the slope")]
    for ax, (spec, xs, ys, c), title in panels:
        rf = spec["materials"]["clay"]["cohesion"]["random_field"]
        d = rf["distribution"]["lognormal"]
        h = (spec["grid"]["max"][0] - spec["grid"]["min"][0]) / spec["grid"]["cells"][0]
        sc = ax.scatter(xs, ys, c=[v / 1e3 for v in c], s=(72 * h / 2) ** 2 * 0.9, marker="s",
                        cmap="viridis", norm=colors.LogNorm(), linewidths=0)
        fig.colorbar(sc, ax=ax, label="c_u (kPa)", shrink=0.85)
        ax.set_aspect("equal")
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
        ax.set_title(f"{title}\nlognormal, mean {d['mean'] / 1e3:g} kPa, COV {d['cov']}, "
                     f"θ = {rf['correlation_length'][0]:g} m, seed {rf['seed']}", fontsize=9)
        ln = [math.log(v) for v in c]
        sigma = math.sqrt(math.log(1 + d["cov"] ** 2))
        print(f"{spec['name']}: {len(c)} particles, mean {statistics.fmean(c):.0f} Pa (target {d['mean']:.0f}), "
              f"COV {statistics.pstdev(c) / statistics.fmean(c):.3f} (target {d['cov']}), std of ln c "
              f"{statistics.pstdev(ln):.3f} (target {sigma:.3f})")
    spec, xs, ys, c = bearing
    rf = spec["materials"]["clay"]["cohesion"]["random_field"]
    d = rf["distribution"]["lognormal"]
    sigma = math.sqrt(math.log(1 + d["cov"] ** 2))
    mu = math.log(d["mean"]) - sigma * sigma / 2
    ax = fig.add_subplot(grid[1, 0:3])
    ln = [math.log(v) for v in c]
    ax.hist(ln, bins=30, density=True, color="tab:blue", alpha=0.6, label=f"ln c_u of the {len(c)} particles")
    zs = [mu + sigma * (-4 + 8 * i / 200) for i in range(201)]
    ax.plot(zs, [math.exp(-0.5 * ((z - mu) / sigma) ** 2) / (sigma * math.sqrt(2 * math.pi)) for z in zs], "k",
            label=f"target normal: μ_ln = {mu:.3f}, σ_ln = {sigma:.3f}")
    ax.set_xlabel("ln c_u (c_u in Pa)")
    ax.set_ylabel("density")
    ax.legend(fontsize=8)
    ax.set_title("random-bearing: one field's histogram (correlated values: wider sampling error)", fontsize=9)
    ax = fig.add_subplot(grid[1, 3:6])
    theta = rf["correlation_length"][0]
    h = 0.5 * (spec["grid"]["max"][0] - spec["grid"]["min"][0]) / spec["grid"]["cells"][0]  # particle spacing
    lags = [h * k for k in range(0, 31)]
    ax.plot(lags, correlation_along_x(xs, ys, c, lags), "o", ms=4, label="this field, ln c_u along x")
    ax.plot(lags, [math.exp(-2 * lag / theta) for lag in lags], "k", label=f"target exp(−2|Δx|/θ), θ = {theta:g} m")
    ax.axhline(0, color="grey", lw=0.5)
    ax.set_xlabel("lag Δx (m)")
    ax.set_ylabel("correlation")
    ax.legend(fontsize=8)
    ax.set_title("random-bearing: correlation of ln c_u (one field on a 6 m domain: noisy)", fontsize=9)
    fig.tight_layout()
    path = os.path.join(args.out, "random-field.png")
    fig.savefig(path, dpi=100)
    print("wrote", path)


if __name__ == "__main__":
    main()
