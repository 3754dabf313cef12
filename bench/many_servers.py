"""Jobs per second through one and three hmpm-servers on one PostgreSQL, and
claim latency (issue 20's benchmark).

    scripts/postgres.sh run python3 bench/many_servers.py [--jobs N] [--out FILE]

Needs HMPM_TEST_POSTGRES (scripts/postgres.sh run sets it) and a built
build/bin/hmpm-server (HMPM_BUILD_DIR to use another build). Standard
library only.

Each configuration gets a schema of its own in the database (a fresh queue)
and one shared --data-dir. Servers run with --workers 1 --threads-per-job 1.

1. Throughput: N short jobs (a 13-particle bar, 50 steps: well under a
   millisecond of solver work, so what is measured is the service: parse,
   store, claim, result files, sha256, finish) are submitted round-robin to
   the servers by 4 client threads as fast as they are answered; jobs/s is
   N over the time from the first POST to the last job's `finished`.
2. Claim latency: with every server idle, one job at a time is posted
   (round-robin) and the latency is its `started` minus its `created`
   (both stamped by the database side's clock, the store's). The worker of
   the server that took the POST is woken at once; the others poll the
   queue every second when idle, so with three servers a job is claimed
   by whichever asks first.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import threading
import time
import urllib.request
from concurrent.futures import ThreadPoolExecutor
from datetime import datetime, timezone
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

SPEC = {
    "name": "bench-short",
    "dimension": 1,
    "grid": {"min": [0.0], "max": [1.0], "cells": [13]},
    "materials": {"bar": {"model": "linear_elastic", "density": 1.0, "youngs_modulus": 10.0,
                          "poisson_ratio": 0.0}},
    "bodies": [{"material": "bar", "box": {"min": [0.0], "max": [1.0]}, "particles_per_cell": 1,
                "initial": {"velocity": ["0.1*sin(pi/2*x)"]}}],
    "gravity": [0.0],
    "boundaries": [{"nodes": {"box": {"min": [0.0], "max": [0.0]}}, "velocity": [0.0]}],
    "time": {"end": 0.05, "dt": 1.0e-3},
    "output": {"series": {"particles": [0, 12], "fields": ["displacement"], "interval": 0.01}},
}


def epoch(ts: str) -> float:
    return datetime.strptime(ts, "%Y-%m-%dT%H:%M:%S.%fZ").replace(tzinfo=timezone.utc).timestamp()


def server_binary() -> Path:
    build = Path(os.environ.get("HMPM_BUILD_DIR", ROOT / "build"))
    return build / "bin" / "hmpm-server"


def uri_with_schema(base: str, schema: str) -> str:
    subprocess.run(["psql", base, "-q", "-c", f"CREATE SCHEMA IF NOT EXISTS {schema}"],
                   check=True, stdout=subprocess.DEVNULL)
    return base + ("&" if "?" in base else "?") + "options=-csearch_path%3D" + schema


class Server:
    def __init__(self, uri: str, data: Path, log: Path):
        self.log = open(log, "w")
        self.proc = subprocess.Popen(
            [str(server_binary()), "--host", "127.0.0.1", "--port", "0", "--db", uri,
             "--data-dir", str(data), "--workers", "1", "--threads-per-job", "1",
             "--retain-days", "0", "--max-queue", "100000"],
            stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=self.log, text=True)
        line = self.proc.stdout.readline()
        m = re.match(r"listening on (http://\S+)", line.strip())
        if not m:
            raise SystemExit(f"many_servers.py: a server did not start: {line!r} ({log})")
        self.url = m.group(1)
        threading.Thread(target=self.proc.stdout.read, daemon=True).start()

    def stop(self) -> None:
        self.proc.terminate()
        try:
            self.proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
        self.log.close()


def request(url: str, body: bytes | None = None) -> dict:
    req = urllib.request.Request(url, data=body, method="POST" if body is not None else "GET",
                                 headers={"Content-Type": "application/json"})
    with urllib.request.urlopen(req, timeout=30) as res:
        return json.loads(res.read())


def submit(url: str, n: int) -> str:
    spec = dict(SPEC, name=f"bench-{n}")
    return request(url + "/jobs", json.dumps(spec).encode())["jobID"]


def wait_all(url: str, ids: list[str], timeout: float) -> list[dict]:
    deadline = time.monotonic() + timeout
    docs = {}
    pending = list(ids)
    while pending:
        if time.monotonic() > deadline:
            raise SystemExit(f"many_servers.py: {len(pending)} jobs not done in {timeout} s")
        still = []
        for i in pending:
            doc = request(f"{url}/jobs/{i}")
            if doc["status"] in ("successful", "failed", "dismissed"):
                docs[i] = doc
            else:
                still.append(i)
        pending = still
        if pending:
            time.sleep(0.2)
    return [docs[i] for i in ids]


def run(base: str, servers: int, jobs: int, latency_jobs: int, work: Path) -> dict:
    schema = f"bench_{servers}_{os.getpid()}"
    uri = uri_with_schema(base, schema)
    data = work / schema
    data.mkdir()
    procs = [Server(uri, data, work / f"{schema}-{k}.log") for k in range(servers)]
    try:
        urls = [p.url for p in procs]
        time.sleep(1.5)  # every worker idle and polling
        # 2. claim latency first, on an idle queue
        latencies = []
        for n in range(latency_jobs):
            url = urls[n % servers]
            i = submit(url, n)
            doc = wait_all(url, [i], 30)[0]
            latencies.append(epoch(doc["started"]) - epoch(doc["created"]))
            time.sleep(0.05)
        # 1. throughput
        t0 = time.time()
        with ThreadPoolExecutor(4) as pool:
            ids = list(pool.map(lambda n: submit(urls[n % servers], n), range(jobs)))
        submitted_s = time.time() - t0
        docs = wait_all(urls[0], ids, 600)
        failed = [d for d in docs if d["status"] != "successful"]
        if failed:
            raise SystemExit(f"many_servers.py: {len(failed)} jobs did not succeed: {failed[0]}")
        last = max(epoch(d["finished"]) for d in docs)
        span = last - t0
        waits = sorted(epoch(d["started"]) - epoch(d["created"]) for d in docs)
        return {
            "servers": servers,
            "jobs": jobs,
            "submit_s": submitted_s,
            "span_s": span,
            "jobs_per_s": jobs / span,
            "claim_latency_ms_median": 1000 * statistics.median(latencies),
            "claim_latency_ms_p90": 1000 * sorted(latencies)[int(0.9 * (len(latencies) - 1))],
            "claim_latency_ms_max": 1000 * max(latencies),
            "queue_wait_ms_median_under_load": 1000 * statistics.median(waits),
        }
    finally:
        for p in procs:
            p.stop()


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--jobs", type=int, default=300)
    ap.add_argument("--latency-jobs", type=int, default=30)
    ap.add_argument("--out", help="also write the rows as JSON to this file")
    args = ap.parse_args()
    base = os.environ.get("HMPM_TEST_POSTGRES")
    if not base:
        print("many_servers.py: set HMPM_TEST_POSTGRES (scripts/postgres.sh run ...)",
              file=sys.stderr)
        return 2
    if not server_binary().exists():
        print(f"many_servers.py: no {server_binary()} (bash scripts/build.sh --target hmpm-server)",
              file=sys.stderr)
        return 2
    cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo")
                if l.startswith("model name")), "unknown")
    print(f"CPU: {cpu}, {os.cpu_count()} cores; load {os.getloadavg()[0]:.2f}")
    work = Path(tempfile.mkdtemp(prefix="hmpm-many-"))
    rows = []
    try:
        for servers in (1, 3):
            row = run(base, servers, args.jobs, args.latency_jobs, work)
            rows.append(row)
            print(f"{servers} server(s): {row['jobs']} jobs in {row['span_s']:.2f} s = "
                  f"{row['jobs_per_s']:.1f} jobs/s (submitted in {row['submit_s']:.2f} s); "
                  f"claim latency idle median {row['claim_latency_ms_median']:.1f} ms, "
                  f"p90 {row['claim_latency_ms_p90']:.1f} ms, max {row['claim_latency_ms_max']:.1f} ms; "
                  f"queue wait under load median {row['queue_wait_ms_median_under_load']:.0f} ms",
                  flush=True)
    finally:
        if os.environ.get("KEEP") is None:
            shutil.rmtree(work, ignore_errors=True)
    if args.out:
        Path(args.out).write_text(json.dumps(rows, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
