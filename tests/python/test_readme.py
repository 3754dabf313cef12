"""The README's quick start, command by command, against a real server.

Every fenced `sh` block between `<!-- quick-start:begin` and
`<!-- quick-start:end -->` in README.md is run as written, with three
substitutions so that the test is fast and leaves the checkout clean:
  - the port 8080 becomes a free loopback port (and the serve command gets
    `--data` in a temporary folder);
  - `examples/quick-start.json` becomes a copy whose end time is 5.1 s
    (T_v = 0.05) instead of 51 s: the same problem, a tenth of the run (about
    5 s of wall time instead of a minute);
  - `out/` and `pore_pressure.png` go to the temporary folder.
The first block (the serve command) is started in the background and must
print "listening"; the others run in one `bash -euo pipefail` script, so any
command that fails fails the test. Then the downloaded series is compared with
Terzaghi's closed form, and both plots must be PNG files.

The serve command runs `scripts/serve.sh` itself when the tests use the
repository's `build/` (then its build step finds everything built); with
another HMPM_BUILD_DIR it starts that folder's hmpm-server with the options
serve.sh would pass, since serve.sh always builds into `build/`.
"""

from __future__ import annotations

import json
import math
import os
import re
import signal
import socket
import subprocess
import tempfile
import time
import unittest
from pathlib import Path

from tests.python.support import REPO, build_dir, server_binary

BEGIN = "<!-- quick-start:begin"
END = "<!-- quick-start:end -->"
SHORT_END_S = 5.1
SERVE_TIMEOUT_S = 120.0  # serve.sh: dependency check, cmake configure, a no-op build
SCRIPT_TIMEOUT_S = 90.0


def quick_start_blocks(readme: str):
    """The fenced sh blocks between the markers, dedented, as strings."""
    start = readme.index(BEGIN)
    end = readme.index(END, start)
    section = readme[start:end]
    blocks = re.findall(r"^([ \t]*)```sh\n(.*?)^\1```", section, flags=re.S | re.M)
    out = []
    for indent, body in blocks:
        lines = [line[len(indent):] if line.startswith(indent) else line
                 for line in body.splitlines()]
        out.append("\n".join(lines).strip())
    return out


def tokenless_env():
    """The environment without HMPM_TOKEN: the quick start serves without one."""
    return {k: v for k, v in os.environ.items() if k != "HMPM_TOKEN"}


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def terzaghi_pressure(x: float, t: float) -> float:
    """Excess pore pressure of the quick-start column (drained top x = 1 m,
    impermeable base x = 0, q = 1 kPa), Terzaghi's series with 200 terms."""
    q, height = 1000.0, 1.0
    k, gamma_w = 1.0e-5, 1000.0 * 9.81
    m_v, storage = 1.0 / 1.0e7, 0.3 / 7.5e7  # 1/E_oed (nu = 0), n / K_w
    c_v = k / (gamma_w * (m_v + storage))
    t_v = c_v * t / height ** 2
    z = height - x  # distance from the drained face
    p = 0.0
    for m in range(200):
        big_m = math.pi * (2 * m + 1) / 2
        p += 2 * q / big_m * math.sin(big_m * z / height) * math.exp(-big_m * big_m * t_v)
    return p


class ReadmeQuickStart(unittest.TestCase):
    def setUp(self):
        self.tmp = Path(tempfile.mkdtemp(prefix="hmpm-readme-"))
        self.server = None
        self.log = None

    def tearDown(self):
        if self.server and self.server.poll() is None:
            os.killpg(self.server.pid, signal.SIGTERM)
            try:
                self.server.wait(timeout=10)
            except subprocess.TimeoutExpired:
                os.killpg(self.server.pid, signal.SIGKILL)
                self.server.wait()
        if self.log:
            self.log.close()
        subprocess.run(["rm", "-rf", str(self.tmp)], check=False)

    def substitute(self, text: str, port: int, spec: Path) -> str:
        text = text.replace("examples/quick-start.json", str(spec))
        text = text.replace("8080", str(port))
        text = re.sub(r"(?<![\w/.-])out/", f"{self.tmp}/out/", text)
        return text.replace("pore_pressure.png", f"{self.tmp}/pore_pressure.png")

    def start_server(self, command: str, port: int) -> None:
        self.assertTrue(command.startswith("bash scripts/serve.sh"), command)
        data = self.tmp / "data"
        if build_dir().resolve() == (REPO / "build").resolve():
            argv = ["bash", "-c", f"{command} --data {data}"]
        else:  # what serve.sh runs after building
            data.mkdir(parents=True)
            argv = [str(server_binary()), "--host", "127.0.0.1", "--port", str(port),
                    "--db", str(data / "hmpm.sqlite"), "--data-dir", str(data / "results")]
        self.log = open(self.tmp / "serve.log", "w")
        self.server = subprocess.Popen(argv, cwd=REPO, stdout=self.log, stderr=subprocess.STDOUT,
                                       start_new_session=True, env=tokenless_env())
        deadline = time.monotonic() + SERVE_TIMEOUT_S
        while time.monotonic() < deadline:
            text = (self.tmp / "serve.log").read_text(errors="replace")
            if f"listening on http://127.0.0.1:{port}" in text:
                return
            if self.server.poll() is not None:
                self.fail(f"the serve command exited {self.server.returncode}:\n{text[-3000:]}")
            time.sleep(0.2)
        self.fail(f"no 'listening' within {SERVE_TIMEOUT_S} s:\n"
                  + (self.tmp / "serve.log").read_text(errors="replace")[-3000:])

    def test_every_quick_start_command_works(self):
        readme = (REPO / "README.md").read_text()
        blocks = quick_start_blocks(readme)
        self.assertGreaterEqual(len(blocks), 4, "the quick start lost its commands")
        example = json.loads((REPO / "examples" / "quick-start.json").read_text())
        self.assertEqual(example["time"]["end"], 51.0, "the README promises about a minute")
        example["time"]["end"] = SHORT_END_S
        spec = self.tmp / "quick-start.json"
        spec.write_text(json.dumps(example))
        port = free_port()
        commands = [self.substitute(b, port, spec) for b in blocks]

        self.start_server(commands[0], port)
        script = "set -euo pipefail\n" + "\n".join(commands[1:]) + "\n"
        run = subprocess.run(["bash", "-c", script], cwd=REPO, capture_output=True, text=True,
                             timeout=SCRIPT_TIMEOUT_S, env=tokenless_env())
        self.assertEqual(run.returncode, 0,
                         f"a quick-start command failed:\n{script}\nstdout:\n{run.stdout[-3000:]}"
                         f"\nstderr:\n{run.stderr[-3000:]}")
        job_id = run.stdout.splitlines()[0].strip()
        self.assertRegex(job_id, r"^[0-9a-f-]{36}$")
        # curl: the status document says successful; the event stream ended with done.
        self.assertIn('"status":"successful"', run.stdout.replace(" ", ""))
        self.assertIn("event: done", run.stdout)

        out = self.tmp / "out"
        summary = json.loads((out / "summary.json").read_text())
        self.assertEqual(summary.get("status"), "successful")
        series = json.loads((out / "series.json").read_text())
        times = series["time"]
        self.assertAlmostEqual(times[-1], SHORT_END_S, delta=0.5)
        # Terzaghi's closed form at every recorded time, for every series
        # particle. Tolerance 1 % of q: the solver test (tests/solver/
        # test_terzaghi.cpp) holds 1 % at 40 cells; the u-p inertia's pressure
        # waves are 0.2 % of q at T_v = 0.05 (docs/verification.md), and this
        # run measured 0.14 % at 200 cells.
        for particle in series["particles"]:
            x = particle["initial_position"][0]
            for t, p in zip(times[1:], particle["pore_pressure"][1:]):
                self.assertLess(abs(p - terzaghi_pressure(x, t)), 10.0,
                                f"x = {x} m, t = {t} s: p = {p} Pa")
        png = (self.tmp / "pore_pressure.png").read_bytes()
        self.assertEqual(png[:8], b"\x89PNG\r\n\x1a\n")


if __name__ == "__main__":
    unittest.main()
