"""What every example check (tests/api/check_*.py) starts with: its command
line `check_X.py EXAMPLE.json RESULT_DIR`, the spec read, and a reader of
the JSON result files that `hmpm run EXAMPLE.json --out RESULT_DIR` wrote.

    spec, results, read = example_results.load()
    profiles = read("profiles.json")
"""
import json
import os
import sys


def load(argv=None):
    example, results = (sys.argv if argv is None else argv)[1:3]
    with open(example) as f:
        spec = json.load(f)

    def read(name):
        with open(os.path.join(results, name)) as f:
            return json.load(f)

    return spec, results, read
