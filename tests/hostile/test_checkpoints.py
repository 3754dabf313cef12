"""Hostile tests of issue 45 (the second hardening campaign), item 8: an
unreadable checkpoint path. Before, a directory in place of the recorded
checkpoint file threw out of the attempt's preparation (libstdc++'s
"error reading the file: Is a directory") and left the job running on no
worker; a symlink to /dev/zero was read for ever (memory without bound)
and a FIFO blocked the worker in open(), so the job stayed running and
SIGTERM did not stop the server.

Three long jobs checkpoint every 0.5 s; the server is killed (kill -9);
each job's recorded checkpoint file is replaced by one of the three; on
restart every job must start again from step 0 within a minute, with the
reason in its log, and SIGTERM must then stop the server within 10 s.
"""

from __future__ import annotations

import os
import shutil
import signal
import sqlite3
import tempfile
import threading
import time
import unittest
from pathlib import Path

from tests.hostile.jobs import KeptServer, get_json, submit, wait_status
from tests.hostile.support import record
from tests.python.support import long_spec

ISSUE = 45
RESTART_BOUND_S = 60.0  # the issue's bound: step 0 (or failed with the reason) within a minute
EXIT_BOUND_S = 10.0  # SIGTERM ends the process within 10 s
RSS_LIMIT_KIB = 1 << 20  # 1 GiB: reading /dev/zero for ever passes it within seconds


def recorded_checkpoints(db: Path) -> dict:
    """job id -> its recorded checkpoint file (relative to the job's folder)."""
    with sqlite3.connect(str(db)) as conn:
        return dict(conn.execute("SELECT job_id, file FROM checkpoints"))


def rss_kib(pid: int) -> int:
    try:
        with open(f"/proc/{pid}/status") as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1])
    except OSError:
        pass
    return 0


class MemoryWatch(threading.Thread):
    """Kills the server (kill -9) if its RSS passes RSS_LIMIT_KIB, so that a
    server reading /dev/zero fails the test instead of the machine."""

    def __init__(self, proc):
        super().__init__(daemon=True)
        self.proc = proc
        self.peak = 0
        self.killed = False
        self.done = threading.Event()

    def run(self):
        while not self.done.wait(0.1) and self.proc.poll() is None:
            self.peak = max(self.peak, rss_kib(self.proc.pid))
            if self.peak > RSS_LIMIT_KIB:
                self.killed = True
                self.proc.kill()
                return


def plant(path: Path, variant: str) -> None:
    """Puts `variant` where the checkpoint file `path` was."""
    path.unlink()
    if variant == "directory":
        path.mkdir()
        (path / "inside").write_bytes(b"x")  # not empty: remove() cannot take it away
    elif variant == "symlink to /dev/zero":
        path.symlink_to("/dev/zero")
    else:
        os.mkfifo(path)


class UnreadableCheckpoint(unittest.TestCase):
    VARIANTS = {"directory": "is a directory", "symlink to /dev/zero": "is a character device",
                "FIFO": "is a FIFO"}

    def setUp(self):
        self.tmp = Path(tempfile.mkdtemp(prefix="hmpm-hostile-ckpt-"))
        self.addCleanup(shutil.rmtree, self.tmp, True)

    def test_directory_dev_zero_and_fifo_restart_from_step_0(self):
        db, data = self.tmp / "db.sqlite", self.tmp / "results"
        extra = ["--threads-per-job", "1", "--checkpoint-interval", "0.5"]
        server = KeptServer(db, data, workers=3, extra=extra).start()
        self.addCleanup(server.stop)
        jobs = {variant: submit(server.url, long_spec()) for variant in self.VARIANTS}
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline and len(recorded_checkpoints(db).keys() & set(jobs.values())) < 3:
            time.sleep(0.1)
        server.proc.kill()  # kill -9: the jobs stay running in the database
        server.proc.wait(10)
        server.stop()
        files = recorded_checkpoints(db)
        for variant, job in jobs.items():
            self.assertIn(job, files, f"no checkpoint recorded for {variant} within 30 s")
            plant(data / job / files[job], variant)

        again = KeptServer(db, data, workers=3, extra=extra).start()
        self.addCleanup(lambda: again.proc.poll() is None and again.proc.kill())
        self.addCleanup(again.stop)
        watch = MemoryWatch(again.proc)
        watch.start()
        self.addCleanup(watch.done.set)
        start = time.monotonic()
        logs = {variant: data / job / "job.log" for variant, job in jobs.items()}

        def restarted():
            return {v for v, log in logs.items() if "starting from step 0" in log.read_text()}

        while (time.monotonic() - start < RESTART_BOUND_S and not watch.killed
               and again.proc.poll() is None and len(restarted()) < len(jobs)):
            time.sleep(0.1)
        restarted_s = time.monotonic() - start
        # Before: the directory's job stayed running on no worker, the FIFO's
        # worker blocked in open(), /dev/zero was read until memory ran out.
        self.assertFalse(watch.killed, f"RSS past {RSS_LIMIT_KIB} KiB: reading /dev/zero?")
        missing = {v: logs[v].read_text()[-600:] for v in jobs if v not in restarted()}
        self.assertEqual(missing, {}, f"not started again from step 0 within {RESTART_BOUND_S} s")
        reasons = {}
        for variant, job in jobs.items():
            line = next(l for l in logs[variant].read_text().splitlines() if "not usable" in l)
            self.assertIn(files[job] + " " + self.VARIANTS[variant], line)
            reasons[variant] = line.split("not usable (", 1)[1].split(")")[0]
            doc = wait_status(again.url, job, "running", 10)
            self.assertEqual(doc["attempts"], 2, doc)
        self.assertEqual(get_json(again.url + "/health")[0], 200)

        # Every worker runs a job: SIGTERM stops them and the server in time.
        t0 = time.monotonic()
        again.proc.send_signal(signal.SIGTERM)
        try:
            code = again.proc.wait(EXIT_BOUND_S + 5)
        except Exception:  # noqa: BLE001 (TimeoutExpired: reported below)
            code = None
        took = time.monotonic() - t0
        self.assertEqual(code, 0, f"SIGTERM: exit code {code} after {took:.1f} s")
        self.assertLess(took, EXIT_BOUND_S)
        with sqlite3.connect(str(db)) as conn:
            statuses = dict(conn.execute("SELECT id, status FROM jobs"))
        self.assertEqual(sorted(statuses.values()), ["accepted"] * 3, statuses)
        record(issue=ISSUE, item=8, faults=3 + 1, bad_inputs=3, lost=0,
               restarted_from_step_0_s=round(restarted_s, 1), sigterm_exit_s=round(took, 1),
               peak_rss_mib=round(watch.peak / 1024), reasons="; ".join(reasons.values()))


if __name__ == "__main__":
    unittest.main()
