"""Physics check of examples/site-response.json: a soil layer on rock shaken
at its compliant base by an outcrop accelerogram (issue 18). Reads the run's
series.json back.

Usage: check_site_response.py EXAMPLE.json RESULT_DIR [FIGURE.png]
RESULT_DIR is what `hmpm run EXAMPLE.json --out RESULT_DIR` wrote (the CTest
entry api_example_site-response). Layer, rock and record come from the spec.

Reference: an elastic layer of height H (shear wave speed Vs) on an elastic
half-space (rock), driven by the rock outcrop's motion, moves at depth d
with the transfer function
    |U(d, f) / U_outcrop(f)| = |cos(k d)| / |cos(k H) + i alpha sin(k H)|,
k = 2 pi f / Vs, alpha = rho Vs / (rho_r Vs_r) (Kramer, Geotechnical
Earthquake Engineering, §7.2). The outcrop velocity is the record's
integral (trapezoids on its 0.01 s rows, as the solver integrates a table
exactly). Both histories are zero before the record starts and the run
goes on 4 s after it ends, long enough for the layer to ring down through
the base (the transients fall by (1 - alpha)/(1 + alpha) = 0.73 per
round trip of 4H/Vs/2 = 0.27 s: 1e-7 in 4 s), so their Fourier transforms
over the run are the transforms of the whole motions and their ratio is
the transfer function wherever the record has energy.

Checked (assertions):
- the first resonance: the frequency of the largest spectral ratio of the
  surface particle within 2 % of the closed form's peak (Vs / (4H) with the
  particle a quarter cell below the top: the same);
- its height within 5 % of the closed form's 1/alpha x cos(k d);
- over 0.5-8 Hz, where the record carries at least 5 % of its peak
  spectral amplitude, the ratio within 10 % of the closed form at every
  frequency, except within 0.15 Hz of the anti-resonances (where the closed
  form vanishes and a relative error is meaningless), at the surface and
  at mid-depth; below 1.5 Hz for the particle a quarter cell above the
  base. Measured: 4.4 % at the surface, 5.5 % at mid-depth, the resonance
  at the closed form's frequency (1.843 Hz on the transform's 0.071 Hz
  spacing) with amplification 6.353 against 6.307 (0.7 %).
With FIGURE.png it also draws the spectral ratios against the closed form
(docs/figures/site-response.png).
"""
import math
import sys

import numpy as np

import example_results


def main():
    spec, _, read = example_results.load()
    figure = sys.argv[3] if len(sys.argv) > 3 else None
    soil, rock = spec["materials"]["soil"], spec["materials"]["rock"]

    def shear_speed(m):
        g = m["youngs_modulus"] / (2 * (1 + m["poisson_ratio"]))
        return math.sqrt(g / m["density"])

    vs, vs_r = shear_speed(soil), shear_speed(rock)
    alpha = soil["density"] * vs / (rock["density"] * vs_r)
    height = spec["grid"]["max"][1] - spec["grid"]["min"][1]
    table = np.array(spec["boundaries"][1]["acceleration"][0]["table"])

    series = read("series.json")
    t = np.array(series["time"])
    dt = t[1] - t[0]
    # Outcrop velocity at the series times: the table's exact integral.
    acc = np.interp(t, table[:, 0], table[:, 1], left=table[0, 1], right=table[-1, 1])
    v_out = np.concatenate([[0.0], np.cumsum(0.5 * (acc[1:] + acc[:-1]) * dt)])
    spectrum_out = np.fft.rfft(v_out)
    f = np.fft.rfftfreq(len(t), dt)

    failures = []
    curves = []
    for p in series["particles"]:
        depth = height - p["initial_position"][1]
        v = np.array([row[0] for row in p["velocity"]])
        ratio = np.abs(np.fft.rfft(v)) / np.maximum(np.abs(spectrum_out), 1e-300)
        k = 2 * math.pi * f / vs
        exact = np.abs(np.cos(k * depth)) / np.abs(np.cos(k * height) + 1j * alpha * np.sin(k * height))
        curves.append((depth, ratio, exact))
        strong = (np.abs(spectrum_out) >= 0.05 * np.abs(spectrum_out).max()) & (f >= 0.5) & (f <= 8)
        # Anti-resonances of this depth: cos(k d) = 0.
        near_zero = np.zeros_like(f, dtype=bool)
        if depth > 0:
            for m in range(0, 20):
                f0 = (m + 0.5) * vs / (2 * depth)
                near_zero |= np.abs(f - f0) < 0.15
        use = strong & ~near_zero
        if depth > 0.75 * height:
            # Next to the base the particle follows the base's own motion;
            # its ratio dips sharply near 1.9 Hz (cos(k d) = 0 a quarter
            # cell above the base, beside the first resonance), where a
            # relative error says nothing. Checked below 1.5 Hz only.
            use &= f < 1.5
        err = np.abs(ratio[use] / exact[use] - 1)
        worst = err.max() if err.size else float("nan")
        print(f"depth {depth:.3f} m: spectral ratio against the closed form over {use.sum()} "
              f"frequencies in 0.5-8 Hz: worst {100 * worst:.2f} %")
        if not worst < 0.10:
            i = np.argmax(err)
            failures.append(f"depth {depth:.3f} m: ratio {ratio[use][i]:.3f} against "
                            f"{exact[use][i]:.3f} at {f[use][i]:.3f} Hz")
        if depth < 0.05 * height:  # the surface particle: the resonance
            band = (f > 0.5) & (f < 1.5 * vs / (4 * height))
            i, j = np.argmax(np.where(band, ratio, 0)), np.argmax(np.where(band, exact, 0))
            print(f"  first resonance: {f[i]:.4f} Hz (closed form {f[j]:.4f}, Vs/4H "
                  f"{vs / (4 * height):.4f}), amplification {ratio[i]:.3f} (closed form "
                  f"{exact[j]:.3f}, 1/alpha {1 / alpha:.3f})")
            if abs(f[i] / f[j] - 1) > 0.02:
                failures.append(f"resonance at {f[i]:.4f} Hz, closed form {f[j]:.4f} Hz")
            if abs(ratio[i] / exact[j] - 1) > 0.05:
                failures.append(f"amplification {ratio[i]:.3f}, closed form {exact[j]:.3f}")

    if figure:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, (ax0, ax1) = plt.subplots(1, 2, figsize=(11, 4.2))
        ax0.plot(t, v_out, "k", lw=1, label="rock outcrop (input)")
        surface = series["particles"][0]
        ax0.plot(t, [row[0] for row in surface["velocity"]], "C0", lw=1, label="surface")
        ax0.set_xlabel("time (s)")
        ax0.set_ylabel("horizontal velocity (m/s)")
        ax0.legend(loc="upper right")
        ax0.set_title("Velocity histories")
        sel = (f > 0.2) & (f < 8)
        for n, (depth, ratio, exact) in enumerate(curves):
            ax1.plot(f[sel], ratio[sel], f"C{n}", lw=1.2, label=f"hmpm, depth {depth:.1f} m")
            ax1.plot(f[sel], exact[sel], f"C{n}--", lw=1, label="closed form" if n == 0 else None)
        ax1.set_xlabel("frequency (Hz)")
        ax1.set_ylabel("|U / U outcrop|")
        ax1.set_yscale("log")
        ax1.set_ylim(0.05, 20)
        ax1.legend(loc="upper right", fontsize=8)
        ax1.set_title("Transfer function: layer on rock")
        fig.tight_layout()
        fig.savefig(figure, dpi=90)
        print(f"figure: {figure}")

    for failure in failures:
        print("FAIL:", failure)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
