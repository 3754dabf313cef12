"""Hostile tests of the job store (hardening issue, items 1 and 8): a second
server on the same database, data folder or port; a data folder that cannot
be written; a database that cannot be written; zero-length and corrupt
database files."""

from __future__ import annotations

import re
import shutil
import tempfile
import threading
import unittest
from pathlib import Path
from urllib.parse import urlparse

from tests.hostile.jobs import KeptServer, run_server, verify_results, wait_status, submit
from tests.hostile.support import record
from tests.python.support import column_spec

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

        done = wait_status(first.url, job, ("successful", "failed", "dismissed"), 60)
        self.assertEqual(done["status"], "successful", done)
        self.assertEqual(done["attempts"], 1, "the job was started again")
        names = verify_results(first.url, job)
        self.assertIn("summary.json", names)
        log = (data / job / "job.log").read_text()
        self.assertEqual(log.count(" started on "), 1, log)
        record(item=1, faults=3, bad_inputs=0, requests=len(names) + 3, lost=0,
               intruders="same --db, same --data-dir, same --port: all refused")


if __name__ == "__main__":
    unittest.main()
