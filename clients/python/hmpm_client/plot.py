"""Plots of a job's series particles (time histories) and profiles (a field
along a line, a curve per time); matplotlib, Agg backend.

matplotlib is optional: the client itself uses the standard library only, and
`plot_series` raises `MatplotlibMissing` (with the Debian package to install)
when it cannot be imported. Scalars (pore_pressure, porosity) give one axes
with a line per particle; vectors and Voigt tensors give one axes per
component that is not zero throughout.

Units: `units` is {field: unit} from the server's `GET /fields` (the solver's
table; `Client.field_units()`); a field it does not name gets no unit on its
axis. Times are shown in the unit that reads best (s, min, h, days, years:
units.time_unit), named on the axis. A profile along a mostly vertical line
is drawn against depth (increasing downward, from the line's top); along a
mostly horizontal line, against the distance from its start.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any, Dict, List, Optional, Sequence

from .units import format_time, scaled_times, time_unit

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


def _axis_label(field: str, comp: str, units: Optional[Dict[str, str]]) -> str:
    unit = (units or {}).get(field, "")
    return field + (f" {comp}" if comp else "") + (f" [{unit}]" if unit else "")


def plot_series(series: Dict[str, Any], field: str, out: Path, title: Optional[str] = None,
                units: Optional[Dict[str, str]] = None) -> Path:
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
    times, time_name = scaled_times(times)
    for row, col in enumerate(columns):
        comp = names[col]
        ax = axes[row][0]
        for p in particles:
            values = p[field]
            ys = [v[col] if isinstance(v, list) else v for v in values] if ncomp else values
            n = min(len(times), len(ys))
            ax.plot(times[:n], ys[:n], label=_label(p))
        ax.set_ylabel(_axis_label(field, comp, units))
        ax.grid(True, alpha=0.3)
    axes[-1][0].set_xlabel(f"time [{time_name}]")
    axes[0][0].legend(fontsize="small", loc="best")
    fig.suptitle(title or field)
    return _save(plt, fig, out)


def profile_axis(prof: Dict[str, Any]) -> tuple:
    """How a profile line is drawn: ("depth", values, label) for a mostly
    vertical line (the last coordinate is vertical: x in 1D, y in 2D, z in
    3D), the depth of each point below the line's top; else ("distance",
    values, label), the distance of each point from the line's start."""
    frm, to = prof.get("from") or [], prof.get("to") or []
    points = prof.get("points") or []
    distance = prof.get("distance") or []
    dim = len(frm)
    if dim and len(to) == dim and points:
        rise = abs(to[-1] - frm[-1])
        run = sum((to[a] - frm[a]) ** 2 for a in range(dim - 1)) ** 0.5
        if rise > run:
            top = max(frm[-1], to[-1])
            axis = "xyz"[dim - 1] if dim > 1 else "x"
            return ("depth", [top - p[-1] for p in points],
                    f"depth below {axis} = {top:.4g} m [m]")
    f = ", ".join(f"{c:.3g}" for c in frm)
    t = ", ".join(f"{c:.3g}" for c in to)
    return "distance", list(distance), f"distance from ({f}) towards ({t}) [m]"


def plot_profile(profiles: Dict[str, Any], field: str, out: Path, line: int = 0,
                 title: Optional[str] = None, units: Optional[Dict[str, str]] = None) -> Path:
    """Writes a PNG of `field` along profile `line` of profiles.json, one
    curve per profile time (isochrones, labelled in the unit that reads
    best). A mostly vertical line: the field across, depth down (0 at the
    line's top, increasing downward); otherwise the field up, the distance
    from the line's start across. Vectors and tensors: one axes per
    component that is not zero throughout.

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
    kind, where, where_label = profile_axis(prof)
    vertical = kind == "depth"
    rows = prof[field]
    first = rows[0][0] if rows and rows[0] else 0
    ncomp = len(first) if isinstance(first, list) else 0
    names = list(component_names(ncomp)) if ncomp else [""]
    columns = list(range(len(names)))
    if ncomp > 1:
        nonzero = [c for c in columns if any(v[c] != 0 for row in rows for v in row)]
        columns = nonzero or columns[:1]
    if vertical:
        fig, axes = plt.subplots(1, len(columns), sharey=True, squeeze=False,
                                 figsize=(3.2 + 3.0 * len(columns), 5.0))
        cells = [axes[0][k] for k in range(len(columns))]
    else:
        fig, axes = plt.subplots(len(columns), 1, sharex=True, squeeze=False,
                                 figsize=(7.5, 2.2 + 2.0 * len(columns)))
        cells = [axes[k][0] for k in range(len(columns))]
    cmap = plt.get_cmap("viridis")
    for ax, col in zip(cells, columns):
        comp = names[col]
        for r, row in enumerate(rows):
            values = [v[col] if isinstance(v, list) else v for v in row]
            n = min(len(values), len(where))
            t = times[r] if r < len(times) else float("nan")
            xs, ys = (values[:n], where[:n]) if vertical else (where[:n], values[:n])
            ax.plot(xs, ys, marker=".", markersize=3, color=cmap(r / max(1, len(rows) - 1)),
                    label=f"t = {format_time(t)}")
        if vertical:
            ax.set_xlabel(_axis_label(field, comp, units))
        else:
            ax.set_ylabel(_axis_label(field, comp, units))
        ax.grid(True, alpha=0.3)
    if vertical:
        cells[0].set_ylabel(where_label)
        cells[0].invert_yaxis()  # shared: depth grows downward on every axes
    else:
        cells[-1].set_xlabel(where_label)
    cells[-1 if vertical else 0].legend(fontsize="x-small", loc="best")
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
    scale, time_name = time_unit(max(t for t, _ in pairs))
    fig, axes = plt.subplots(1, 2, figsize=(10.5, 4.2), squeeze=False)
    ax = axes[0][0]
    ax.plot([t / scale for t, _ in pairs], [100 * u for _, u in pairs], marker=".", markersize=3)
    ax.set_xscale("log")
    ax.set_ylim(105, -5)
    ax.set_xlabel(f"time [{time_name}]")
    ax.set_ylabel("average degree of consolidation U [%]")
    for key, level in (("t50", 50), ("t90", 90)):
        t = doc.get(key)
        if t:
            ax.axhline(level, color="grey", lw=0.6, ls=":")
            ax.axvline(t / scale, color="grey", lw=0.6, ls=":")
            ax.annotate(f"{key} = {format_time(t)}", (t / scale, level), textcoords="offset points",
                        xytext=(4, -10), fontsize="small")
    ax.grid(True, which="both", alpha=0.3)
    ax2 = axes[0][1]
    excess = doc.get("average_excess_pore_pressure") or []
    ex = [(t, e) for t, e in zip(times, excess) if e is not None and t > 0]
    ax2.plot([t / scale for t, _ in ex], [e / 1000 for _, e in ex], marker=".", markersize=3, color="C1")
    ax2.set_xscale("log")
    ax2.set_xlabel(f"time [{time_name}]")
    ax2.set_ylabel("average excess pore pressure [kPa]")
    ax2.grid(True, which="both", alpha=0.3)
    fig.suptitle(title or "degree of consolidation")
    return _save(plt, fig, out)

