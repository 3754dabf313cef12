"""Units for labels: the output fields' units (from the server's `GET /fields`
document, the solver's table) and the time unit that reads best for a span.

`time_unit(span)` picks seconds, minutes, hours, days or years so that the
numbers on an axis stay between about 1 and a few hundred: a five-year
consolidation reads `0 … 5 years`, not `0 … 1.578e8 s`.
"""

from __future__ import annotations

from typing import Any, Dict, Iterable, Optional, Tuple

MINUTE = 60.0
HOUR = 3600.0
DAY = 86400.0
YEAR = 365.25 * DAY

# (unit, seconds per unit, the span from which it is used); the first row
# whose threshold the span reaches, from the bottom, wins.
_TIME_UNITS = (
    ("s", 1.0, 0.0),
    ("min", MINUTE, 2 * MINUTE),
    ("h", HOUR, 2 * HOUR),
    ("days", DAY, 2 * DAY),
    ("years", YEAR, YEAR),
)


def time_unit(span: Optional[float]) -> Tuple[float, str]:
    """(seconds per unit, unit name) for times up to `span` seconds:
    s below 2 min, min below 2 h, h below 2 days, days below a year, then
    years."""
    s = abs(span) if isinstance(span, (int, float)) and span == span else 0.0
    scale, name = 1.0, "s"
    for unit, seconds, threshold in _TIME_UNITS:
        if s >= threshold:
            scale, name = seconds, unit
    return scale, name


def scaled_times(times: Iterable[float]) -> Tuple[list, str]:
    """The times in the unit that reads best for the largest of them, and
    that unit's name."""
    values = [float(t) for t in times]
    scale, name = time_unit(max((abs(t) for t in values), default=0.0))
    return [t / scale for t in values], name


def format_time(t: float, span: Optional[float] = None) -> str:
    """`t` in the unit that reads best for `span` (default: `t` itself):
    `10 days`, `1 years`, `30 s`."""
    scale, name = time_unit(t if span is None else span)
    return f"{t / scale:.4g} {name}"


def field_units(fields_doc: Optional[Dict[str, Any]]) -> Dict[str, str]:
    """{field name: unit} from the server's `GET /fields` document
    (`{"fields": [{"name", "kind", "unit"}, ...]}`); {} when absent."""
    out: Dict[str, str] = {}
    for f in (fields_doc or {}).get("fields") or []:
        if isinstance(f, dict) and isinstance(f.get("name"), str) and isinstance(f.get("unit"), str):
            out[f["name"]] = f["unit"]
    return out
