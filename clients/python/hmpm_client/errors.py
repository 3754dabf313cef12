"""The one exception the hmpm client raises for anything the service refuses.

The service answers every error with an RFC 9457 problem document
(`application/problem+json`: `type`, `title`, `status`, `detail`, and for a
refused job spec `errors: [{"path", "message"}]`). `HmpmError` carries that
document unchanged in `.problem`, so callers can branch on `.type` or
`.status`, and its `str()` is a readable report with one line per spec error.
Failures that never reached the service (connection refused, a bad checksum
on a download) are reported the same way with a problem document the client
makes up, so a caller needs a single `except HmpmError`.
"""

from __future__ import annotations

from typing import Any, Dict, List, Optional


class HmpmError(Exception):
    """A request the hmpm service refused, or that could not be completed.

    Attributes:
        problem: the problem document (a dict; always has `type` and `title`).
        status:  the HTTP status code, or None when no response was received.
    """

    def __init__(self, problem: Dict[str, Any], status: Optional[int] = None):
        self.problem: Dict[str, Any] = dict(problem)
        self.problem.setdefault("type", "about:blank")
        self.problem.setdefault("title", "request failed")
        if status is None:
            raw = self.problem.get("status")
            status = raw if isinstance(raw, int) else None
        self.status: Optional[int] = status
        super().__init__(self._render())

    @property
    def type(self) -> str:
        """The problem type URI or short name, e.g. `result-not-ready`."""
        return str(self.problem.get("type", "about:blank"))

    @property
    def title(self) -> str:
        return str(self.problem.get("title", ""))

    @property
    def detail(self) -> str:
        return str(self.problem.get("detail") or "")

    @property
    def errors(self) -> List[Dict[str, str]]:
        """Each `{"path", "message"}` of a refused job spec (empty otherwise)."""
        errs = self.problem.get("errors")
        if not isinstance(errs, list):
            return []
        out = []
        for e in errs:
            if isinstance(e, dict):
                out.append({"path": str(e.get("path", "")), "message": str(e.get("message", ""))})
            else:
                out.append({"path": "", "message": str(e)})
        return out

    def type_is(self, name: str) -> bool:
        """True when the problem type is `name` or a URI ending in `/name`."""
        t = self.type
        return t == name or t.endswith("/" + name) or t.endswith("#" + name)

    def _render(self) -> str:
        head = self.title or self.type
        if self.status is not None:
            head = f"{head} (HTTP {self.status})"
        detail = self.detail
        if detail and detail != self.title:
            head = f"{head}: {detail}"
        retry = self.problem.get("retry_after")
        if retry is not None:
            head = f"{head} (retry after {retry} s)"
        lines = [head]
        for e in self.errors:
            path = e["path"] or "/"
            lines.append(f"  {path}: {e['message']}")
        return "\n".join(lines)
