"""Shared pieces of the hostile suite (tests/hostile/).

Each test attacks a real hmpm-server on loopback (the `ServerProcess` of
tests/python/support.py: a free port, a fresh database in a temporary
folder) and, when it passes, records what it did with `record()`:

    record(item=2, probes=60, answered=60, load="64 slowloris connections, 30 s")

`item` is the number of the defect in the hardening issue (1-11) the test
reproduces; a test of a later campaign names its issue too
(`record(issue=45, item=1, ...)`). The other keys are figures the runner
sums into its summary:

    faults     faults injected and survived (kills, full disks, corrupt files)
    bad_inputs hostile inputs sent and answered correctly
    requests   requests answered under load
    lost       accepted jobs or results lost (must stay 0)

Any other key is printed as it is. `run.py` runs the suite and prints the
summary; an item with no passing test is a failure of the suite.
"""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO))

from tests.python.support import (  # noqa: E402  (re-exported for the tests)
    BAR_SPEC, COLUMN_SPEC, LiveServerCase, ServerProcess, build_dir, server_binary)

__all__ = ["BAR_SPEC", "COLUMN_SPEC", "LiveServerCase", "ServerProcess", "build_dir",
           "server_binary", "record", "FIGURES_ENV"]

FIGURES_ENV = "HMPM_HOSTILE_FIGURES"


def record(item: int, issue: int = 0, **figures) -> None:
    """Appends one passing test's figures to the file run.py reads."""
    path = os.environ.get(FIGURES_ENV)
    if not path:
        return
    test = os.environ.get("HMPM_HOSTILE_TEST", "")
    row = {"item": int(item), "test": test, **figures}
    if issue:
        row["issue"] = int(issue)
    with open(path, "a", encoding="utf-8") as f:
        f.write(json.dumps(row) + "\n")
