"""Checkpointed jobs survive crashes (issue 20, checkpoint acceptance).

A real hmpm-server with `--checkpoint-interval 1` runs a job of about ten
seconds; the test SIGKILLs the server twice mid-run and starts it again on
the same database and data folder, then stops it once with SIGTERM (the run
checkpoints where it stops) and starts it again. The job must end `successful` with
result files identical (SHA-256) to an uninterrupted run of the same spec on
a server without checkpoints — summary.json compared without its wall-time
fields — and each restart may repeat at most one checkpoint interval of
work. The figures (checkpoint size and write time, steps repeated per kill)
are printed.

Run: HMPM_BUILD_DIR=$PWD/build python3 -m unittest tests/python/test_checkpoint.py -v
"""

from __future__ import annotations

import copy
import datetime
import hashlib
import json
import os
import queue
import re
import shutil
import signal
import subprocess
import tempfile
import threading
import time
import unittest
import urllib.request
from pathlib import Path
from typing import List, Optional, Tuple

try:
    from tests.python.support import BAR_SPEC, server_binary
except ImportError:  # run from tests/python
    from support import BAR_SPEC, server_binary  # type: ignore

INTERVAL_S = 1.0  # --checkpoint-interval of the interrupted server
# The vibrating bar, 4000 particles, 150 000 steps of 1e-5 s: 7-15 s at one
# solver thread on this machine (HMPM_CHECKPOINT_TEST_END scales it).
END_S = float(os.environ.get("HMPM_CHECKPOINT_TEST_END", "1.5"))
# When to kill: the first progress report past each threshold, plus a delay
# (a fraction of the interval: progress is stored on the same one-second
# beat as the checkpoints are taken, so killing at the report would always
# find a fresh checkpoint and repeat almost nothing).
KILLS = ((30.0, 0.45 * INTERVAL_S), (65.0, 0.85 * INTERVAL_S))
WALL_FIELDS = ("solve_seconds", "particle_steps_per_second")


def spec(end: float = END_S) -> dict:
    s = copy.deepcopy(BAR_SPEC)
    s["name"] = "pytest-checkpoint"
    s["grid"] = {"min": [0.0], "max": [1.2], "cells": [2400]}  # room for the free end
    s["bodies"][0]["particles_per_cell"] = 2
    s["time"] = {"end": end, "dt": 1.0e-5}
    s["output"] = {
        "series": {"particles": [0, 1999, 3999], "fields": ["displacement", "velocity"],
                   "interval": end / 200},
        "snapshots": {"interval": end / 6},
    }
    return s


def utc(text: str) -> float:
    """Seconds since the epoch of an RFC 3339 UTC timestamp."""
    return datetime.datetime.fromisoformat(text.replace("Z", "+00:00")).timestamp()


class Server:
    """hmpm-server on a fixed database and data folder, restartable."""

    def __init__(self, folder: Path, extra: List[str]):
        self.folder = folder
        self.extra = extra
        self.proc: Optional[subprocess.Popen] = None
        self.url = ""
        self.log = open(folder / "server.log", "a")

    def start(self) -> None:
        cmd = [str(server_binary()), "--host", "127.0.0.1", "--port", "0",
               "--db", str(self.folder / "db.sqlite"), "--data-dir", str(self.folder / "results"),
               "--workers", "1", "--threads-per-job", "1", "--max-attempts", "10"] + self.extra
        env = dict(os.environ)
        env.pop("HMPM_TOKEN", None)
        self.proc = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                     stderr=self.log, text=True, bufsize=1, env=env)
        first: "queue.Queue[str]" = queue.Queue()

        def pump(p: subprocess.Popen) -> None:
            assert p.stdout
            for line in p.stdout:
                first.put(line)
            first.put("")

        threading.Thread(target=pump, args=(self.proc,), daemon=True).start()
        line = first.get(timeout=20)
        m = re.match(r"listening on (http://\S+)", line.strip())
        assert m, f"unexpected first line from hmpm-server: {line!r}"
        self.url = m.group(1).rstrip("/")

    def kill(self, sig: int = signal.SIGKILL) -> None:
        assert self.proc
        self.proc.send_signal(sig)
        self.proc.wait(timeout=10)
        self.proc.stdout.close()

    def stop(self) -> None:
        if self.proc and self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait(timeout=10)
        if self.proc and self.proc.stdout and not self.proc.stdout.closed:
            self.proc.stdout.close()
        self.log.close()

    def get(self, path: str) -> bytes:
        with urllib.request.urlopen(self.url + path, timeout=10) as r:
            return r.read()

    def json(self, path: str) -> dict:
        return json.loads(self.get(path))

    def submit(self, body: dict) -> str:
        req = urllib.request.Request(self.url + "/jobs", data=json.dumps(body).encode(),
                                     headers={"Content-Type": "application/json"}, method="POST")
        with urllib.request.urlopen(req, timeout=10) as r:
            return json.loads(r.read())["jobID"]

    def wait(self, job: str, until, timeout: float) -> dict:
        deadline = time.monotonic() + timeout
        while True:
            doc = self.json(f"/jobs/{job}")
            if until(doc) or time.monotonic() > deadline:
                return doc
            time.sleep(0.05)

    def results(self, job: str) -> dict:
        """name -> bytes of every file in the manifest (checked against its sha256)."""
        out = {}
        for f in self.json(f"/jobs/{job}/results")["files"]:
            data = self.get(f"/jobs/{job}/results/{f['name']}")
            assert hashlib.sha256(data).hexdigest() == f["sha256"], f["name"]
            out[f["name"]] = data
        return out


def comparable(files: dict) -> dict:
    """sha256 per file; summary.json without its wall-time fields."""
    out = {}
    for name, data in files.items():
        if name == "summary.json":
            summary = json.loads(data)
            for key in WALL_FIELDS:
                summary.pop(key, None)
            data = json.dumps(summary, sort_keys=True).encode()
        out[name] = hashlib.sha256(data).hexdigest()
    return out


def done(doc: dict) -> bool:
    return doc["status"] in ("successful", "failed", "dismissed")


class CheckpointedJobSurvivesKills(unittest.TestCase):
    def setUp(self):
        self.tmp = Path(tempfile.mkdtemp(prefix="hmpm-checkpoint-"))
        self.addCleanup(shutil.rmtree, self.tmp, True)

    def start(self, name: str, extra: List[str]) -> Server:
        folder = self.tmp / name
        folder.mkdir()
        server = Server(folder, extra)
        self.addCleanup(server.stop)
        server.start()
        return server

    def test_killed_twice_resumes_and_ends_with_the_uninterrupted_results(self):
        t_start = time.monotonic()
        # Reference: no checkpoints at all.
        ref = self.start("reference", ["--checkpoint-interval", "0"])
        ref_id = ref.submit(spec())
        doc = ref.wait(ref_id, done, 60)
        self.assertEqual(doc["status"], "successful", doc)
        reference = ref.results(ref_id)
        reference_s = time.monotonic() - t_start
        ref.stop()
        total_steps = json.loads(reference["summary.json"])["steps"]

        srv = self.start("interrupted", ["--checkpoint-interval", str(INTERVAL_S)])
        job = srv.submit(spec())
        kills: List[Tuple[float, float]] = []  # (UTC time of the kill, progress % seen just before)
        for threshold, delay in KILLS:
            doc = srv.wait(job, lambda d: done(d) or (d["status"] == "running" and
                                                      d["progress"] >= threshold), 60)
            self.assertEqual(doc["status"], "running", f"the job ended before the kill: {doc}")
            time.sleep(delay)  # not synchronisation: where in the interval the crash falls
            seen = srv.json(f"/jobs/{job}")["progress"]
            kills.append((time.time(), seen))
            srv.kill()
            srv.start()
        # Then a graceful stop (SIGTERM): the run checkpoints where it stops.
        doc = srv.wait(job, lambda d: done(d) or d["progress"] >= 80.0, 60)
        self.assertEqual(doc["status"], "running", f"the job ended before the stop: {doc}")
        stopped_at = int(srv.json(f"/jobs/{job}")["progress"] / 100.0 * total_steps)
        srv.kill(signal.SIGTERM)
        srv.start()
        doc = srv.wait(job, done, 60)
        self.assertEqual(doc["status"], "successful", doc)
        log = srv.get(f"/jobs/{job}/log").decode()
        resumed = comparable(srv.results(job))
        self.assertEqual(resumed, comparable(reference))
        self.assertTrue(all(not n.startswith("checkpoint-") for n in resumed), resumed.keys())
        self.assertEqual(list((self.tmp / "interrupted" / "results" / job).rglob("checkpoint-*")), [],
                         "checkpoint files left after the job ended")

        # Checkpoints written: steps, size, write time; the resumes.
        written = [(utc(m[1]), int(m[2]), int(m[3]), float(m[4])) for m in re.finditer(
            r"^(\S+) checkpoint at step (\d+), t = \S+ s: (\d+) bytes in (\S+) s$", log, re.M)]
        starts = re.findall(r"^(\S+) resumed from the checkpoint at step (\d+), t = \S+ s "
                            r"\(\S+, written (\S+)\)$", log, re.M)
        self.assertEqual(len(starts), 3, log)
        self.assertRegex(log, r"s: the server is shutting down; queued again, to resume from attempt-\d+/checkpoint-")
        # The stop lost nothing: it resumed from at least the step the
        # progress showed before it (a lower bound of the step reached).
        print(f"stop at step >= {stopped_at}: resumed from step {starts[2][1]}")
        self.assertGreaterEqual(int(starts[2][1]), stopped_at)
        self.assertGreaterEqual(len(written), 4, log)
        # Steps per checkpoint interval, from consecutive checkpoints of one attempt.
        per_interval = max(b[1] - a[1] for a, b in zip(written, written[1:]) if b[1] > a[1])
        size = written[0][2]
        print(f"\ncheckpoint: {size} bytes for 4000 particles ({size / 4000:.1f} bytes/particle), "
              f"written in {max(w[3] for w in written) * 1e3:.1f} ms at most "
              f"({len(written)} checkpoints); up to {per_interval} steps per {INTERVAL_S:g} s interval")
        for (kill_utc, progress), (_, step, written_at) in zip(kills, starts[:2]):
            # Work repeated: from the checkpoint resumed from to the step the
            # killed run had reached, the wall time between the two at the
            # run's own step rate (the stored progress lags by up to a second).
            lost_wall = kill_utc - utc(written_at)
            rate = per_interval / INTERVAL_S
            print(f"kill at {progress:.0f} % (progress seen): resumed from step {step}, written "
                  f"{lost_wall:.2f} s before the kill: ~{lost_wall * rate:.0f} steps repeated "
                  f"(one interval: {per_interval})")
            # At most one interval: a checkpoint follows the previous one by
            # the interval plus one step and the write (milliseconds); 0.5 s
            # covers the log's timing and a busy machine.
            self.assertLessEqual(lost_wall, INTERVAL_S + 0.5)
            self.assertGreater(int(step), 0)
        total_s = time.monotonic() - t_start
        print(f"uninterrupted run {reference_s:.1f} s, whole test {total_s:.1f} s")

    def test_a_corrupt_checkpoint_is_not_used_and_the_job_starts_again(self):
        srv = self.start("corrupt", ["--checkpoint-interval", str(INTERVAL_S)])
        end = 0.6  # ~3 s
        job = srv.submit(spec(end))
        deadline = time.monotonic() + 30
        while "checkpoint at step" not in srv.get(f"/jobs/{job}/log").decode():
            self.assertLess(time.monotonic(), deadline, "no checkpoint within 30 s")
            time.sleep(0.05)
        srv.kill()
        files = list((self.tmp / "corrupt" / "results" / job).glob("attempt-*/checkpoint-*.hmpmck"))
        self.assertEqual(len(files), 1, files)
        data = bytearray(files[0].read_bytes())
        data[len(data) // 2] ^= 0x01
        files[0].write_bytes(bytes(data))
        srv.start()
        doc = srv.wait(job, done, 60)
        self.assertEqual(doc["status"], "successful", doc)
        log = srv.get(f"/jobs/{job}/log").decode()
        self.assertIn("does not have the recorded SHA-256): starting from step 0", log)
        self.assertNotIn("resumed from the checkpoint", log)
        summary = json.loads(srv.get(f"/jobs/{job}/results/summary.json"))
        self.assertEqual(summary["steps"], round(end / 1.0e-5))


if __name__ == "__main__":
    unittest.main()
