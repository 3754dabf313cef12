"""Shared fixtures for the Python client tests: a live hmpm-server and specs.

`ServerProcess` starts the real `$HMPM_BUILD_DIR/bin/hmpm-server` on an
ephemeral loopback port with a fresh database in a temporary folder, reads
the first stdout line (`listening on http://HOST:PORT`) and stops the server
at the end (SIGTERM, a bounded wait, then SIGKILL). A missing binary is a
test failure with the command that builds it, never a silent skip.
"""

from __future__ import annotations

import copy
import os
import queue
import re
import shutil
import subprocess
import sys
import tempfile
import threading
import time
import unittest
from pathlib import Path
from typing import Dict, List, Optional

REPO = Path(__file__).resolve().parents[2]
CLIENT_DIR = REPO / "clients" / "python"
START_TIMEOUT_S = 20.0
STOP_TIMEOUT_S = 10.0
JOB_TIMEOUT_S = 120.0


def build_dir() -> Path:
    return Path(os.environ.get("HMPM_BUILD_DIR") or REPO / "build")


def server_binary() -> Path:
    return build_dir() / "bin" / "hmpm-server"


class ServerProcess:
    """One hmpm-server subprocess; use start()/stop() or `with`."""

    def __init__(self, token: Optional[str] = None, workers: Optional[int] = 2,
                 extra: Optional[List[str]] = None):
        self.token = token
        self.workers = workers
        self.extra = list(extra or [])
        self.tmp = Path()
        self.proc: Optional[subprocess.Popen] = None
        self.url = ""
        self.stdout_lines: List[str] = []
        self._log = None

    def start(self) -> "ServerProcess":
        exe = server_binary()
        if not exe.is_file() or not os.access(exe, os.X_OK):
            raise AssertionError(
                f"hmpm-server not found at {exe}; build it first "
                f"(cmake -S . -B build -DCMAKE_BUILD_TYPE=Release && cmake --build build --target hmpm-server) "
                f"or set HMPM_BUILD_DIR to the build folder")
        self.tmp = Path(tempfile.mkdtemp(prefix="hmpm-pytest-"))
        cmd = [str(exe), "--host", "127.0.0.1", "--port", "0", "--db", str(self.tmp / "db.sqlite")]
        if self.workers is not None:  # None: the server's default
            cmd += ["--workers", str(self.workers)]
        cmd += self.extra
        if self.token:
            cmd += ["--token", self.token]
        env = dict(os.environ)
        env.pop("HMPM_TOKEN", None)
        self._log = open(self.tmp / "server.log", "w")
        self.proc = subprocess.Popen(cmd, cwd=self.tmp, env=env, stdin=subprocess.DEVNULL,
                                     stdout=subprocess.PIPE, stderr=self._log, text=True, bufsize=1)
        first: "queue.Queue[str]" = queue.Queue()

        def pump():
            assert self.proc and self.proc.stdout
            for i, line in enumerate(self.proc.stdout):
                if i == 0:
                    first.put(line)
                self.stdout_lines.append(line)
            first.put("")

        threading.Thread(target=pump, daemon=True).start()
        try:
            line = first.get(timeout=START_TIMEOUT_S)
        except queue.Empty:
            self.stop()
            raise AssertionError(f"hmpm-server printed nothing within {START_TIMEOUT_S} s\n{self.log_tail()}")
        m = re.match(r"listening on (http://\S+)", line.strip())
        if not m:
            self.stop()
            raise AssertionError(f"unexpected first line from hmpm-server: {line!r}\n{self.log_tail()}")
        self.url = m.group(1).rstrip("/")
        return self

    def log_tail(self, n: int = 40) -> str:
        try:
            if self._log:
                self._log.flush()
            lines = (self.tmp / "server.log").read_text(errors="replace").splitlines()
        except OSError:
            return ""
        return "server log (tail):\n" + "\n".join(lines[-n:])

    def stop(self) -> None:
        if self.proc and self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(timeout=STOP_TIMEOUT_S)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait(timeout=STOP_TIMEOUT_S)
        if self.proc and self.proc.stdout:
            self.proc.stdout.close()
        if self._log:
            self._log.close()
            self._log = None
        if self.tmp != Path():
            shutil.rmtree(self.tmp, ignore_errors=True)

    def __enter__(self) -> "ServerProcess":
        return self.start()

    def __exit__(self, *exc) -> None:
        self.stop()


class LiveServerCase(unittest.TestCase):
    """A test class sharing one server (with `server_token`, if set); each
    test gets a fresh temporary folder in `self.tmp`."""

    server_token: Optional[str] = None
    server_workers: Optional[int] = 2
    server_args: List[str] = []
    server: ServerProcess

    @classmethod
    def setUpClass(cls):
        cls.server = ServerProcess(token=cls.server_token, workers=cls.server_workers,
                                   extra=cls.server_args).start()

    @classmethod
    def tearDownClass(cls):
        cls.server.stop()

    def setUp(self):
        self.tmp = Path(tempfile.mkdtemp(prefix="hmpm-pytest-case-"))
        self.addCleanup(shutil.rmtree, self.tmp, True)


def run_cli(args: List[str], env: Optional[Dict[str, str]] = None, cwd: Optional[Path] = None,
            timeout: float = JOB_TIMEOUT_S + 30, input: Optional[str] = None) -> subprocess.CompletedProcess:
    """Runs `python -m hmpm_client ARGS` with this interpreter, bounded."""
    full_env = dict(os.environ)
    full_env.pop("HMPM_TOKEN", None)
    full_env.pop("HMPM_URL", None)
    full_env["PYTHONPATH"] = str(CLIENT_DIR) + os.pathsep + full_env.get("PYTHONPATH", "")
    full_env.update(env or {})
    return subprocess.run([sys.executable, "-m", "hmpm_client"] + args, env=full_env,
                          cwd=str(cwd or REPO), capture_output=True, text=True, timeout=timeout,
                          input=input, stdin=None if input is not None else subprocess.DEVNULL)


# A vibrating elastic bar (the contract's example, shortened): 13 particles,
# a few hundred steps, done in well under a second.
BAR_SPEC = {
    "name": "pytest-bar",
    "dimension": 1,
    "grid": {"min": [0.0], "max": [1.0], "cells": [13]},
    "shape_function": "linear",
    "materials": {
        "bar": {"model": "linear_elastic", "density": 1.0, "youngs_modulus": 10.0, "poisson_ratio": 0.0},
    },
    "bodies": [
        {"material": "bar", "box": {"min": [0.0], "max": [1.0]}, "particles_per_cell": 1,
         "initial": {"velocity": ["0.1*sin(pi/2*x)"]}},
    ],
    "gravity": [0.0],
    "boundaries": [{"nodes": {"box": {"min": [0.0], "max": [0.0]}}, "velocity": [0.0]}],
    "tractions": [],
    "time": {"end": 0.5, "dt": 1.0e-3},
    "output": {
        "series": {"particles": [0, 6, 12], "fields": ["displacement", "velocity"], "interval": 0.01},
        "snapshots": {"interval": 0.25},
    },
}

# A small saturated column loaded at the top (a coarse Terzaghi problem):
# pore pressure histories to plot.
COLUMN_SPEC = {
    "name": "pytest-column",
    "dimension": 1,
    "grid": {"min": [0.0], "max": [1.0], "cells": [10]},
    "materials": {
        "clay": {"model": "linear_elastic", "density": 2650.0, "youngs_modulus": 1.0e7, "poisson_ratio": 0.0,
                 "hydraulic": {"porosity": 0.4, "hydraulic_conductivity": 1.0e-3,
                               "fluid_bulk_modulus": 7.5e7, "fluid_density": 1000.0}},
    },
    "bodies": [{"material": "clay", "box": {"min": [0.0], "max": [1.0]}, "particles_per_cell": 1,
                "initial": {"pore_pressure": 10000.0}}],
    "gravity": [0.0],
    "boundaries": [
        {"nodes": {"box": {"min": [0.0], "max": [0.0]}}, "velocity": [0.0]},
        {"nodes": {"box": {"min": [1.0], "max": [1.0]}}, "pore_pressure": 0.0},
    ],
    "tractions": [{"particles": {"box": {"min": [0.9], "max": [1.0]}}, "face": "x+", "traction": [-10000.0]}],
    "time": {"end": 0.05},
    "output": {"series": {"particles": [0, 5, 9], "fields": ["pore_pressure", "displacement"], "interval": 0.005}},
}


def bar_spec(**time) -> dict:
    spec = copy.deepcopy(BAR_SPEC)
    spec["time"].update(time)
    return spec


def column_spec(cells: int = 10, end: float = 0.05) -> dict:
    """The saturated column with `cells` particles; the work grows as
    cells^3 (the hydraulic step limit scales with the cell size squared):
    60 cells to t = 0.51 s take about a second."""
    spec = copy.deepcopy(COLUMN_SPEC)
    spec["grid"]["cells"] = [cells]
    spec["tractions"][0]["particles"]["box"]["min"] = [1.0 - 1.0 / cells]
    spec["time"]["end"] = end
    spec["output"]["series"]["particles"] = [0, cells // 2, cells - 1]
    spec["output"]["series"]["interval"] = end / 10
    return spec


def quasi_static_column_spec() -> dict:
    """The saturated column (20 cells) in the quasi-static scheme, its step
    growing from 1 ms to 0.1 s: 41 steps to t = 2 s in milliseconds. The
    estimate's steps times its first step (0.041 s) is not the end time."""
    spec = column_spec(cells=20, end=2.0)
    spec["name"] = "pytest-quasi-static"
    spec["time"] = {"end": 2.0, "scheme": "quasi_static",
                    "dt": {"initial": 0.001, "max": 0.1, "growth": 1.2}}
    return spec


def long_spec() -> dict:
    """A job that runs for many minutes unless cancelled: 4000 particles,
    10 million steps (half the api's step limit)."""
    spec = copy.deepcopy(BAR_SPEC)
    spec["name"] = "pytest-long"
    spec["grid"]["cells"] = [2000]
    spec["bodies"][0]["particles_per_cell"] = 2
    del spec["bodies"][0]["initial"]  # at rest: nothing can leave the grid
    spec["time"] = {"end": 100.0, "dt": 1.0e-5}
    spec["output"] = {"series": {"particles": [0], "fields": ["displacement"], "interval": 1.0}}
    return spec


def invalid_spec() -> dict:
    """A spec with two errors: a negative Young's modulus and no time.end."""
    spec = copy.deepcopy(BAR_SPEC)
    spec["materials"]["bar"]["youngs_modulus"] = -1.0
    del spec["time"]["end"]
    return spec


def wait_until(predicate, timeout: float, interval: float = 0.1) -> bool:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(interval)
    return predicate()
