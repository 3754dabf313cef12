"""Time-history plots of a job's series particles (matplotlib, Agg backend).

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
    "strain": "-", "porosity": "-",
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
    fig.tight_layout()
    out = Path(out)
    if out.parent and not out.parent.exists():
        out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return out
