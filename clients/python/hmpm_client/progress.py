"""A one-line progress bar for a running job: percent, simulated time, ETA.

`ProgressBar.update(doc)` takes a job status document (or the merged fields of
a progress event) and redraws the line. On a terminal the line is redrawn in
place with a carriage return; when the output is a file or a pipe (CI logs,
tests) a new line is written only when the status changes or the progress
crosses another 10 %, so logs stay short. `finish(doc)` ends the line.

The simulated time and end time shown are the server's own: hmpm-server's
status document carries them in `run` (`simulated_time`, `end_time`, the
solver's figures, stored with the progress) once the job runs. Before that,
or from a service that reports only the percentage, the simulated time is
that fraction of the spec's `time.end` when this client submitted it (never
an estimate from `cost`: the steps of a quasi-static or staged run are not
all of the first step's size). The ETA is extrapolated from the progress rate
observed by this client since the job started running; it is never taken
from the server's clock.
"""

from __future__ import annotations

import shutil
import sys
import time
from typing import Any, Dict, Optional, TextIO

# Keys under which a status document or progress event may report the
# simulated time reached and the end time of the run (first match wins).
_SIM_TIME_KEYS = ("simulated_time", "sim_time", "time", "t")
_END_TIME_KEYS = ("end_time", "time_end", "simulated_end_time", "t_end")


def _number(doc: Dict[str, Any], keys) -> Optional[float]:
    for k in keys:
        v = doc.get(k)
        if isinstance(v, (int, float)) and not isinstance(v, bool):
            return float(v)
    return None


def format_duration(seconds: Optional[float]) -> str:
    """`7s`, `1m05s`, `2h03m`; `--` when unknown."""
    if seconds is None or seconds != seconds or seconds < 0 or seconds > 1e7:
        return "--"
    s = int(round(seconds))
    if s < 60:
        return f"{s}s"
    if s < 3600:
        return f"{s // 60}m{s % 60:02d}s"
    return f"{s // 3600}h{(s % 3600) // 60:02d}m"


def format_sim_time(t: float) -> str:
    return f"{t:.4g}"


def format_sim_span(t: float, end: Optional[float] = None) -> str:
    """`t` (and `end`) in the time unit that reads best for `end` (or `t`):
    `t=12.5/30 s`, `t=3.2/10 days`, `t=0.8/5 years`."""
    from .units import time_unit  # local: units has no dependency on this module

    scale, unit = time_unit(end if end is not None else t)
    if end is None:
        return f"t={format_sim_time(t / scale)} {unit}"
    return f"t={format_sim_time(t / scale)}/{format_sim_time(end / scale)} {unit}"


class ProgressBar:
    """Draws the progress of one job on `file` (default: stderr)."""

    width = 20

    def __init__(self, job_id: str, file: Optional[TextIO] = None, end_time: Optional[float] = None):
        self.job_id = job_id
        self.file = file if file is not None else sys.stderr
        try:
            self.tty = bool(self.file.isatty())
        except (AttributeError, ValueError):
            self.tty = False
        self._start: Optional[tuple] = None  # (wall time, progress) when first seen running
        self._last_line_len = 0
        self._last_status: Optional[str] = None
        self._last_decile = -1
        self._last_printed = ""
        self._end_time: Optional[float] = end_time
        self._finished = False

    def eta(self, progress: float, now: Optional[float] = None) -> Optional[float]:
        """Seconds left, extrapolated from the rate seen since the run began."""
        if self._start is None:
            return None
        now = time.monotonic() if now is None else now
        t0, p0 = self._start
        if progress <= p0 or now <= t0:
            return None
        return (now - t0) * (100.0 - progress) / (progress - p0)

    def render(self, doc: Dict[str, Any]) -> str:
        status = str(doc.get("status", "?"))
        progress = doc.get("progress")
        p = float(progress) if isinstance(progress, (int, float)) else 0.0
        p = min(max(p, 0.0), 100.0)
        filled = int(round(self.width * p / 100.0))
        bar = "#" * filled + "-" * (self.width - filled)
        parts = [f"{self.job_id[:8]} {status:<10}", f"[{bar}]", f"{p:3.0f}%"]
        sim = _number(doc, _SIM_TIME_KEYS)
        end = _number(doc, _END_TIME_KEYS)
        run = doc.get("run")
        if isinstance(run, dict):  # hmpm-server: what the solver reached
            sim = _number(run, _SIM_TIME_KEYS) if sim is None else sim
            end = _number(run, _END_TIME_KEYS) if end is None else end
        if end is not None and end > 0:
            self._end_time = end
        end = self._end_time
        if sim is None and end is not None and status in ("running", "successful"):
            sim = end * p / 100.0  # progress is the fraction of simulated time done
        if sim is not None:
            parts.append(format_sim_span(sim, end))
        if status == "running":
            parts.append("ETA " + format_duration(self.eta(p)))
        elif status == "accepted":
            parts.append("queued")
        return "  ".join(parts)

    def update(self, doc: Dict[str, Any]) -> None:
        """Redraws the line for the status document (or merged event) `doc`."""
        if self._finished:
            return
        status = str(doc.get("status", ""))
        progress = doc.get("progress")
        p = float(progress) if isinstance(progress, (int, float)) else 0.0
        if status == "running" and self._start is None:
            self._start = (time.monotonic(), p)
        line = self.render(doc)
        if self.tty:
            # Never wrap: a wrapped line cannot be redrawn with a carriage return.
            line = line[: max(20, shutil.get_terminal_size((100, 24)).columns - 1)]
            pad = max(0, self._last_line_len - len(line))
            self.file.write("\r" + line + " " * pad)
            self._last_line_len = len(line)
            self.file.flush()
            return
        decile = int(p // 10)
        if (status != self._last_status or decile != self._last_decile) and line != self._last_printed:
            self.file.write(line + "\n")
            self.file.flush()
            self._last_printed = line
        self._last_status = status
        self._last_decile = decile

    def finish(self, doc: Dict[str, Any]) -> None:
        """Draws the final state and ends the line."""
        if self._finished:
            return
        if self.tty:
            self.update(doc)
            self.file.write("\n")
        else:
            self._last_status = None  # force the final line out
            self.update(doc)
        self.file.flush()
        self._finished = True
