"""Runs clients/curl/README.md against a live hmpm-server so it cannot rot.

Every ```sh block is extracted in order. The blocks of the token section
(its heading mentions "token") run against a second server started with
`--token`, with HMPM_TOKEN set; all others run, in one bash process with
`set -eo pipefail`, against a server without a token. A block whose command
fails fails the test, and a few outputs a reader relies on are checked.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import tempfile
import unittest
import uuid
from pathlib import Path
from typing import List, Tuple

from .support import REPO, ServerProcess

WALKTHROUGH = REPO / "clients" / "curl" / "README.md"
RUN_TIMEOUT_S = 300


def sh_blocks(markdown: str) -> List[Tuple[str, str]]:
    """(section heading, code) for every ```sh block, in document order."""
    blocks = []
    heading = ""
    in_block = False
    lines: List[str] = []
    for line in markdown.splitlines():
        if not in_block and line.startswith("#"):
            heading = line.lstrip("#").strip()
        elif not in_block and re.match(r"^```(sh|bash)\s*$", line):
            in_block, lines = True, []
        elif in_block and line.startswith("```"):
            in_block = False
            blocks.append((heading, "\n".join(lines) + "\n"))
        elif in_block:
            lines.append(line)
    return blocks


def run_blocks(blocks: List[Tuple[str, str]], cwd: Path, env: dict) -> subprocess.CompletedProcess:
    script = ["set -eo pipefail"]
    for heading, code in blocks:
        script.append(f"echo '>>> {heading}' >&2")
        script.append(code)
    full_env = dict(os.environ)
    full_env.pop("HMPM_TOKEN", None)
    # curl would send even loopback requests through a configured proxy.
    full_env["no_proxy"] = full_env["NO_PROXY"] = "127.0.0.1,localhost"
    full_env.update(env)
    return subprocess.run(["bash", "-c", "\n".join(script)], cwd=str(cwd), env=full_env,
                          capture_output=True, text=True, timeout=RUN_TIMEOUT_S)


class CurlWalkthroughTest(unittest.TestCase):
    def test_every_block_runs(self):
        self.assertTrue(WALKTHROUGH.is_file(), f"{WALKTHROUGH} is missing")
        blocks = sh_blocks(WALKTHROUGH.read_text())
        self.assertGreaterEqual(len(blocks), 10, "the walkthrough lost its command blocks")
        main = [b for b in blocks if "token" not in b[0].lower()]
        token = [b for b in blocks if "token" in b[0].lower()]
        self.assertTrue(token, "the walkthrough has no token section")
        self.assertIn("HMPM=${HMPM:-http://127.0.0.1:8080}", main[0][1])

        cwd = Path(tempfile.mkdtemp(prefix="hmpm-curl-"))
        self.addCleanup(shutil.rmtree, cwd, True)
        with ServerProcess(workers=2) as server:
            r = run_blocks(main, cwd, {"HMPM": server.url})
            report = f"stdout:\n{r.stdout}\nstderr:\n{r.stderr}\n{server.log_tail()}"
            self.assertEqual(r.returncode, 0, report)
        out = r.stdout
        self.assertRegex(out, r"HTTP/1\.[01] 201", report)
        self.assertRegex(out, r"(?im)^location: \S*/jobs/", report)
        self.assertIn("same job: True", out, report)
        self.assertRegex(out, r"data:", report)
        self.assertIn("successful 100", out, report)
        self.assertRegex(out, r"series\.json: OK", report)
        self.assertNotIn("FAILED", out, report)
        self.assertIn("/materials/clay/youngs_modulus", out, report)
        self.assertIn("/time", out, report)
        self.assertIn("dismissed", out, report)
        for name in ("summary.json", "series.json", "series.csv", "snapshots.pvd"):
            self.assertTrue((cwd / "out" / name).is_file(), name)

        token_value = "walkthrough-" + uuid.uuid4().hex
        with ServerProcess(token=token_value, workers=1) as server:
            r = run_blocks(main[:1] + token, cwd, {"HMPM": server.url, "HMPM_TOKEN": token_value})
            report = f"stdout:\n{r.stdout}\nstderr:\n{r.stderr}\n{server.log_tail()}"
            self.assertEqual(r.returncode, 0, report)
        self.assertIn("without a token: 401", r.stdout, report)
        self.assertIn("health stays open: 200", r.stdout, report)
        self.assertIn('"jobID"', r.stdout, report)


if __name__ == "__main__":
    unittest.main()
