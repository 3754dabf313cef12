"""Ensembles of jobs (contract v3, `POST /ensembles`), standard library only.

    from hmpm_client import Client
    client = Client("http://127.0.0.1:8080")
    ens = client.submit_ensemble({"spec": spec, "samples": 100, "seed": 1,
                                  "vary": [{"path": "/materials/clay/cohesion",
                                            "distribution": {"lognormal": {"mean": 20e3, "cov": 0.3}}}]})
    ens.wait()                          # one progress line for the whole ensemble
    stats = ens.statistics()            # parsed statistics.json
    ens.download("out/")                # samples.json and statistics.json, sha256-checked

Each sample is an ordinary job (`ens.jobs()`), so everything `Job` does
works on one sample too.
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path
from typing import Any, Dict, List, Optional, TextIO, Union

from .client import (TERMINAL_STATUSES, Client, Job, SpecLike, _bounded_sleep, _spec_bytes,
                     download_files, result_url)
from .errors import HmpmError


def submit_ensemble(client: Client, request: SpecLike,
                    idempotency_key: Optional[str] = None) -> "Ensemble":
    """`POST /ensembles` (see Client.submit_ensemble)."""
    headers = {"Idempotency-Key": idempotency_key} if idempotency_key else {}
    doc = client.request("POST", "/ensembles", _spec_bytes(request), headers)
    if not isinstance(doc, dict) or not doc.get("ensembleID"):
        raise HmpmError({"type": "bad-response", "title": "the service did not return an ensemble id",
                         "detail": json.dumps(doc)[:200]})
    ens = Ensemble(client, str(doc["ensembleID"]), doc)
    warnings = doc.get("warnings")
    ens.warnings = [w for w in warnings if isinstance(w, dict)] if isinstance(warnings, list) else []
    return ens


class Ensemble:
    """A handle on one ensemble: its status, samples and results."""

    def __init__(self, client: Client, ensemble_id: str, doc: Optional[Dict[str, Any]] = None):
        self.client = client
        self.id = ensemble_id
        self.doc: Dict[str, Any] = dict(doc or {})
        self.warnings: List[Dict[str, Any]] = []

    def __repr__(self) -> str:
        return f"Ensemble({self.id!r}, status={self.doc.get('status')!r})"

    @property
    def path(self) -> str:
        return f"/ensembles/{self.id}"

    def status(self) -> Dict[str, Any]:
        """`GET /ensembles/{id}`: status, progress, counts per status, jobs."""
        self.doc = self.client.request("GET", self.path)
        return self.doc

    @property
    def done(self) -> bool:
        return self.doc.get("status") in TERMINAL_STATUSES

    def jobs(self) -> List[Job]:
        """The samples, in index order, as Job handles."""
        if "jobs" not in self.doc:
            self.status()
        return [Job(self.client, str(j)) for j in self.doc.get("jobs", [])]

    def cancel(self) -> Dict[str, Any]:
        """`POST /ensembles/{id}/cancel`: cancels every sample not yet ended."""
        self.doc = self.client.request("POST", self.path + "/cancel")
        return self.doc

    def delete(self) -> Dict[str, Any]:
        """`DELETE /ensembles/{id}`: dismisses every sample and deletes its files."""
        self.doc = self.client.request("DELETE", self.path)
        return self.doc

    def wait(self, progress: bool = True, timeout: Optional[float] = None,
             poll_interval: float = 1.0, file: Optional[TextIO] = None) -> Dict[str, Any]:
        """Polls until every sample has ended; with `progress`, a line per
        change of the counts on `file` (default stderr). Returns the final
        document; raises TimeoutError after `timeout` seconds."""
        out = file or sys.stderr
        deadline = None if timeout is None else time.monotonic() + timeout
        last = None
        while True:
            doc = self.status()
            line = format_status(doc)
            if progress and line != last:
                out.write(line + "\n")
                out.flush()
                last = line
            if self.done:
                return doc
            if deadline is not None and time.monotonic() >= deadline:
                raise TimeoutError(f"ensemble {self.id} did not finish within {timeout:g} s")
            time.sleep(_bounded_sleep(poll_interval, deadline))

    def results(self) -> List[Dict[str, Any]]:
        """`GET /ensembles/{id}/results`: the manifest's files (samples.json,
        statistics.json). HmpmError `result-not-ready` until every sample ended."""
        doc = self.client.request("GET", self.path + "/results")
        return list(doc.get("files", [])) if isinstance(doc, dict) else []

    def read_result(self, name: str) -> bytes:
        with self.client.open("GET", self.path + "/results/" + name,
                              timeout=max(self.client.timeout, 120.0)) as resp:
            return resp.read()

    def samples(self) -> Dict[str, Any]:
        """The parsed samples.json: each sample's index, jobID, status, values."""
        return json.loads(self.read_result("samples.json").decode("utf-8"))

    def statistics(self) -> Dict[str, Any]:
        """The parsed statistics.json: for each series field of each series
        particle at each time, mean, std, p05, p50 and p95 over the
        successful samples."""
        return json.loads(self.read_result("statistics.json").decode("utf-8"))

    def download(self, directory: Union[str, "Path"]) -> List[Path]:
        """Downloads samples.json and statistics.json into `directory`,
        checked against the manifest's size and sha256."""
        return download_files(self.client, self.results(), directory,
                              lambda entry: result_url(self.client, self.path, entry))


def format_status(doc: Dict[str, Any]) -> str:
    """One line: id, status, progress and the samples per status."""
    counts = doc.get("counts") or {}
    parts = ", ".join(f"{n} {s}" for s, n in counts.items() if n)
    return (f"ensemble {doc.get('ensembleID', '?')} {doc.get('status', '?')} "
            f"{doc.get('progress', 0):>3}%  ({parts or 'no samples'})")


def final_statistics(stats: Dict[str, Any]) -> List[Dict[str, Any]]:
    """The figures at the last time as rows {particle, field, component,
    mean, std, p05, p50, p95} (a vector field gives a row per component)."""
    rows = []
    for particle in stats.get("particles", []):
        for field, figures in particle.items():
            if not isinstance(figures, dict) or "mean" not in figures:
                continue
            means = figures["mean"]
            if not means:
                continue
            last = len(means) - 1
            value = means[last]
            components = len(value) if isinstance(value, list) else 1
            for c in range(components):
                row = {"particle": particle.get("index"), "field": field,
                       "component": c if isinstance(value, list) else None}
                for k in ("mean", "std", "p05", "p50", "p95"):
                    v = figures[k][last]
                    row[k] = v[c] if isinstance(v, list) else v
                rows.append(row)
    return rows
