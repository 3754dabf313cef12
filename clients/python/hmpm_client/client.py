"""Python access to an hmpm job service (standard library only).

    from hmpm_client import Client
    client = Client("http://127.0.0.1:8080")          # token: arg or HMPM_TOKEN
    job = client.submit("examples/terzaghi.json")     # path, dict or JSON text
    job.wait()                                        # progress bar on stderr
    job.download("out/")                              # every file, sha256-checked
    series = job.series()                             # parsed series.json

`Client` sends requests; `Job` is a handle on one job id. Every refusal by
the service raises `HmpmError` with the service's problem document; network
failures raise `HmpmError` too (type `connection-error`, no HTTP status).
The HTTP contract is in docs/api.md and docs/contract.md.
"""

from __future__ import annotations

import hashlib
import json
import os
import socket
import time
import urllib.error
import urllib.parse
import urllib.request
from pathlib import Path
from typing import Any, Dict, List, Optional, Sequence, TextIO, Union

from .errors import HmpmError
from .events import read_events
from .progress import ProgressBar

TERMINAL_STATUSES = frozenset({"successful", "failed", "dismissed"})
DEFAULT_URL = "http://127.0.0.1:8080"

SpecLike = Union[str, "os.PathLike[str]", Dict[str, Any], bytes]


def _problem_from_body(status: int, reason: str, content_type: str, body: bytes) -> Dict[str, Any]:
    """The problem document of an error response, or one made up from it."""
    if body:
        try:
            doc = json.loads(body.decode("utf-8"))
            if isinstance(doc, dict) and ("type" in doc or "title" in doc or "errors" in doc):
                return doc
        except (ValueError, UnicodeDecodeError):
            pass
    text = body.decode("utf-8", errors="replace").strip()[:500]
    return {"type": "about:blank", "title": reason or f"HTTP {status}", "status": status, "detail": text}


class Client:
    """A connection to one hmpm service.

    Args:
        url:     base URL, e.g. `http://127.0.0.1:8080` (default: `HMPM_URL`
                 or http://127.0.0.1:8080).
        token:   bearer token; default `HMPM_TOKEN` from the environment.
        timeout: seconds to wait for each ordinary request.
    """

    def __init__(self, url: Optional[str] = None, token: Optional[str] = None, timeout: float = 30.0):
        url = url or os.environ.get("HMPM_URL") or DEFAULT_URL
        self.url = url.rstrip("/")
        self.token = token if token is not None else (os.environ.get("HMPM_TOKEN") or None)
        self.timeout = timeout
        # A service on this machine is reached directly even when
        # http_proxy/https_proxy are set; anything else follows the
        # environment's proxy settings as urllib does by default.
        host = (urllib.parse.urlsplit(self.url).hostname or "").lower()
        loopback = host in ("localhost", "::1") or host.startswith("127.")
        self._opener = urllib.request.build_opener(urllib.request.ProxyHandler({}) if loopback else
                                                   urllib.request.ProxyHandler())

    def __repr__(self) -> str:
        return f"Client({self.url!r})"

    # -- HTTP ------------------------------------------------------------

    def _full_url(self, path: str) -> str:
        if path.startswith("http://") or path.startswith("https://"):
            return path
        return self.url + ("" if path.startswith("/") else "/") + path

    def _same_origin(self, url: str) -> bool:
        a, b = urllib.parse.urlsplit(url), urllib.parse.urlsplit(self.url)
        return (a.scheme, a.netloc) == (b.scheme, b.netloc)

    def open(self, method: str, path: str, body: Optional[bytes] = None,
             headers: Optional[Dict[str, str]] = None, timeout: Optional[float] = None):
        """Sends a request and returns the open response (status < 400).

        Raises HmpmError with the service's problem document for any error
        status, and with type `connection-error` when the service is not
        reachable. The caller closes the response.
        """
        url = self._full_url(path)
        hdrs = {"Accept": "application/json, application/problem+json"}
        if self.token and self._same_origin(url):
            hdrs["Authorization"] = f"Bearer {self.token}"
        if body is not None:
            hdrs["Content-Type"] = "application/json"
        hdrs.update(headers or {})
        req = urllib.request.Request(url, data=body, method=method, headers=hdrs)
        try:
            return self._opener.open(req, timeout=self.timeout if timeout is None else timeout)
        except urllib.error.HTTPError as e:
            try:
                raw = e.read()
            except OSError:
                raw = b""
            ctype = e.headers.get("Content-Type", "") if e.headers else ""
            problem = _problem_from_body(e.code, str(e.reason or ""), ctype, raw)
            retry = e.headers.get("Retry-After") if e.headers else None
            if retry is not None:
                problem.setdefault("retry_after", retry)
            raise HmpmError(problem, e.code) from None
        except (urllib.error.URLError, OSError) as e:
            reason = getattr(e, "reason", e)
            raise HmpmError({"type": "connection-error", "title": "cannot reach the hmpm service",
                             "detail": f"{method} {url}: {reason}"}) from None

    def request(self, method: str, path: str, body: Optional[bytes] = None,
                headers: Optional[Dict[str, str]] = None) -> Any:
        """Sends a request and returns the parsed JSON body (None if empty)."""
        with self.open(method, path, body, headers) as resp:
            raw = resp.read()
            location = resp.headers.get("Location")
        if not raw.strip():
            return None
        try:
            doc = json.loads(raw.decode("utf-8"))
        except ValueError:
            raise HmpmError({"type": "bad-response", "title": "the service sent invalid JSON",
                             "detail": f"{method} {path}: {raw[:200]!r}"}) from None
        if isinstance(doc, dict) and location and "jobID" not in doc:
            doc["_location"] = location
        return doc

    # -- Jobs ------------------------------------------------------------

    def health(self) -> Any:
        """`GET /health`: the service's health document."""
        return self.request("GET", "/health")

    def fields(self) -> Dict[str, Any]:
        """`GET /fields`: the output fields with their kinds and units
        (`{"fields": [{"name", "kind", "unit"}, ...], "time_unit": "s"}`),
        the solver's table; the plots take their axis units from it."""
        doc = self.request("GET", "/fields")
        return doc if isinstance(doc, dict) else {}

    def field_units(self) -> Dict[str, str]:
        """{field name: unit} from `fields()`."""
        from .units import field_units
        return field_units(self.fields())

    def submit(self, spec: SpecLike, idempotency_key: Optional[str] = None) -> "Job":
        """Submits a job spec and returns its Job (status `accepted`).

        `spec` is a path to a JSON file, a dict, JSON text, or bytes. A file
        is sent byte for byte so the service's error paths match it. With an
        `idempotency_key`, repeating the same submission returns the first
        job (with `.replayed` True) instead of creating another. Raises HmpmError when the spec is
        refused (`.errors` lists every path and message).
        """
        body = _spec_bytes(spec)
        headers = {"Idempotency-Key": idempotency_key} if idempotency_key else {}
        with self.open("POST", "/jobs", body, headers) as resp:
            raw = resp.read()
            location = resp.headers.get("Location", "")
            replayed = resp.headers.get("Idempotent-Replayed", "").lower() == "true"
        doc: Dict[str, Any] = {}
        if raw.strip():
            try:
                doc = json.loads(raw.decode("utf-8"))
            except ValueError:
                doc = {}
        job_id = doc.get("jobID") if isinstance(doc, dict) else None
        if not job_id and location:
            job_id = location.rstrip("/").rsplit("/", 1)[-1]
        if not job_id:
            raise HmpmError({"type": "bad-response", "title": "the service did not return a job id",
                             "detail": raw[:200].decode("utf-8", errors="replace")})
        job = Job(self, str(job_id), doc if isinstance(doc, dict) else {})
        job.end_time = _spec_end_time(body)
        job.replayed = replayed
        warnings = doc.get("warnings") if isinstance(doc, dict) else None
        job.warnings = [w for w in warnings if isinstance(w, dict)] if isinstance(warnings, list) else []
        return job

    def job(self, job_id: str) -> "Job":
        """A handle on an existing job (no request is made)."""
        return Job(self, job_id)

    # -- Ensembles (ensemble.py) -------------------------------------------

    def submit_ensemble(self, request: SpecLike, idempotency_key: Optional[str] = None):
        """`POST /ensembles`: submits an ensemble request (`{"spec", "samples",
        "seed", "vary"}`: a path, dict, JSON text or bytes) and returns its
        Ensemble. Raises HmpmError when it is refused (`.errors` lists every
        JSON path and message)."""
        from .ensemble import submit_ensemble
        return submit_ensemble(self, request, idempotency_key)

    def ensemble(self, ensemble_id: str):
        """A handle on an existing ensemble (no request is made)."""
        from .ensemble import Ensemble
        return Ensemble(self, ensemble_id)

    def ensembles(self, status: Union[str, Sequence[str], None] = None,
                  limit: Optional[int] = None) -> List[Dict[str, Any]]:
        """`GET /ensembles`: ensemble documents, newest first, of the given
        status (as for jobs), at most `limit`."""
        return self._list("ensembles", status, limit)

    def jobs(self, status: Union[str, Sequence[str], None] = None,
             limit: Optional[int] = None, name: Optional[str] = None) -> List[Dict[str, Any]]:
        """`GET /jobs`: status documents, newest first, of the given status
        (one name, a comma-separated string or a list) and job `name`, at
        most `limit`."""
        return self._list("jobs", status, limit, name)

    def _list(self, collection: str, status: Union[str, Sequence[str], None],
              limit: Optional[int], name: Optional[str] = None) -> List[Dict[str, Any]]:
        """GET /jobs or /ensembles with the status, limit and name filters."""
        query = {}
        if status:
            query["status"] = status if isinstance(status, str) else ",".join(status)
        if name:
            query["name"] = name
        if limit is not None:
            query["limit"] = str(int(limit))
        path = f"/{collection}" + ("?" + urllib.parse.urlencode(query) if query else "")
        doc = self.request("GET", path)
        if isinstance(doc, dict):
            doc = doc.get(collection, [])
        return list(doc or [])


def _spec_bytes(spec: SpecLike) -> bytes:
    if isinstance(spec, bytes):
        return spec
    if isinstance(spec, dict):
        return json.dumps(spec).encode("utf-8")
    if isinstance(spec, str) and spec.lstrip().startswith("{"):
        return spec.encode("utf-8")
    path = Path(spec)
    return path.read_bytes()


def _spec_end_time(body: bytes) -> Optional[float]:
    """The job's end in seconds: the last stage's `end` of a staged spec,
    else `time.end`; None when the spec does not say."""
    try:
        spec = json.loads(body.decode("utf-8"))
        stages = spec.get("stages")
        end = stages[-1].get("end") if isinstance(stages, list) and stages else None
        if end is None:
            end = spec.get("time", {}).get("end")
    except (ValueError, UnicodeDecodeError, AttributeError):
        return None
    return float(end) if isinstance(end, (int, float)) and not isinstance(end, bool) else None


def _safe_relative(name: str) -> Path:
    """`name` as a relative path that stays inside the download folder."""
    p = Path(name.replace("\\", "/"))
    if not name or p.is_absolute() or any(part in ("..", "") for part in p.parts) or ":" in name:
        raise HmpmError({"type": "bad-response", "title": "unsafe result file name", "detail": repr(name)})
    return p


class Job:
    """One job on the service. `doc` holds the last status document seen."""

    def __init__(self, client: Client, job_id: str, doc: Optional[Dict[str, Any]] = None):
        self.client = client
        self.id = job_id
        self.doc: Dict[str, Any] = dict(doc or {})
        self.end_time: Optional[float] = None  # the spec's time.end, when known
        self.replayed = False  # submit() returned an earlier job for its idempotency key
        # What the service warned about at submission ({"path", "message"} each):
        # the spec is valid but something is worth knowing before it runs.
        self.warnings: List[Dict[str, Any]] = []

    def __repr__(self) -> str:
        return f"Job({self.id!r}, status={self.doc.get('status')!r})"

    @property
    def path(self) -> str:
        return "/jobs/" + urllib.parse.quote(self.id, safe="")

    def status(self) -> Dict[str, Any]:
        """`GET /jobs/{id}`: the current status document."""
        doc = self.client.request("GET", self.path)
        if isinstance(doc, dict):
            self.doc = doc
        return self.doc

    @property
    def done(self) -> bool:
        return self.doc.get("status") in TERMINAL_STATUSES

    def spec(self) -> Dict[str, Any]:
        """`GET /jobs/{id}/spec`: the job spec as it was submitted."""
        doc = self.client.request("GET", self.path + "/spec")
        return doc if isinstance(doc, dict) else {}

    def cancel(self) -> Dict[str, Any]:
        """`POST /jobs/{id}/cancel`: stops a queued or running job (status
        `dismissed`); whatever it wrote stays downloadable.

        Raises HmpmError with status 409 (type `job-finished`) when the job
        had already ended: nothing changes then, its results stay.
        """
        doc = self.client.request("POST", self.path + "/cancel")
        if isinstance(doc, dict) and "status" in doc:
            self.doc = doc
            return doc
        return self.status()

    def delete(self) -> Dict[str, Any]:
        """`DELETE /jobs/{id}`: dismisses the job (cancelling it if it runs)
        and deletes its result files."""
        doc = self.client.request("DELETE", self.path)
        if isinstance(doc, dict) and "status" in doc:
            self.doc = doc
            return doc
        return self.status()

    def log(self) -> str:
        """`GET /jobs/{id}/log`: the job's log so far, as text."""
        with self.client.open("GET", self.path + "/log", headers={"Accept": "text/plain"}) as resp:
            return resp.read().decode("utf-8", errors="replace")

    # -- waiting ---------------------------------------------------------

    def wait(self, progress: bool = True, timeout: Optional[float] = None,
             poll_interval: float = 1.0, events: bool = True,
             file: Optional[TextIO] = None) -> Dict[str, Any]:
        """Blocks until the job is successful, failed or dismissed.

        Follows `GET /jobs/{id}/events` (Server-Sent Events) and falls back
        to polling `GET /jobs/{id}` every `poll_interval` seconds when the
        stream is refused or breaks. With `progress`, draws a one-line bar on
        `file` (default stderr). Returns the final status document; raises
        TimeoutError after `timeout` seconds, HmpmError if the job cannot be
        read.
        """
        deadline = None if timeout is None else time.monotonic() + timeout
        bar = ProgressBar(self.id, file, self.end_time) if progress else None
        try:
            doc = self.status()
            if bar:
                bar.update(doc)
            if events and not self.done:
                self._follow_events(bar, deadline)
            while not self.done:
                _check_deadline(deadline, self.id, timeout)
                time.sleep(_bounded_sleep(poll_interval, deadline))
                doc = self.status()
                if bar:
                    bar.update(doc)
        finally:
            if bar and self.done:
                bar.finish(self.doc)
            elif bar:
                bar.file.write("\n")
        return self.doc

    def _follow_events(self, bar: Optional[ProgressBar], deadline: Optional[float]) -> None:
        """Merges the event stream into `self.doc` until the job ends.

        Returns early (leaving the rest to polling) when the stream cannot be
        opened, breaks, goes quiet, or ends before the job does and
        reconnecting did not help.
        """
        reconnects = 0
        while not self.done and reconnects < 3:
            remaining = None if deadline is None else deadline - time.monotonic()
            if remaining is not None and remaining <= 0:
                return
            read_timeout = 30.0 if remaining is None else max(1.0, min(30.0, remaining))
            got_any = False
            try:
                resp = self.client.open("GET", self.path + "/events",
                                        headers={"Accept": "text/event-stream"}, timeout=read_timeout)
            except HmpmError:
                return
            try:
                ctype = resp.headers.get("Content-Type", "")
                if "text/event-stream" not in ctype:
                    return
                for ev in read_events(_lines(resp)):
                    got_any = True
                    if ev.name != "heartbeat" and ev.data:
                        self._merge_event(ev.data)
                        if bar:
                            bar.update(self.doc)
                    if self.done:
                        return
                    if deadline is not None and time.monotonic() > deadline:
                        return
            except (OSError, socket.timeout, ValueError):
                return
            finally:
                resp.close()
            # The stream ended before a final state: ask for the status, and
            # reconnect unless the job has finished meanwhile.
            try:
                doc = self.status()
            except HmpmError:
                return
            if bar:
                bar.update(doc)
            reconnects = 0 if got_any else reconnects + 1
            if not self.done:
                time.sleep(_bounded_sleep(1.0, deadline))  # as the stream's `retry:` asks

    def _merge_event(self, data: str) -> None:
        try:
            payload = json.loads(data)
        except ValueError:
            return
        if isinstance(payload, dict):
            # A progress event may carry only some fields; keep the rest.
            inner = payload.get("job") if isinstance(payload.get("job"), dict) else payload
            self.doc.update({k: v for k, v in inner.items() if k != "jobID" or v == self.id})

    # -- results ---------------------------------------------------------

    def results(self) -> List[Dict[str, Any]]:
        """`GET /jobs/{id}/results`: the manifest's files (name, size,
        media_type, sha256, href). Raises HmpmError of type
        `result-not-ready` while the job has not finished."""
        doc = self.client.request("GET", self.path + "/results")
        files = doc.get("files", []) if isinstance(doc, dict) else []
        return list(files)

    def _file_url(self, entry: Dict[str, Any]) -> str:
        return result_url(self.client, self.path, entry)

    def open_result(self, name: str):
        """Opens the result file `name` as an HTTP response (caller closes)."""
        path = self.path + "/results/" + urllib.parse.quote(name, safe="/")
        return self.client.open("GET", path, timeout=max(self.client.timeout, 120.0))

    def read_result(self, name: str) -> bytes:
        """The bytes of one result file."""
        with self.open_result(name) as resp:
            return resp.read()

    def series(self) -> Dict[str, Any]:
        """The parsed `series.json`: `{"time": [...], "particles": [...]}`."""
        return json.loads(self.read_result("series.json").decode("utf-8"))

    def summary(self) -> Dict[str, Any]:
        """The parsed `summary.json`."""
        return json.loads(self.read_result("summary.json").decode("utf-8"))

    def download(self, directory: Union[str, "os.PathLike[str]"]) -> List[Path]:
        """Downloads every result file into `directory` (created if needed).

        Each file is written to a temporary name, checked against the
        manifest's size and sha256, then renamed; returns the paths written.
        Raises HmpmError (type `checksum-mismatch`) if a file does not match.
        """
        return download_files(self.client, self.results(), directory, self._file_url)


def result_url(client: Client, path: str, entry: Dict[str, Any]) -> str:
    """Where to fetch a manifest entry of the resource at `path` (a job or an
    ensemble): its `href` on this service, else `path/results/name`."""
    href = entry.get("href")
    if isinstance(href, str) and href:
        url = urllib.parse.urljoin(client.url + "/", href)
        if client._same_origin(url):
            return url
    return path + "/results/" + urllib.parse.quote(str(entry["name"]), safe="/")


def download_files(client: Client, entries: List[Dict[str, Any]],
                   directory: Union[str, "os.PathLike[str]"], file_url) -> List[Path]:
    """Downloads the manifest `entries` (name, size, sha256) into `directory`,
    each from `file_url(entry)`: to a temporary name, checked against the
    manifest's size and sha256, then renamed. Returns the paths written;
    raises HmpmError (type `checksum-mismatch`) if a file does not match."""
    root = Path(directory)
    root.mkdir(parents=True, exist_ok=True)
    written = []
    for entry in entries:
        rel = _safe_relative(str(entry.get("name", "")))
        target = root / rel
        target.parent.mkdir(parents=True, exist_ok=True)
        part = target.with_name(target.name + ".part")
        digest = hashlib.sha256()
        size = 0
        with client.open("GET", file_url(entry), timeout=max(client.timeout, 120.0)) as resp, \
                open(part, "wb") as out:
            while True:
                chunk = resp.read(1 << 16)
                if not chunk:
                    break
                digest.update(chunk)
                size += len(chunk)
                out.write(chunk)
        want_sha = str(entry.get("sha256") or "").lower()
        want_size = entry.get("size")
        if (want_sha and digest.hexdigest() != want_sha) or (isinstance(want_size, int) and size != want_size):
            part.unlink()
            raise HmpmError({"type": "checksum-mismatch", "title": "downloaded file does not match the manifest",
                             "detail": f"{rel}: got {size} bytes sha256 {digest.hexdigest()}, "
                                       f"manifest says {want_size} bytes sha256 {want_sha}"})
        os.replace(part, target)
        written.append(target)
    return written


def _lines(resp):
    while True:
        line = resp.readline()
        if not line:
            return
        yield line


def _check_deadline(deadline: Optional[float], job_id: str, timeout: Optional[float]) -> None:
    if deadline is not None and time.monotonic() >= deadline:
        raise TimeoutError(f"job {job_id} did not finish within {timeout:g} s")


def _bounded_sleep(interval: float, deadline: Optional[float]) -> float:
    if deadline is None:
        return interval
    return max(0.0, min(interval, deadline - time.monotonic()))


__all__ = ["Client", "Job", "HmpmError", "TERMINAL_STATUSES", "DEFAULT_URL"]
