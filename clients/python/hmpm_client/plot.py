"""Plots of a job's series particles (time histories) and profiles (a field
along a line, a curve per time); matplotlib, Agg backend.

matplotlib is optional: the client itself uses the standard library only, and
`plot_series` raises `MatplotlibMissing` (with the Debian package to install)
when it cannot be imported. Scalars (pore_pressure, porosity) give one axes
with a line per particle; vectors and Voigt tensors give one axes per
component that is not zero throughout.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any, Dict, List, Optional, Sequence

UNITS = {
    "position": "m", "displacement": "m", "velocity": "m/s", "darcy_velocity": "m/s",
    "pore_pressure": "Pa", "effective_stress": "Pa", "stress": "Pa", "total_stress": "Pa",
    "strain": "-", "porosity": "-", "plastic_strain": "-",
}
VECTOR_NAMES = ("x", "y", "z")
VOIGT_NAMES = ("xx", "yy", "zz", "xy", "yz", "zx")


class MatplotlibMissing(RuntimeError):
    pass


def _import_pyplot():
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as e:
        raise MatplotlibMissing(
            f"plotting needs matplotlib, which {sys.executable} cannot import ({e}). "
            "On Debian: sudo apt-get install python3-matplotlib, then run the client with /usr/bin/python3"
        ) from None
    return plt


def _save(plt, fig, out: Path) -> Path:
    fig.tight_layout()
    out = Path(out)
    if out.parent and not out.parent.exists():
        out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return out


def component_names(n: int) -> Sequence[str]:
    if n == 6:
        return VOIGT_NAMES
    if n <= 3:
        return VECTOR_NAMES[:n]
    return [str(i) for i in range(n)]


def _label(particle: Dict[str, Any]) -> str:
    idx = particle.get("index", "?")
    pos = particle.get("initial_position")
    if isinstance(pos, list) and pos:
        return f"particle {idx} at ({', '.join(f'{c:.3g}' for c in pos)})"
    return f"particle {idx}"


def available_fields(series: Dict[str, Any]) -> List[str]:
    parts = series.get("particles") or []
    if not parts:
        return []
    return sorted(k for k, v in parts[0].items() if isinstance(v, list) and k != "initial_position")


def plot_series(series: Dict[str, Any], field: str, out: Path, title: Optional[str] = None) -> Path:
    """Writes a PNG of `field` against time for every series particle.

    Raises MatplotlibMissing without matplotlib, and ValueError when the
    series has no particles or no such field.
    """
    times = series.get("time") or []
    particles = series.get("particles") or []
    if not particles:
        raise ValueError("series.json lists no particles (does the spec set output.series?)")
    if not all(field in p for p in particles):
        raise ValueError(f"series.json has no field {field!r}; it has: {', '.join(available_fields(series)) or 'none'}")
    plt = _import_pyplot()

    first = particles[0][field]
    ncomp = len(first[0]) if first and isinstance(first[0], list) else 0
    names = list(component_names(ncomp)) if ncomp else [""]
    columns = list(range(len(names)))
    if ncomp > 1:
        # Leave out components that are zero throughout (e.g. the shear
        # stresses of a 1D column); keep at least one.
        nonzero = [c for c in columns if any(v[c] != 0 for p in particles for v in p[field])]
        columns = nonzero or columns[:1]
    fig, axes = plt.subplots(len(columns), 1, sharex=True, squeeze=False,
                             figsize=(7.5, 2.2 + 2.0 * len(columns)))
    unit = UNITS.get(field, "")
    for row, col in enumerate(columns):
        comp = names[col]
        ax = axes[row][0]
        for p in particles:
            values = p[field]
            ys = [v[col] if isinstance(v, list) else v for v in values] if ncomp else values
            n = min(len(times), len(ys))
            ax.plot(times[:n], ys[:n], label=_label(p))
        ylabel = field + (f" {comp}" if comp else "") + (f" [{unit}]" if unit else "")
        ax.set_ylabel(ylabel)
        ax.grid(True, alpha=0.3)
    axes[-1][0].set_xlabel("time [s]")
    axes[0][0].legend(fontsize="small", loc="best")
    fig.suptitle(title or field)
    return _save(plt, fig, out)


def plot_profile(profiles: Dict[str, Any], field: str, out: Path, line: int = 0,
                 title: Optional[str] = None) -> Path:
    """Writes a PNG of `field` along profile `line` of profiles.json: the
    field against the distance from the line's start, one curve per
    profile time (isochrones). Vectors and tensors: one axes per component
    that is not zero throughout.

    Raises MatplotlibMissing without matplotlib, and ValueError when there
    is no such line or field.
    """
    lines = profiles.get("profiles") or []
    if not 0 <= line < len(lines):
        raise ValueError(f"profiles.json has {len(lines)} line(s); there is no line {line}")
    prof = lines[line]
    fields = sorted(k for k, v in prof.items()
                    if isinstance(v, list) and k not in ("from", "to", "points", "distance",
                                                         "particles", "initial_positions"))
    if field not in prof or field not in fields:
        raise ValueError(f"profile {line} has no field {field!r}; it has: {', '.join(fields) or 'none'}")
    plt = _import_pyplot()
    times = profiles.get("time") or []
    distance = prof.get("distance") or []
    rows = prof[field]
    first = rows[0][0] if rows and rows[0] else 0
    ncomp = len(first) if isinstance(first, list) else 0
    names = list(component_names(ncomp)) if ncomp else [""]
    columns = list(range(len(names)))
    if ncomp > 1:
        nonzero = [c for c in columns if any(v[c] != 0 for row in rows for v in row)]
        columns = nonzero or columns[:1]
    fig, axes = plt.subplots(1, len(columns), sharey=True, squeeze=False,
                             figsize=(3.2 + 3.0 * len(columns), 5.0))
    unit = UNITS.get(field, "")
    cmap = plt.get_cmap("viridis")
    for k, col in enumerate(columns):
        comp = names[col]
        ax = axes[0][k]
        for r, row in enumerate(rows):
            xs = [v[col] if isinstance(v, list) else v for v in row]
            t = times[r] if r < len(times) else float("nan")
            ax.plot(xs, distance[:len(xs)], marker=".", markersize=3,
                    color=cmap(r / max(1, len(rows) - 1)), label=f"t = {t:.4g} s")
        ax.set_xlabel(field + (f" {comp}" if comp else "") + (f" [{unit}]" if unit else ""))
        ax.grid(True, alpha=0.3)
    frm = ", ".join(f"{c:.3g}" for c in prof.get("from", []))
    to = ", ".join(f"{c:.3g}" for c in prof.get("to", []))
    axes[0][0].set_ylabel(f"distance from ({frm}) towards ({to}) [m]")
    axes[0][-1].legend(fontsize="x-small", loc="best")
    fig.suptitle(title or f"{field} along profile {line}")
    return _save(plt, fig, out)


def plot_consolidation(doc: Dict[str, Any], out: Path, title: Optional[str] = None) -> Path:
    """Writes a PNG of consolidation.json: the average degree of
    consolidation U against time (log scale, U growing downwards as in a
    settlement curve), with t50 and t90 marked, and the average excess pore
    pressure beside it.

    Raises MatplotlibMissing without matplotlib, and ValueError when U is
    undefined in every sample (no excess at `from`).
    """
    times = doc.get("time") or []
    degree = doc.get("degree") or []
    pairs = [(t, u) for t, u in zip(times, degree) if u is not None and t > 0]
    if not pairs:
        raise ValueError("consolidation.json has no degree of consolidation (null in every "
                         "sample: the excess at 'from' was zero; see the run's warnings)")
    plt = _import_pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(10.5, 4.2), squeeze=False)
    ax = axes[0][0]
    ax.plot([t for t, _ in pairs], [100 * u for _, u in pairs], marker=".", markersize=3)
    ax.set_xscale("log")
    ax.set_ylim(105, -5)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("average degree of consolidation U [%]")
    for key, level in (("t50", 50), ("t90", 90)):
        t = doc.get(key)
        if t:
            ax.axhline(level, color="grey", lw=0.6, ls=":")
            ax.axvline(t, color="grey", lw=0.6, ls=":")
            ax.annotate(f"{key} = {t:.4g} s", (t, level), textcoords="offset points",
                        xytext=(4, -10), fontsize="small")
    ax.grid(True, which="both", alpha=0.3)
    ax2 = axes[0][1]
    excess = doc.get("average_excess_pore_pressure") or []
    ex = [(t, e) for t, e in zip(times, excess) if e is not None and t > 0]
    ax2.plot([t for t, _ in ex], [e / 1000 for _, e in ex], marker=".", markersize=3, color="C1")
    ax2.set_xscale("log")
    ax2.set_xlabel("time [s]")
    ax2.set_ylabel("average excess pore pressure [kPa]")
    ax2.grid(True, which="both", alpha=0.3)
    fig.suptitle(title or "degree of consolidation")
    return _save(plt, fig, out)

