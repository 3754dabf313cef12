#!/usr/bin/env python3
"""Runs the hostile suite (tests/hostile/test_*.py) and prints its summary:
per defect item of each hardening campaign (the first hardening issue,
items 1-11; issue 45, the second campaign, `record(issue=45, item=N)`), the
tests that reproduce it and their figures; in all, faults survived, bad
inputs tried, load held and anything lost. Exit 0 only when every test
passed, every item of ITEMS has a passing test and nothing was lost.

    HMPM_BUILD_DIR=build python3 tests/hostile/run.py [-k PATTERN]

The PostgreSQL tests (test_postgres.py) use HMPM_TEST_POSTGRES; when it is
not set, run.py starts a throw-away PostgreSQL with scripts/postgres.sh for
the run and stops it at the end.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
import unittest
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
# Campaign (the issue number; 0: the first hardening issue) -> its items.
ITEMS = {0: range(1, 12), 45: range(1, 11)}
SUMMED = ("faults", "bad_inputs", "requests", "lost")


class _Named(unittest.TextTestResult):
    """Tells support.record() which test is running."""

    def startTest(self, test):
        os.environ["HMPM_HOSTILE_TEST"] = test.id().split(".", 2)[-1]
        super().startTest(test)


def main(argv) -> int:
    if os.environ.get("HMPM_TEST_POSTGRES"):
        return run(argv)
    pg_dir = tempfile.mkdtemp(prefix="hmpm-hostile-pg.")
    script = str(REPO / "scripts" / "postgres.sh")
    try:
        os.environ["HMPM_TEST_POSTGRES"] = subprocess.run(
            ["bash", script, "start", pg_dir], check=True, capture_output=True, text=True,
            timeout=120).stdout.strip()
        return run(argv)
    finally:
        subprocess.run(["bash", script, "stop", pg_dir], capture_output=True, timeout=120)


def run(argv) -> int:
    sys.path.insert(0, str(REPO))
    fd, figures = tempfile.mkstemp(prefix="hmpm-hostile-", suffix=".jsonl")
    os.close(fd)
    os.environ["HMPM_HOSTILE_FIGURES"] = figures
    pattern = None
    if len(argv) >= 2 and argv[0] == "-k":
        pattern = argv[1]
    loader = unittest.TestLoader()
    if pattern:
        loader.testNamePatterns = [f"*{pattern}*"]
    suite = loader.discover(str(HERE), pattern="test_*.py", top_level_dir=str(REPO))
    start = time.monotonic()
    result = unittest.TextTestRunner(verbosity=2, resultclass=_Named).run(suite)
    elapsed = time.monotonic() - start
    rows = [json.loads(line) for line in Path(figures).read_text().splitlines() if line.strip()]
    os.unlink(figures)

    print(f"\nhostile suite: {result.testsRun} tests in {elapsed:.0f} s, "
          f"{len(result.failures) + len(result.errors)} failed")
    totals = {k: 0 for k in SUMMED}
    missing = []
    for issue, items in ITEMS.items():
        print("  first hardening campaign:" if issue == 0 else f"  issue {issue}:")
        for item in items:
            mine = [r for r in rows if r["item"] == item and int(r.get("issue", 0)) == issue]
            label = f"item {item:2d}" if issue == 0 else f"#{issue} item {item:2d}"
            if not mine:
                missing.append(label)
                print(f"  {label}: NO PASSING TEST")
                continue
            for r in mine:
                extra = {k: v for k, v in r.items() if k not in ("item", "test", "issue")}
                for k in SUMMED:
                    totals[k] += int(extra.get(k, 0) or 0)
                shown = ", ".join(f"{k}={v}" for k, v in extra.items())
                print(f"  {label}: {r['test']}: {shown}")
    print(f"  in all: faults survived {totals['faults']}, bad inputs tried {totals['bad_inputs']}, "
          f"requests answered under load {totals['requests']}, lost {totals['lost']}")
    ok = result.wasSuccessful() and totals["lost"] == 0 and (pattern is not None or not missing)
    if missing and pattern is None:
        print(f"  items without a passing test: {missing}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
