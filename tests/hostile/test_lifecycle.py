"""Hostile tests of the server's life cycle (hardening issue, items 3 and
11): SIGTERM with a trickling client and running jobs; the attempt limit
after crashes that were not a job's fault; NaN from a load formula at run
time; job names with control and bidirectional characters."""

from __future__ import annotations

import json
import shutil
import signal
import socket
import sqlite3
import tempfile
import threading
import time
import unittest
from pathlib import Path
from urllib.parse import urlparse

from tests.hostile.jobs import KeptServer, log_events, request, submit, wait_status
from tests.hostile.support import LiveServerCase, record
from tests.python.support import bar_spec, long_spec

# The bound: SIGTERM ends the process within 10 s. The server gives
# connections a 5 s drain (ServiceConfig::shutdown_drain_s), so 10 s leaves
# 5 s for the workers to stop their jobs (one solver step each) and requeue.
EXIT_BOUND_S = 10.0


def jobs_in(db: Path) -> dict:
    """id -> (status, attempts) as the database holds them (server stopped)."""
    with sqlite3.connect(str(db)) as conn:
        return {row[0]: (row[1], row[2]) for row in
                conn.execute("SELECT id, status, attempts FROM jobs ORDER BY seq")}


class Trickler(threading.Thread):
    """A client sending one byte of a request head per second, for ever."""

    def __init__(self, url: str):
        super().__init__(daemon=True)
        u = urlparse(url)
        self.sock = socket.create_connection((u.hostname, u.port), timeout=5)
        self.sock.sendall(b"GET /health HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Slow: ")
        self.sent = 0
        self.cut = threading.Event()
        self.done = threading.Event()

    def run(self):
        while not self.done.wait(1.0):
            try:
                self.sock.sendall(b"a")
                self.sent += 1
            except OSError:
                self.cut.set()
                return

    def close(self):
        self.done.set()
        self.sock.close()


class Sigterm(unittest.TestCase):
    """Item 3: SIGTERM with a trickling client and running jobs."""

    def setUp(self):
        self.tmp = Path(tempfile.mkdtemp(prefix="hmpm-hostile-life-"))
        self.addCleanup(shutil.rmtree, self.tmp, True)

    def test_sigterm_exits_requeues_and_claims_nothing(self):
        db = self.tmp / "db.sqlite"
        server = KeptServer(db, workers=2).start()
        self.addCleanup(server.stop)
        running = [submit(server.url, long_spec()) for _ in range(2)]
        for job in running:
            wait_status(server.url, job, "running", 20)
        queued = submit(server.url, long_spec())
        trickler = Trickler(server.url)
        trickler.start()
        self.addCleanup(trickler.close)
        # The trickler is being read by a connection thread before the signal.
        deadline = time.monotonic() + 5
        while trickler.sent < 2 and time.monotonic() < deadline:
            time.sleep(0.1)
        self.assertGreaterEqual(trickler.sent, 2)
        self.assertFalse(trickler.cut.is_set())

        t0 = time.monotonic()
        server.proc.send_signal(signal.SIGTERM)
        try:
            rc = server.proc.wait(timeout=EXIT_BOUND_S + 20)
        except Exception:
            self.fail(f"hmpm-server still running {EXIT_BOUND_S + 20} s after SIGTERM\n"
                      f"{server.log_tail()}")
        elapsed = time.monotonic() - t0
        self.assertLess(elapsed, EXIT_BOUND_S, server.log_tail())
        self.assertEqual(rc, 0, server.log_tail())

        events = log_events(server)
        starts = [e["job"] for e in events if e.get("event") == "job" and e.get("status") == "running"]
        self.assertEqual(sorted(starts), sorted(running), "a job was claimed after the signal")
        requeued = [e["job"] for e in events if e.get("event") == "job" and e.get("requeued")]
        self.assertEqual(sorted(requeued), sorted(running))
        # The store: both back in the queue with the attempt not counted, the
        # queued one never started.
        rows = jobs_in(db)
        for job in running + [queued]:
            self.assertEqual(rows[job], ("accepted", 0), job)

        # A restarted server runs them, oldest first.
        again = KeptServer(db, workers=2).start()
        self.addCleanup(again.stop)
        for job in running:
            doc = wait_status(again.url, job, "running", 20)
            self.assertEqual(doc["attempts"], 1)
        again.stop()
        record(item=3, faults=1, bad_inputs=1, requests=0, lost=0,
               exit_seconds=round(elapsed, 1), requeued=len(requeued),
               claimed_after_signal=len(starts) - len(running))



class UnrelatedCrashes(unittest.TestCase):
    """Item 11 (a): jobs claimed just before crashes that are not theirs
    (kill -9 about a second into their attempts) are not failed by the
    attempt limit (3)."""

    CRASHES = 4  # one more than --max-attempts

    def setUp(self):
        self.tmp = Path(tempfile.mkdtemp(prefix="hmpm-hostile-crash-"))
        self.addCleanup(shutil.rmtree, self.tmp, True)

    def test_innocent_jobs_survive_more_crashes_than_the_limit(self):
        db = self.tmp / "db.sqlite"
        server = KeptServer(db, workers=2).start()
        self.addCleanup(server.stop)
        heads = [submit(server.url, long_spec()) for _ in range(2)]
        waiting = [submit(server.url, long_spec()) for _ in range(2)]
        for crash in range(1, self.CRASHES + 1):
            for job in heads:
                doc = wait_status(server.url, job, "running", 20)
                self.assertEqual(doc["attempts"], crash)
            # Well under --charge-after (30 s): the attempts are too young to
            # be the suspects of the crash.
            time.sleep(1.0)
            server.proc.kill()
            server.proc.wait(10)
            server.stop()
            server = KeptServer(db, workers=2).start()
            self.addCleanup(server.stop)
        for job in heads:
            doc = wait_status(server.url, job, ("running", "failed"), 20)
            self.assertEqual(doc["status"], "running", doc)
            self.assertEqual(doc["attempts"], self.CRASHES + 1)
        for job in waiting:  # never started, never charged
            doc = wait_status(server.url, job, "accepted", 5)
            self.assertEqual(doc["attempts"], 0)
        record(item=11, faults=self.CRASHES, bad_inputs=0, requests=0, lost=0,
               case=f"{self.CRASHES} kill -9 one second into the attempts of 2 jobs: none failed")


def nan_between_samples(center: float) -> str:
    """A formula that is NaN only for |t - center| < 1e-4: validation samples
    [0, 0.5] every 0.5 ms (1001 instants), so with center = k * 0.5 ms +
    0.15 ms no sample falls inside; the run's 10 us steps do."""
    return f"1e-3*sqrt((t-{center})^2-1e-8)"


class FormulasAndNames(LiveServerCase):
    """Item 11 (b, c): NaN from a load formula at run time is reported as the
    formula's; job names with control or bidirectional characters are
    refused at submit."""

    server_workers = 2

    def test_nan_from_a_formula_names_the_formula(self):
        traction = bar_spec(end=0.5, dt=1.0e-5)
        traction["tractions"] = [{"particles": {"box": {"min": [0.9], "max": [1.0]}}, "face": "x+",
                                  "traction": [nan_between_samples(0.10015)]}]
        boundary = bar_spec(end=0.5, dt=1.0e-5)
        boundary["boundaries"][0]["velocity"] = ["0*" + nan_between_samples(0.20015)]
        cases = {"/tractions/0/traction/0": (traction, "0.10"),
                 "/boundaries/0/velocity/0": (boundary, "0.20")}
        for path, (spec, when) in cases.items():
            with self.subTest(path=path):
                job = submit(self.server.url, spec)
                doc = wait_status(self.server.url, job, ("successful", "failed"), 60)
                self.assertEqual(doc["status"], "failed", doc)
                message = doc["message"]
                self.assertIn(f"the formula at {path} gave NaN at t = {when}", message)
                self.assertNotIn("volume", message)
                self.assertNotIn("reduce time.dt", message)
        # A formula that is NaN everywhere ("0/0", sqrt(-1)) never runs: 400 at submit.
        refused = 0
        for formula in ("0/0", "sqrt(-1)", "sqrt(t-1)"):
            spec = bar_spec()
            spec["tractions"] = [{"particles": {"box": {"min": [0.9], "max": [1.0]}},
                                  "face": "x+", "traction": [formula]}]
            code, _, body = request(self.server.url + "/jobs", "POST", json.dumps(spec).encode())
            self.assertEqual(code, 400, body)
            errors = json.loads(body)["errors"]
            self.assertIn("/tractions/0/traction/0", [e["path"] for e in errors], errors)
            refused += 1
        record(item=11, faults=0, bad_inputs=len(cases) + refused, requests=len(cases) + refused,
               lost=0, case="NaN from traction and boundary formulas")

    def test_names_with_control_or_bidi_characters_refused(self):
        names = {"nul": "a\u0000b", "newline": "run\nfake log line", "escape": "\u001b[31mred",
                 "c1": "a\u0085b", "rlo": "invoice\u202efdp.exe", "isolate": "x\u2067y",
                 "lrm": "a\u200eb", "alm": "a\u061cb"}
        for what, name in names.items():
            with self.subTest(name=what):
                spec = bar_spec()
                spec["name"] = name
                code, _, body = request(self.server.url + "/jobs", "POST",
                                        json.dumps(spec).encode())
                self.assertEqual(code, 400, body)
                errors = json.loads(body)["errors"]
                self.assertEqual([e["path"] for e in errors], ["/name"], errors)
                self.assertIn("remove it", errors[0]["message"])
        # Letters of any script, punctuation and emoji stay allowed.
        spec = bar_spec()
        spec["name"] = "Böschung – Bemessung 斜面 🙂"
        job = submit(self.server.url, spec)
        doc = wait_status(self.server.url, job, ("successful", "failed"), 60)
        self.assertEqual(doc["name"], spec["name"])
        record(item=11, faults=0, bad_inputs=len(names), requests=len(names) + 1, lost=0,
               case="job names with NUL, control and bidi characters")


if __name__ == "__main__":
    unittest.main()
