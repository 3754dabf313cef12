"""`python3 -m hmpm_client` against a live hmpm-server (see support.py)."""

from __future__ import annotations

import hashlib
import json
import subprocess
import tempfile
import unittest
import uuid
from pathlib import Path

from hmpm_client import Client

from .support import (CLIENT_DIR, JOB_TIMEOUT_S, REPO, LiveServerCase, ServerProcess, bar_spec, build_dir, column_spec,
                      invalid_spec, long_spec, run_cli, wait_until)


def have_matplotlib() -> bool:
    import importlib.util
    return importlib.util.find_spec("matplotlib") is not None


class CliTest(LiveServerCase):
    def write_spec(self, spec: dict, name: str = "spec.json") -> Path:
        path = self.tmp / name
        path.write_text(json.dumps(spec, indent=2))
        return path

    def cli(self, *args: str, **kw):
        return run_cli(["--url", self.server.url, *args], **kw)

    def submit_and_wait(self, spec: dict) -> str:
        r = self.cli("submit", str(self.write_spec(spec)), "--wait", "--quiet")
        self.assertEqual(r.returncode, 0, r.stderr)
        return r.stdout.strip()

    def test_submit_wait_download(self):
        out = self.tmp / "out"
        r = self.cli("submit", str(self.write_spec(bar_spec())), "--wait", "--download", str(out))
        self.assertEqual(r.returncode, 0, r.stderr + self.server.log_tail())
        job_id = r.stdout.strip().splitlines()[0]
        manifest = Client(self.server.url).job(job_id).results()
        self.assertTrue(manifest)
        for f in manifest:
            data = (out / f["name"]).read_bytes()
            self.assertEqual(hashlib.sha256(data).hexdigest(), f["sha256"].lower(), f["name"])
        # The progress bar went to stderr: percent, final state.
        self.assertIn("%", r.stderr)
        self.assertIn("100%", r.stderr)
        self.assertIn("successful", r.stderr)

    def test_stdin_results_download(self):
        r = self.cli("submit", "-", "--wait", "--quiet", input=json.dumps(bar_spec()))
        self.assertEqual(r.returncode, 0, r.stderr)
        job_id = r.stdout.strip()
        r = self.cli("results", job_id)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertRegex(r.stdout, r"(?m)^\s*\d+\s+[0-9a-f]{64}\s+series\.json$")
        r = self.cli("download", job_id, str(self.tmp / "dl"))
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertTrue((self.tmp / "dl" / "summary.json").is_file())
        self.assertIn("sha256 verified", r.stderr)

    def test_invalid_spec_exits_non_zero_with_paths(self):
        spec = self.write_spec(invalid_spec())
        r = self.cli("submit", str(spec), "--wait")
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertEqual(r.stdout.strip(), "")
        self.assertIn("/materials/bar/youngs_modulus", r.stderr)
        self.assertIn("/time", r.stderr)

    def test_failed_job_exits_3_with_reason_and_summary(self):
        spec = bar_spec()
        spec["bodies"][0]["initial"]["velocity"] = ["100"]  # the bar flies off the grid
        out = self.tmp / "out"
        r = self.cli("submit", str(self.write_spec(spec)), "--wait", "--quiet", "--download", str(out))
        self.assertEqual(r.returncode, 3, r.stderr)
        job_id = r.stdout.strip()
        self.assertIn(f"job {job_id} failed: ", r.stderr)
        reason = Client(self.server.url).job(job_id).status().get("reason", "")
        self.assertTrue(reason)
        self.assertIn(reason, r.stderr)
        summary = json.loads((out / "summary.json").read_text())
        self.assertEqual(summary["status"], "failed")

    def test_missing_spec_file(self):
        r = self.cli("submit", str(self.tmp / "nope.json"))
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("nope.json", r.stderr)

    def test_status_list_cancel(self):
        r = self.cli("submit", str(self.write_spec(long_spec())))
        self.assertEqual(r.returncode, 0, r.stderr)
        job_id = r.stdout.strip()
        r = self.cli("status", job_id)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(json.loads(r.stdout)["jobID"], job_id)
        r = self.cli("list", "--limit", "50")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn(job_id, r.stdout)
        r = self.cli("list", "--status", "successful", "--json")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertNotIn(job_id, r.stdout)
        self.assertTrue(all(d["status"] == "successful" for d in json.loads(r.stdout)))
        r = self.cli("cancel", job_id)
        self.assertEqual(r.returncode, 0, r.stderr)
        job = Client(self.server.url).job(job_id)
        self.assertTrue(wait_until(lambda: job.status()["status"] == "dismissed", 10), job.doc)
        r = self.cli("wait", job_id, "--quiet")
        self.assertEqual(r.returncode, 3)
        self.assertIn("dismissed", r.stderr)

    def test_cancel_of_a_finished_job_changes_nothing(self):
        job_id = self.submit_and_wait(bar_spec())
        job = Client(self.server.url).job(job_id)
        before = {f["name"]: f["sha256"] for f in job.results()}
        r = self.cli("cancel", job_id)
        self.assertEqual(r.returncode, 1, r.stderr)
        self.assertIn("already ended (successful)", r.stderr)
        self.assertIn("nothing was changed", r.stderr)
        self.assertEqual(job.status()["status"], "successful")
        self.assertEqual({f["name"]: f["sha256"] for f in job.results()}, before)
        r = self.cli("log", job_id)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertTrue(r.stdout.strip(), "the log of a finished job is empty")
        r = self.cli("delete", job_id)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("dismissed", r.stdout)

    def test_list_shows_and_filters_names(self):
        spec = bar_spec()
        spec["name"] = "named-" + uuid.uuid4().hex[:8]
        job_id = self.submit_and_wait(spec)
        self.submit_and_wait(bar_spec())
        r = self.cli("list", "--name", spec["name"])
        self.assertEqual(r.returncode, 0, r.stderr)
        lines = [l for l in r.stdout.splitlines() if l.strip()]
        self.assertEqual(len(lines), 1, r.stdout)
        self.assertIn(job_id, lines[0])
        self.assertIn(spec["name"], lines[0])

    @unittest.skipUnless(have_matplotlib(), "matplotlib is not installed (Debian: python3-matplotlib)")
    def test_plot_a_local_result_folder(self):
        job_id = self.submit_and_wait(column_spec())
        out = self.tmp / "local"
        r = self.cli("download", job_id, str(out))
        self.assertEqual(r.returncode, 0, r.stderr)
        png = self.tmp / "local.png"
        # No service needed: an unreachable --url must not matter.
        r = run_cli(["--url", "http://127.0.0.1:9", "plot", str(out), "--field", "pore_pressure",
                     "--out", str(png)], timeout=60)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(png.read_bytes()[:8], b"\x89PNG\r\n\x1a\n")
        r = run_cli(["plot", str(self.tmp), "--out", str(self.tmp / "none.png")], timeout=60)
        self.assertEqual(r.returncode, 1)
        self.assertIn("no series.json", r.stderr)

    @unittest.skipUnless(have_matplotlib(), "matplotlib is not installed (Debian: python3-matplotlib)")
    def test_plot_a_profile_of_a_local_result_folder(self):
        # The soft-clay example's isochrones (output.profiles), run by the
        # built `hmpm` (half a second), plotted with no service.
        out = self.tmp / "soft-clay"
        run = subprocess.run([str(build_dir() / "bin" / "hmpm"), "run",
                              str(REPO / "examples" / "soft-clay.json"), "--out", str(out)],
                             capture_output=True, text=True, timeout=120)
        self.assertEqual(run.returncode, 0, run.stderr)
        png = self.tmp / "isochrones.png"
        r = run_cli(["--url", "http://127.0.0.1:9", "plot", str(out), "--profile", "0",
                     "--field", "pore_pressure", "--out", str(png)], timeout=60)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(png.read_bytes()[:8], b"\x89PNG\r\n\x1a\n")
        r = run_cli(["plot", str(out), "--profile", "3", "--out", str(self.tmp / "x.png")], timeout=60)
        self.assertEqual(r.returncode, 1)
        self.assertIn("there is no line 3", r.stderr)
        r = run_cli(["plot", str(out), "--profile", "0", "--field", "strain",
                     "--out", str(self.tmp / "x.png")], timeout=60)
        self.assertEqual(r.returncode, 1)
        self.assertIn("it has: pore_pressure", r.stderr)
        # Its degree of consolidation (output.consolidation), likewise.
        png = self.tmp / "consolidation.png"
        r = run_cli(["--url", "http://127.0.0.1:9", "plot", str(out), "--consolidation",
                     "--out", str(png)], timeout=60)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(png.read_bytes()[:8], b"\x89PNG\r\n\x1a\n")
        r = run_cli(["plot", str(self.tmp), "--consolidation", "--out", str(self.tmp / "x.png")],
                    timeout=60)
        self.assertEqual(r.returncode, 1)
        self.assertIn("no consolidation.json", r.stderr)
        self.assertIn("output.consolidation", r.stderr)

    def test_status_takes_the_8_characters_the_progress_bar_prints(self):
        job_id = self.submit_and_wait(bar_spec())
        r = self.cli("status", job_id[:8])
        self.assertEqual(r.returncode, 0, r.stderr)
        doc = json.loads(r.stdout)
        self.assertEqual(doc["jobID"], job_id)
        # The non-dimensional bar's two plausibility warnings (docs/job-spec.md).
        self.assertEqual([w["path"] for w in doc["warnings"]],
                         ["/materials/bar/youngs_modulus", "/materials/bar/density"])
        r = self.cli("log", job_id[:8])
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("successful after", r.stdout)

    def test_unknown_job_status(self):
        r = self.cli("status", "no-such-job")
        self.assertEqual(r.returncode, 1)
        self.assertIn("404", r.stderr)

    def test_unreachable_server(self):
        r = run_cli(["--url", "http://127.0.0.1:9", "list"], timeout=30)
        self.assertEqual(r.returncode, 1)
        self.assertIn("cannot reach", r.stderr)

    @unittest.skipUnless(have_matplotlib(), "matplotlib is not installed (Debian: python3-matplotlib)")
    def test_plot_writes_png(self):
        job_id = self.submit_and_wait(column_spec())
        png = self.tmp / "pp.png"
        r = self.cli("plot", job_id, "--field", "pore_pressure", "--out", str(png))
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(png.read_bytes()[:8], b"\x89PNG\r\n\x1a\n")
        self.assertGreater(png.stat().st_size, 5000)
        r = self.cli("plot", job_id, "--field", "no_such_field", "--out", str(self.tmp / "x.png"))
        self.assertEqual(r.returncode, 1)
        self.assertIn("pore_pressure", r.stderr)

    def test_plot_without_matplotlib_names_the_debian_package(self):
        job_id = self.submit_and_wait(bar_spec())
        fake = self.tmp / "fake"
        (fake / "matplotlib").mkdir(parents=True)
        (fake / "matplotlib" / "__init__.py").write_text("raise ImportError('hidden for the test')\n")
        r = self.cli("plot", job_id, "--field", "displacement", "--out", str(self.tmp / "d.png"),
                     env={"PYTHONPATH": f"{fake}:{CLIENT_DIR}"})
        self.assertEqual(r.returncode, 4, r.stderr)
        self.assertIn("python3-matplotlib", r.stderr)


class CliTokenTest(LiveServerCase):
    TOKEN = server_token = "cli-" + uuid.uuid4().hex
    server_workers = 1

    def test_token_option_and_environment(self):
        url = self.server.url
        r = run_cli(["--url", url, "list"])
        self.assertEqual(r.returncode, 1)
        self.assertIn("401", r.stderr)
        r = run_cli(["--url", url, "--token", self.TOKEN, "list"])
        self.assertEqual(r.returncode, 0, r.stderr)
        r = run_cli(["--url", url, "list"], env={"HMPM_TOKEN": self.TOKEN})
        self.assertEqual(r.returncode, 0, r.stderr)


class AcceptanceExampleTest(unittest.TestCase):
    """The issue's acceptance command on examples/terzaghi.json."""

    def test_terzaghi_submit_wait_download(self):
        example = REPO / "examples" / "terzaghi.json"
        self.assertTrue(example.is_file(), f"{example} is missing")
        with ServerProcess(workers=1) as server, tempfile.TemporaryDirectory(prefix="hmpm-terzaghi-") as tmp:
            out = Path(tmp) / "out"
            r = run_cli(["--url", server.url, "submit", str(example), "--wait", "--download", str(out)],
                        timeout=JOB_TIMEOUT_S * 3)
            self.assertEqual(r.returncode, 0, r.stderr + server.log_tail())
            self.assertIn("%", r.stderr)
            names = {p.relative_to(out).as_posix() for p in out.rglob("*") if p.is_file()}
            for required in ("summary.json", "series.json", "series.csv", "snapshots.pvd"):
                self.assertIn(required, names)
            summary = json.loads((out / "summary.json").read_text())
            self.assertEqual(summary["status"], "successful")


if __name__ == "__main__":
    unittest.main()
