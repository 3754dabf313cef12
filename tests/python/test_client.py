"""The hmpm_client library against a live hmpm-server (see support.py)."""

from __future__ import annotations

import hashlib
import io
import json
import os
import unittest
import uuid
from unittest import mock

from hmpm_client import Client, HmpmError

from .support import (JOB_TIMEOUT_S, LiveServerCase, bar_spec, column_spec, invalid_spec, long_spec,
                      quasi_static_column_spec, wait_until)


class ClientTest(LiveServerCase):
    def setUp(self):
        super().setUp()
        self.client = Client(self.server.url, token="")

    def run_small_job(self):
        job = self.client.submit(bar_spec(), idempotency_key=None)
        doc = job.wait(progress=False, timeout=JOB_TIMEOUT_S)
        self.assertEqual(doc["status"], "successful", f"{doc}\n{self.server.log_tail()}")
        return job

    def test_health(self):
        self.assertIsNotNone(self.client.health())

    def test_submit_returns_status_document(self):
        job = self.client.submit(bar_spec())
        self.assertTrue(job.id)
        self.assertIn(job.doc.get("status"), ("accepted", "running", "successful"))
        doc = job.status()
        self.assertEqual(doc["jobID"], job.id)
        for key in ("status", "progress", "created", "links"):
            self.assertIn(key, doc)
        job.wait(progress=False, timeout=JOB_TIMEOUT_S)

    def test_submit_keeps_the_spec_warnings(self):
        # A fluid 75 times softer than in column_spec: E_oed Q = 4, about 4 times
        # the u-p stability limit (rho - rho_f)/rho_f = 0.99 (docs/verification.md).
        spec = column_spec()
        spec["materials"]["clay"]["hydraulic"]["fluid_bulk_modulus"] = 1.0e6
        job = self.client.submit(spec)
        self.assertEqual([w["path"] for w in job.warnings], ["/materials/clay/hydraulic"])
        self.assertIn("What to change", job.warnings[0]["message"])
        job.wait(progress=False, timeout=JOB_TIMEOUT_S)
        # The bar is non-dimensional (E = 10 Pa, 1 kg/m3): only its two
        # documented plausibility warnings (docs/job-spec.md).
        self.assertEqual([w["path"] for w in self.client.submit(bar_spec()).warnings],
                         ["/materials/bar/youngs_modulus", "/materials/bar/density"])

    def test_spec_comes_back(self):
        spec = bar_spec()
        job = self.client.submit(spec)
        self.assertEqual(job.spec(), spec)
        job.wait(progress=False, timeout=JOB_TIMEOUT_S)

    def test_submit_from_path_and_text(self):
        path = self.tmp / "bar.json"
        path.write_text(json.dumps(bar_spec()))
        for spec in (str(path), path, path.read_text()):
            job = self.client.submit(spec)
            self.assertEqual(job.wait(progress=False, timeout=JOB_TIMEOUT_S)["status"], "successful")

    def test_wait_download_checks_every_file(self):
        job = self.run_small_job()
        self.assertEqual(job.doc.get("progress"), 100)
        manifest = job.results()
        names = {f["name"] for f in manifest}
        for required in ("summary.json", "series.json", "series.csv", "snapshots.pvd"):
            self.assertIn(required, names)
        self.assertTrue(any(n.endswith(".vtu") for n in names), names)
        written = job.download(self.tmp / "out")
        self.assertEqual(len(written), len(manifest))
        for f in manifest:
            data = (self.tmp / "out" / f["name"]).read_bytes()
            self.assertEqual(len(data), f["size"], f["name"])
            self.assertEqual(hashlib.sha256(data).hexdigest(), f["sha256"].lower(), f["name"])
        self.assertEqual(list((self.tmp / "out").rglob("*.part")), [])
        summary = json.loads((self.tmp / "out" / "summary.json").read_text())
        self.assertEqual(summary["status"], "successful")

    def test_series(self):
        job = self.run_small_job()
        series = job.series()
        times = series["time"]
        self.assertGreater(len(times), 10)
        self.assertEqual(sorted(p["index"] for p in series["particles"]), [0, 6, 12])
        for p in series["particles"]:
            self.assertEqual(len(p["displacement"]), len(times))
            self.assertEqual(len(p["velocity"]), len(times))

    def test_series_vectors_are_component_arrays(self):
        # CONTRACT.md, series.json: vectors as arrays of components, also in
        # 1D: "displacement": [[ux], ...].
        series = self.run_small_job().series()
        for p in series["particles"]:
            for field in ("displacement", "velocity"):
                self.assertIsInstance(p[field][0], list, f"{field} rows must be [ux], not a bare number")
                self.assertEqual(len(p[field][0]), 1)

    def test_results_not_ready(self):
        job = self.client.submit(long_spec())
        try:
            with self.assertRaises(HmpmError) as ctx:
                job.results()
            self.assertEqual(ctx.exception.status, 404)
            self.assertTrue(ctx.exception.type_is("result-not-ready"), ctx.exception.problem)
        finally:
            job.cancel()

    def test_invalid_spec_lists_every_path(self):
        with self.assertRaises(HmpmError) as ctx:
            self.client.submit(invalid_spec())
        err = ctx.exception
        self.assertIn(err.status, (400, 422))
        self.assertGreaterEqual(len(err.errors), 2, err.problem)
        text = str(err)
        for e in err.errors:
            self.assertIn(f"{e['path']}: {e['message']}", text)
        self.assertTrue(any("youngs_modulus" in e["path"] for e in err.errors), err.errors)
        self.assertTrue(any("/time" in e["path"] for e in err.errors), err.errors)

    def test_not_json_is_a_problem_document(self):
        with self.assertRaises(HmpmError) as ctx:
            self.client.submit(b"this is not json")
        self.assertEqual(ctx.exception.status, 400)
        self.assertTrue(ctx.exception.title)

    def test_unknown_job(self):
        with self.assertRaises(HmpmError) as ctx:
            self.client.job("no-such-job").status()
        self.assertEqual(ctx.exception.status, 404)

    def test_cancel_running_job(self):
        job = self.client.submit(long_spec())
        self.assertTrue(wait_until(lambda: job.status()["status"] == "running", 30),
                        f"job never ran: {job.doc}")
        doc = job.cancel()
        self.assertIn(doc["status"], ("running", "dismissed"))
        self.assertTrue(wait_until(lambda: job.status()["status"] == "dismissed", 10), job.doc)
        final = job.wait(progress=False, timeout=10)
        self.assertEqual(final["status"], "dismissed")

    def test_list_filter_and_limit(self):
        done = self.run_small_job()
        all_jobs = self.client.jobs()
        self.assertIn(done.id, [d["jobID"] for d in all_jobs])
        successful = self.client.jobs(status="successful")
        self.assertTrue(successful)
        self.assertTrue(all(d["status"] == "successful" for d in successful))
        self.assertEqual(len(self.client.jobs(limit=1)), 1)
        finished = self.client.jobs(status=["successful", "failed"], limit=1000)
        self.assertIn(done.id, [d["jobID"] for d in finished])
        with self.assertRaises(HmpmError) as ctx:
            self.client.jobs(status="no-such-state")
        self.assertEqual(ctx.exception.status, 400)

    def test_idempotency_key_returns_the_same_job(self):
        key = str(uuid.uuid4())
        first = self.client.submit(bar_spec(), idempotency_key=key)
        second = self.client.submit(bar_spec(), idempotency_key=key)
        self.assertEqual(first.id, second.id)
        self.assertFalse(first.replayed)
        self.assertTrue(second.replayed)
        first.wait(progress=False, timeout=JOB_TIMEOUT_S)

    def test_progress_bar_follows_events(self):
        out = io.StringIO()
        job = self.client.submit(column_spec(cells=60, end=0.51))  # about a second
        doc = job.wait(progress=True, timeout=JOB_TIMEOUT_S, file=out)
        self.assertEqual(doc["status"], "successful")
        text = out.getvalue()
        self.assertRegex(text, r"running .*%  t=[0-9.e-]+/0\.51 s  ETA ")
        self.assertIn(job.id[:8], text)
        self.assertIn("100%", text)
        self.assertIn("successful", text.splitlines()[-1])

    def test_progress_shows_the_servers_simulated_time(self):
        # Issue 44: the bar multiplied the estimated steps by the first step
        # (0.041 s here) instead of showing the run's own time (2 s).
        out = io.StringIO()
        job = self.client.submit(quasi_static_column_spec())
        doc = job.wait(progress=True, timeout=JOB_TIMEOUT_S, file=out)
        self.assertEqual(doc["status"], "successful", doc)
        run = doc["run"]
        self.assertEqual(run["end_time"], 2.0)
        self.assertAlmostEqual(run["simulated_time"], 2.0, places=9)
        summary = job.summary()
        self.assertEqual(run["steps"], summary["steps"])
        # dt range: the growing step's mean over each report lies in [1 ms, 0.1 s].
        self.assertGreaterEqual(run["dt_min"], 0.001 * (1 - 1e-9))
        self.assertLessEqual(run["dt_min"], 2.0 / run["steps"] * (1 + 1e-9))
        self.assertGreaterEqual(run["dt_max"], 2.0 / run["steps"] * (1 - 1e-9))
        self.assertLessEqual(run["dt_max"], 0.1 * (1 + 1e-9))
        self.assertIn("t=2/2 s", out.getvalue().splitlines()[-1])
        # A client that did not submit the spec reads the same from the server.
        out = io.StringIO()
        self.client.job(job.id).wait(progress=True, timeout=JOB_TIMEOUT_S, file=out)
        self.assertIn("t=2/2 s", out.getvalue().splitlines()[-1])

    def test_running_job_reports_simulated_time(self):
        job = self.client.submit(long_spec())  # t = 0..100 s in steps of 1e-5 s
        try:
            self.assertTrue(wait_until(lambda: "run" in job.status(), 30), f"no run in {job.doc}")
            run = job.doc["run"]
            self.assertEqual(job.doc["status"], "running")
            self.assertEqual(run["end_time"], 100.0)
            self.assertGreater(run["simulated_time"], 0.0)
            self.assertLess(run["simulated_time"], 100.0)
            # The stored percent and simulated time come from the same report.
            self.assertAlmostEqual(run["simulated_time"], job.doc["progress"], delta=1.0)
            self.assertAlmostEqual(run["steps"] * 1e-5, run["simulated_time"], delta=1e-3)
            self.assertAlmostEqual(run["dt_min"], 1e-5, delta=1e-12)
            self.assertAlmostEqual(run["dt_max"], 1e-5, delta=1e-12)
        finally:
            job.cancel()

    def test_polling_only(self):
        job = self.client.submit(bar_spec())
        doc = job.wait(progress=False, events=False, timeout=JOB_TIMEOUT_S, poll_interval=0.2)
        self.assertEqual(doc["status"], "successful")

    def test_wait_timeout_is_bounded(self):
        job = self.client.submit(long_spec())
        try:
            with self.assertRaises(TimeoutError):
                job.wait(progress=False, timeout=1.0)
        finally:
            job.cancel()


class DefaultWorkersTest(LiveServerCase):
    """Issue 44: with one worker by default, a slow job held every other job
    in the queue (an OGC execution waited 687 s)."""

    server_workers = None  # the server's default

    def setUp(self):
        super().setUp()
        self.client = Client(self.server.url, token="")

    def test_a_short_job_runs_beside_a_long_one(self):
        long = self.client.submit(long_spec())
        try:
            self.assertTrue(wait_until(lambda: long.status()["status"] == "running", 30), long.doc)
            short = self.client.submit(bar_spec())
            doc = short.wait(progress=False, timeout=60)
            self.assertEqual(doc["status"], "successful", doc)
            self.assertEqual(long.status()["status"], "running")
        finally:
            long.cancel()


class QueuePositionTest(LiveServerCase):
    server_workers = 1

    def setUp(self):
        super().setUp()
        self.client = Client(self.server.url, token="")

    def test_accepted_jobs_show_their_place_in_the_queue(self):
        long = self.client.submit(long_spec())
        waiting = []
        try:
            self.assertTrue(wait_until(lambda: long.status()["status"] == "running", 30), long.doc)
            self.assertNotIn("queue_position", long.doc)
            waiting = [self.client.submit(bar_spec()) for _ in range(3)]
            self.assertEqual([j.doc.get("queue_position") for j in waiting], [1, 2, 3])  # the 201s
            self.assertEqual([j.status().get("queue_position") for j in waiting], [1, 2, 3])
            listed = {d["jobID"]: d.get("queue_position") for d in self.client.jobs(status="accepted")}
            self.assertEqual([listed[j.id] for j in waiting], [1, 2, 3])
            waiting[0].cancel()
            self.assertEqual([j.status().get("queue_position") for j in waiting], [None, 1, 2])
        finally:
            # Cancelling `long` frees the worker, so a waiting bar job may
            # end between its status and its cancel (409: already ended).
            for job in [long] + waiting:
                if job.status()["status"] in ("accepted", "running"):
                    try:
                        job.cancel()
                    except HmpmError as e:
                        if e.status != 409:
                            raise


class TokenTest(LiveServerCase):
    TOKEN = server_token = "s3cret-" + uuid.uuid4().hex
    server_workers = 1

    def test_health_is_open(self):
        self.assertIsNotNone(Client(self.server.url, token="").health())

    def test_missing_and_wrong_token_are_refused(self):
        for token in ("", "wrong"):
            with self.assertRaises(HmpmError) as ctx:
                Client(self.server.url, token=token).jobs()
            self.assertEqual(ctx.exception.status, 401)

    def test_token_from_argument(self):
        client = Client(self.server.url, token=self.TOKEN)
        job = client.submit(bar_spec())
        self.assertEqual(job.wait(progress=False, timeout=JOB_TIMEOUT_S)["status"], "successful")
        self.assertTrue(job.download(self.tmp / "out"))

    def test_token_from_environment(self):
        with mock.patch.dict(os.environ, {"HMPM_TOKEN": self.TOKEN}):
            client = Client(self.server.url)
        self.assertEqual(client.token, self.TOKEN)
        self.assertIsInstance(client.jobs(), list)


class NoEventStreamsTest(LiveServerCase):
    server_args = ["--max-event-streams", "0"]

    def test_wait_falls_back_to_polling(self):
        client = Client(self.server.url)
        job = client.submit(bar_spec())
        with self.assertRaises(HmpmError) as ctx:
            client.open("GET", job.path + "/events").close()
        self.assertEqual(ctx.exception.status, 503)
        out = io.StringIO()
        doc = job.wait(progress=True, file=out, timeout=JOB_TIMEOUT_S, poll_interval=0.2)
        self.assertEqual(doc["status"], "successful")
        self.assertIn("100%", out.getvalue())


class QueueFullTest(LiveServerCase):
    server_args = ["--max-queue", "0"]

    def test_queue_full_is_an_error_with_retry_after(self):
        with self.assertRaises(HmpmError) as ctx:
            Client(self.server.url).submit(bar_spec())
        self.assertEqual(ctx.exception.status, 503)
        self.assertIn("retry after", str(ctx.exception))


if __name__ == "__main__":
    unittest.main()
