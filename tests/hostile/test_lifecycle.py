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

from tests.hostile.jobs import KeptServer, log_events, submit, wait_status
from tests.hostile.support import record
from tests.python.support import long_spec

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
        self.sock.sendall(b"GET /health HTTP/1.1\r\nHost: x\r\nX-Slow: ")
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


if __name__ == "__main__":
    unittest.main()
