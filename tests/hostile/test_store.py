"""Hostile tests of the job store (hardening issue, items 1 and 8): a second
server on the same database, data folder or port; a data folder that cannot
be written; a database that cannot be written; zero-length and corrupt
database files."""

from __future__ import annotations

import copy
import hashlib
import json
import os
import re
import resource
import shutil
import tempfile
import threading
import time
import unittest
from pathlib import Path
from urllib.parse import urlparse

from tests.hostile.jobs import (KeptServer, get_json, log_events, request, run_server,
                                submit, verify_results, wait_status)
from tests.hostile.support import record
from tests.python.support import BAR_SPEC, column_spec, long_spec

# 100 particles to t = 2.5 s: about 5 s of work on one core (1.1 s to
# t = 0.51 s measured), so the job is still running while the three
# intruders start and fail (each about 1 s, most of it calibration).
RUNNING_SPEC = column_spec(cells=100, end=2.5)


class TwoServers(unittest.TestCase):
    """Item 1: a second server on the first one's database, data folder or
    port refuses to start, and the first one's running job is neither rerun
    nor deleted."""

    def setUp(self):
        self.tmp = Path(tempfile.mkdtemp(prefix="hmpm-hostile-store-"))
        self.addCleanup(shutil.rmtree, self.tmp, True)

    def test_second_server_refused(self):
        db, data = self.tmp / "a.sqlite", self.tmp / "a-results"
        first = KeptServer(db, data, workers=1).start()
        self.addCleanup(first.stop)
        port = urlparse(first.url).port
        job = submit(first.url, RUNNING_SPEC)
        wait_status(first.url, job, "running", 20)

        intruders = {
            "same --db": ["--db", str(db), "--data-dir", str(self.tmp / "b-results"), "--port", "0"],
            "same --data-dir": ["--db", str(self.tmp / "c.sqlite"), "--data-dir", str(data),
                                "--port", "0"],
            "same --port": ["--db", str(self.tmp / "d.sqlite"), "--data-dir",
                            str(self.tmp / "d-results"), "--port", str(port)],
        }
        expected = {
            "same --db": rf"database {re.escape(str(db))} is in use by another hmpm-server "
                         rf"\(pid {first.proc.pid}, lock file ",
            "same --data-dir": rf"data folder {re.escape(str(data))} is in use by another "
                               rf"hmpm-server \(pid {first.proc.pid}, lock file ",
            "same --port": rf"cannot listen on 127\.0\.0\.1:{port}",
        }
        results = {}

        def intrude(name):
            results[name] = run_server(intruders[name])

        # At once: all three meet the first server while its job runs.
        threads = [threading.Thread(target=intrude, args=(n,)) for n in intruders]
        for t in threads:
            t.start()
        for t in threads:
            t.join(30)
        for name, proc in results.items():
            with self.subTest(intruder=name):
                self.assertNotEqual(proc.returncode, 0, proc.stderr)
                self.assertRegex(proc.stderr, expected[name])
                self.assertNotIn("listening on", proc.stdout)
        self.assertEqual(len(results), 3)
        # The job was running all along (the intruders ended before it).
        status = wait_status(first.url, job, "running", 1)
        self.assertEqual(status["attempts"], 1)

        # About 5 s unloaded; the bound leaves room for a busy machine.
        done = wait_status(first.url, job, ("successful", "failed", "dismissed"), 120)
        self.assertEqual(done["status"], "successful", done)
        self.assertEqual(done["attempts"], 1, "the job was started again")
        names = verify_results(first.url, job)
        self.assertIn("summary.json", names)
        log = (data / job / "job.log").read_text()
        self.assertEqual(log.count(" started on "), 1, log)
        record(item=1, faults=3, bad_inputs=0, requests=len(names) + 3, lost=0,
               intruders="same --db, same --data-dir, same --port: all refused")



def set_file_size_limit(pid: int, limit: int) -> None:
    """Sets the soft RLIMIT_FSIZE of process `pid` (the hard limit stays, so
    any user can raise it again). hmpm-server ignores SIGXFSZ: a write past
    the limit fails with EFBIG, as on a full disk. Works as root too, where
    a read-only folder would not stop a write."""
    _, hard = resource.prlimit(pid, resource.RLIMIT_FSIZE)
    resource.prlimit(pid, resource.RLIMIT_FSIZE, (limit, hard))


def lift_file_size_limit(pid: int) -> None:
    _, hard = resource.prlimit(pid, resource.RLIMIT_FSIZE)
    resource.prlimit(pid, resource.RLIMIT_FSIZE, (hard, hard))


def snapshot_spec() -> dict:
    """A bar of 4800 particles at rest, 50 000 steps (about 6 s on one core:
    2 000 steps took 0.25 s), a snapshot of about 1.5 MB every 0.25 s of
    simulated time: the first at once, the second about 3 s later."""
    spec = copy.deepcopy(BAR_SPEC)
    spec["name"] = "hostile-snapshots"
    spec["grid"] = {"min": [0.0], "max": [1.2], "cells": [4800]}
    spec["time"] = {"end": 0.5, "dt": 1.0e-5}
    spec["output"] = {"snapshots": {"interval": 0.25},
                      "series": {"particles": [0], "fields": ["displacement"], "interval": 0.05}}
    return spec


def wait_for(predicate, timeout: float, what: str):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = predicate()
        if value:
            return value
        time.sleep(0.02)
    raise AssertionError(f"not within {timeout} s: {what}")


class DiskFull(unittest.TestCase):
    """Item 8: result files and database writes that fail for want of space;
    empty and damaged database files at start-up."""

    def setUp(self):
        self.tmp = Path(tempfile.mkdtemp(prefix="hmpm-hostile-disk-"))
        self.addCleanup(shutil.rmtree, self.tmp, True)

    def test_failed_result_write_leaves_no_invisible_files(self):
        data = self.tmp / "results"
        server = KeptServer(self.tmp / "db.sqlite", data, workers=1,
                            extra=["--threads-per-job", "1"]).start()
        self.addCleanup(server.stop)
        job = submit(server.url, snapshot_spec())
        # Once the first snapshot (1.5 MB) is complete, no file may grow past
        # 1 MB: the second snapshot fails; the database, the logs and small
        # results stay well below that.
        # The job's folder: its log and the folder of its one attempt (claim 1).
        attempt = data / job / "attempt-1"
        wait_for(lambda: (attempt / "snapshot_0000.vtu").is_file(), 30, "first snapshot")
        set_file_size_limit(server.proc.pid, 1 << 20)
        self.addCleanup(lambda: server.proc.poll() is None and lift_file_size_limit(server.proc.pid))
        doc = wait_status(server.url, job, ("successful", "failed", "dismissed"), 60)
        self.assertEqual(doc["status"], "failed", doc)
        self.assertIn("could not write results", doc["message"])
        names = verify_results(server.url, job)
        self.assertEqual(names, ["summary.json"])
        self.assertEqual(sorted(p.name for p in (data / job).iterdir()), ["attempt-1", "job.log"])
        on_disk = sorted(p.name for p in attempt.iterdir())
        self.assertEqual(on_disk, ["summary.json"], "files the manifest does not list")
        summary = json.loads((attempt / "summary.json").read_text())
        self.assertEqual(summary["status"], "failed")
        self.assertEqual(summary["files"], ["summary.json"])
        # The next job, still under the limit, runs: nothing of the failed
        # one is in its way.
        after = submit(server.url, BAR_SPEC)
        self.assertEqual(wait_status(server.url, after, ("successful", "failed"), 60)["status"],
                         "successful")
        self.assertIn("summary.json", verify_results(server.url, after))
        record(item=8, faults=1, bad_inputs=0, requests=4, lost=0,
               fault="result file past RLIMIT_FSIZE (EFBIG)", left_files=len(on_disk))

    def test_database_write_failure_is_visible_and_recovered(self):
        db = self.tmp / "db.sqlite"
        # The job below runs for minutes; the wall-time limit ends it after
        # 4 s whatever the machine's load, while the database is unwritable.
        server = KeptServer(db, workers=1,
                            extra=["--threads-per-job", "1", "--job-wall-time", "4"]).start()
        self.addCleanup(server.stop)
        for _ in range(5):  # some history, so the WAL is larger than the logs
            warm = submit(server.url, BAR_SPEC)
        wait_status(server.url, warm, "successful", 60)
        job = submit(server.url, long_spec())
        wait_status(server.url, job, "running", 20)
        wal = Path(str(db) + "-wal")
        log_size = (server.tmp / "server.log").stat().st_size
        wal_size = wal.stat().st_size
        # The WAL only grows in a run this short (no checkpoint before 4 MB):
        # every database write is past this limit; the log and the job's
        # small result files (tens of kB) are not.
        self.assertGreater(wal_size, 2 * log_size + 200_000, "WAL too small for the limit")
        set_file_size_limit(server.proc.pid, wal_size)
        lifted = False
        try:
            # The write probe runs at most once a second: 503 within 5 s.
            health = wait_for(lambda: (lambda r: r if r[0] == 503 else None)(
                request(server.url + "/health")), 5, "/health 503 while the database is unwritable")
            self.assertEqual(json.loads(health[2])["detail"],
                             "no space left: the database cannot be written")
            self.assertIn("Retry-After", health[1])
            code, headers, body = request(server.url + "/jobs", "POST", json.dumps(BAR_SPEC).encode())
            # A file-size limit is a want of space: 507, not a bare 500.
            self.assertEqual(code, 507, body)
            self.assertEqual(headers.get("Retry-After"), "10")
            self.assertTrue(headers.get("Content-Type", "").startswith("application/problem+json"))
            self.assertEqual(json.loads(body)["type"], "insufficient-storage")
            # The job's end cannot be recorded: retried, not given up.
            wait_for(lambda: [e for e in log_events(server)
                              if e.get("event") == "store_error" and e.get("during") == "finish"
                              and e.get("attempt", 0) >= 2], 60, "finish retried")
            self.assertEqual(get_json(f"{server.url}/jobs/{job}")[1]["status"], "running")
            lift_file_size_limit(server.proc.pid)
            lifted = True
        finally:
            if not lifted:
                lift_file_size_limit(server.proc.pid)
        # Within the backoff's longest wait (5 s) and a margin, it ends, as
        # it would have without the fault: failed at its wall-time limit, its
        # summary.json (small, written under the limit) in its manifest.
        doc = wait_status(server.url, job, ("successful", "failed"), 15)
        self.assertEqual(doc["status"], "failed", doc)
        self.assertIn("wall-time limit", doc["message"])
        self.assertEqual(verify_results(server.url, job), ["series.csv", "series.json",
                                                           "summary.json"])
        wait_for(lambda: request(server.url + "/health")[0] == 200, 5, "/health 200 again")
        again = submit(server.url, BAR_SPEC)
        self.assertEqual(wait_status(server.url, again, ("successful", "failed"), 60)["status"],
                         "successful")
        record(item=8, faults=1, bad_inputs=1, requests=6, lost=0,
               fault="database writes past RLIMIT_FSIZE (507 to POST, /health 503)")

    def test_empty_and_damaged_databases_refused(self):
        empty = self.tmp / "empty.sqlite"
        empty.write_bytes(b"")
        proc = run_server(["--db", str(empty), "--port", "0"])
        self.assertNotEqual(proc.returncode, 0)
        self.assertIn("is an empty file (0 bytes)", proc.stderr)
        self.assertEqual(empty.stat().st_size, 0)

        db = self.tmp / "db.sqlite"
        server = KeptServer(db, workers=1).start()
        for _ in range(20):
            last = submit(server.url, BAR_SPEC)
        wait_status(server.url, last, "successful", 60)
        server.stop()  # a clean stop: the WAL is checkpointed into the file
        size = db.stat().st_size
        self.assertGreater(size, 8 * 4096)
        damaged = bytearray(db.read_bytes())
        damaged[4096:size] = b"\x5a" * (size - 4096)  # every page after the header's
        db.write_bytes(bytes(damaged))
        digest = hashlib.sha256(db.read_bytes()).hexdigest()
        proc = run_server(["--db", str(db), "--port", "0"])
        self.assertNotEqual(proc.returncode, 0)
        self.assertNotIn("listening on", proc.stdout)
        self.assertRegex(proc.stderr, r"database .* (is damaged|cannot be opened)")
        self.assertIn("restore it from a backup", proc.stderr)
        self.assertEqual(hashlib.sha256(db.read_bytes()).hexdigest(), digest, "file changed")
        record(item=8, faults=2, bad_inputs=0, requests=21, lost=0,
               fault="zero-length and garbled database files")


if __name__ == "__main__":
    unittest.main()
