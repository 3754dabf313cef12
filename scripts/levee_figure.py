"""Draws docs/figures/levee.png from a run of examples/levee.json:
    build/bin/hmpm run examples/levee.json --out /tmp/levee
    /usr/bin/python3 scripts/levee_figure.py /tmp/levee docs/figures/levee.png
Top: the particles at the end coloured by the hydraulic head p/gamma_w + y,
with the Darcy velocity as arrows. Bottom: the aquifer's head along the
levee (profile 0) against Bennett's blanket theory (tests/api/check_levee.py).
Needs Debian's python3-matplotlib and python3-meshio (the system interpreter).
"""
import json
import os
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import meshio  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "tests", "api"))
from check_levee import blanket_theory  # noqa: E402

GAMMA_W = 9810.0


def main():
    out, png = sys.argv[1:3]
    spec = json.load(open(os.path.join(os.path.dirname(__file__), "..", "examples", "levee.json")))
    pvd = open(os.path.join(out, "snapshots.pvd")).read()
    last = pvd.split('file="')[-1].split('"')[0]  # the collection's last snapshot
    mesh = meshio.read(os.path.join(out, last))
    x = mesh.points
    head = mesh.point_data["pore_pressure"] / GAMMA_W + x[:, 1]
    w = mesh.point_data["darcy_velocity"]
    fig, (ax, bx) = plt.subplots(2, 1, figsize=(10, 7.5), gridspec_kw={"height_ratios": [1.1, 1]})
    sc = ax.scatter(x[:, 0], x[:, 1], c=head, s=4, cmap="viridis", vmin=6.0, vmax=8.5)
    fig.colorbar(sc, ax=ax, label="hydraulic head p/γw + y [m]")
    ix = np.rint((x[:, 0] - 0.125) / 0.25).astype(int)  # the particles' lattice (0.25 m)
    iy = np.rint((x[:, 1] - 0.125) / 0.25).astype(int)
    pick = (ix % 8 == 4) & (iy % 4 == 1)
    speed = np.hypot(w[:, 0], w[:, 1])
    scale = np.where(speed > 0, speed, 1) ** 0.5 / np.where(speed > 0, speed, 1)  # show sqrt(speed)
    ax.quiver(x[pick, 0], x[pick, 1], (w[:, 0] * scale)[pick], (w[:, 1] * scale)[pick],
              color="black", width=0.002, scale=0.03, alpha=0.9)
    ax.axhline(8.5, xmax=17 / 40, color="tab:blue", lw=2)
    ax.text(1, 8.7, "river at 8.5 m", color="tab:blue")
    ax.text(31, 6.4, "seepage face (landside)", fontsize="small")
    ax.set_aspect("equal")
    ax.set_xlim(0, 40)
    ax.set_ylim(0, 10)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title("levee example at the end: head and flow (arrows ∝ √|w|)")
    profiles = json.load(open(os.path.join(out, "profiles.json")))
    line = profiles["profiles"][0]
    xs = [p[0] for p in line["initial_positions"]]
    heads = [p / GAMMA_W + q[1] for p, q in zip(line["pore_pressure"][-1], line["initial_positions"])]
    mats = spec["materials"]
    theory = blanket_theory(8.5, 40.0, 12.0, 28.0, mats["aquifer sand"]["hydraulic"]["hydraulic_conductivity"],
                            4.0, mats["blanket clay"]["hydraulic"]["hydraulic_conductivity"], 2.0, 6.0)
    fine = np.linspace(0, 40, 401)
    bx.plot(fine, [theory(v) for v in fine], "k-", lw=1.5, label="Bennett's blanket theory (1D)")
    bx.plot(xs, heads, "o", ms=3, color="tab:orange", label="hmpm, aquifer at y = 1.875 m")
    bx.axvspan(12, 28, color="0.9", label="under the levee")
    bx.axhline(6.0, color="0.5", ls=":", lw=1)
    bx.set_xlim(0, 40)
    bx.set_xlabel("x [m]")
    bx.set_ylabel("aquifer head [m]")
    bx.legend(fontsize="small")
    bx.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    print(png, "from", last, "of", pvd.count("<DataSet"))


if __name__ == "__main__":
    main()
