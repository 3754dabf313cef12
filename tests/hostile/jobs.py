"""Small HTTP and process helpers of the store and life-cycle attacks
(test_store.py, test_lifecycle.py): JSON requests with the standard
library, waiting for a job's status, checking downloads against the
manifest, and running hmpm-server on a database and data folder the test
keeps across restarts (ServerProcess makes a fresh one each time).
"""

from __future__ import annotations

import hashlib
import json
import os
import subprocess
import time
import urllib.error
import urllib.request
from pathlib import Path
from typing import List, Optional, Tuple

from tests.hostile.support import ServerProcess, server_binary

HTTP_TIMEOUT_S = 10.0


def request(url: str, method: str = "GET", body: Optional[bytes] = None,
            headers: Optional[dict] = None) -> Tuple[int, dict, bytes]:
    """(status, headers, body) of one request; HTTP errors are answers too."""
    req = urllib.request.Request(url, data=body, method=method, headers=dict(headers or {}))
    if body is not None:
        req.add_header("Content-Type", "application/json")
    try:
        with urllib.request.urlopen(req, timeout=HTTP_TIMEOUT_S) as r:
            return r.status, dict(r.headers), r.read()
    except urllib.error.HTTPError as e:
        return e.code, dict(e.headers), e.read()


def get_json(url: str) -> Tuple[int, dict]:
    status, _, body = request(url)
    return status, json.loads(body or b"{}")


def submit(base: str, spec: dict) -> str:
    status, _, body = request(base + "/jobs", "POST", json.dumps(spec).encode())
    if status != 201:
        raise AssertionError(f"POST /jobs answered {status}: {body[:500]!r}")
    return json.loads(body)["jobID"]


def wait_status(base: str, job: str, wanted, timeout: float) -> dict:
    """The job's status document once its status is in `wanted`."""
    wanted = {wanted} if isinstance(wanted, str) else set(wanted)
    deadline = time.monotonic() + timeout
    doc: dict = {}
    while time.monotonic() < deadline:
        status, doc = get_json(f"{base}/jobs/{job}")
        if status == 200 and doc.get("status") in wanted:
            return doc
        time.sleep(0.05)
    raise AssertionError(f"job {job} not {sorted(wanted)} within {timeout} s: {doc}")


def verify_results(base: str, job: str) -> List[str]:
    """Downloads every file of the job's manifest and checks size and
    SHA-256; returns the names. Raises AssertionError on any mismatch."""
    status, manifest = get_json(f"{base}/jobs/{job}/results")
    if status != 200:
        raise AssertionError(f"manifest of {job}: {status} {manifest}")
    names = []
    for f in manifest["files"]:
        code, _, data = request(f"{base}/jobs/{job}/results/{f['name']}")
        if code != 200:
            raise AssertionError(f"{f['name']}: {code} {data[:300]!r}")
        if len(data) != f["size"] or hashlib.sha256(data).hexdigest() != f["sha256"]:
            raise AssertionError(f"{f['name']}: {len(data)} bytes, sha256 differs from the manifest")
        names.append(f["name"])
    return names


class KeptServer(ServerProcess):
    """A ServerProcess on a database and data folder of the caller's (so a
    restart finds the same jobs); `--db`/`--data-dir` given last win."""

    def __init__(self, db: Path, data_dir: Optional[Path] = None, workers: int = 1,
                 extra: Optional[List[str]] = None, port: int = 0):
        args = ["--db", str(db)] + (["--data-dir", str(data_dir)] if data_dir else [])
        args += ["--port", str(port)] + list(extra or [])
        super().__init__(workers=workers, extra=args)


def run_server(args: List[str], timeout: float = 20.0) -> subprocess.CompletedProcess:
    """hmpm-server ARGS to its end (for servers that must refuse to start)."""
    env = dict(os.environ)
    env.pop("HMPM_TOKEN", None)
    return subprocess.run([str(server_binary()), "--host", "127.0.0.1"] + args, env=env,
                          stdin=subprocess.DEVNULL, capture_output=True, text=True, timeout=timeout)


def log_events(server: ServerProcess) -> List[dict]:
    """The server's JSON log lines so far (stderr)."""
    if server._log:
        server._log.flush()
    out = []
    for line in (server.tmp / "server.log").read_text(errors="replace").splitlines():
        try:
            out.append(json.loads(line))
        except ValueError:
            pass
    return out
