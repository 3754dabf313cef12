"""Runs one example job with the built `hmpm` and checks every result file.

Usage: run_example.py HMPM EXAMPLE.json OUT_DIR
`hmpm run` must exit 0 and write summary.json (status successful),
series.json/series.csv when the spec asks for a series, and snapshots.pvd
with .vtu files (read back with meshio) when it asks for snapshots.
"""
import json
import os
import shutil
import subprocess
import sys


def main():
    hmpm, example, out = sys.argv[1:4]
    shutil.rmtree(out, ignore_errors=True)
    with open(example) as f:
        spec = json.load(f)
    run = subprocess.run([hmpm, "run", example, "--out", out, "--threads", "2"],
                         capture_output=True, text=True, timeout=600)
    print(run.stdout, run.stderr, sep="\n")
    if run.returncode != 0:
        print(f"hmpm run exited {run.returncode}")
        # Still check what was written: summary.json must exist even on failure.
    output = spec.get("output", {})
    check = [sys.executable, os.path.join(os.path.dirname(__file__), "check_results.py"), out,
             "--hmpm", hmpm, "--status", "successful"]
    if "series" in output:
        check.append("--require-series")
    if "snapshots" in output:
        # No fields listed: every field of the solver's table (position is the points).
        tables = json.loads(subprocess.run([hmpm, "spec-keys"], check=True, capture_output=True,
                                           text=True).stdout)
        # A material parameter's field only where some material varies it
        # (a random field; docs/job-spec.md "Random fields").
        parameters = {"youngs_modulus", "cohesion", "friction_angle", "hydraulic_conductivity"}
        varying = set()
        for material in spec.get("materials", {}).values():
            for key, value in list(material.items()) + list(material.get("hydraulic", {}).items()):
                if isinstance(value, dict) and "random_field" in value:
                    varying.add(key)
        # Cam-Clay's state (void_ratio, preconsolidation_pressure) only where
        # some material is modified_cam_clay (0 on the others' particles then).
        cam_clay = {"void_ratio", "preconsolidation_pressure"}
        if any(m.get("model") == "modified_cam_clay" for m in spec.get("materials", {}).values()):
            cam_clay = set()
        every = [f["name"] for f in tables["fields"]
                 if f["name"] != "position" and (f["name"] not in parameters or f["name"] in varying)
                 and f["name"] not in cam_clay]
        check += ["--require-snapshots", "--snapshot-fields",
                  ",".join(output["snapshots"].get("fields", every))]
    checked = subprocess.run(check)
    return 0 if run.returncode == 0 and checked.returncode == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
