"""Reads a result directory back with independent readers and checks it.

The contract's files: summary.json (keys and status), series.json (one row
per time, vectors as arrays of `dim` components, tensors as 6), series.csv
(same numbers, one row per time), snapshots.pvd and every .vtu it lists
(read with meshio: point count = summary particles, the expected fields).

Usage: check_results.py DIR --hmpm HMPM [--status S] [--particles N]
                            [--snapshot-fields a,b] [--require-series] [--require-snapshots]
The kind of each field (scalar, vector, tensor) comes from `HMPM spec-keys`,
the solver's field table, not from a copy here.
Exit 0 when everything holds, 1 with one line per problem otherwise.
"""
import argparse
import csv
import json
import math
import os
import subprocess
import sys
import xml.etree.ElementTree as ET

SUMMARY_KEYS = ["status", "message", "steps", "end_time", "dt", "particles", "nodes",
                "solve_seconds", "particle_steps_per_second"]
VECTOR_SUFFIX = ["x", "y", "z"]
TENSOR_SUFFIX = ["xx", "yy", "zz", "xy", "yz", "zx"]


def same(a, b):
    if a is None or b is None:
        return (a is None or math.isnan(a)) and (b is None or math.isnan(b))
    return a == b or abs(a - b) <= 1e-12 * max(abs(a), abs(b))


def field_kinds(hmpm):
    """{field name: "scalar" | "vector" | "tensor"} from the built hmpm."""
    tables = json.loads(subprocess.run([hmpm, "spec-keys"], check=True, capture_output=True,
                                       text=True).stdout)
    return {f["name"]: f["kind"] for f in tables["fields"]}


def check_series(d, kinds, problems):
    with open(os.path.join(d, "series.json")) as f:
        series = json.load(f)
    times = series["time"]
    if not times:
        problems.append("series.json: no rows")
    expected_columns = ["time"]
    rows_from_json = [[t] for t in times]
    for p in series["particles"]:
        dim = len(p["initial_position"])
        if not 1 <= dim <= 3:
            problems.append(f"series.json: particle {p.get('index')} initial_position has {dim} components")
        for field, values in p.items():
            if field in ("index", "initial_position"):
                continue
            if len(values) != len(times):
                problems.append(f"series.json: {field} of particle {p['index']} has {len(values)} rows, "
                                f"time has {len(times)}")
                continue
            if field not in kinds:
                problems.append(f"series.json: '{field}' is not a field of the solver's table")
                continue
            if kinds[field] == "scalar":
                names, width = [""], 1
            elif kinds[field] == "tensor":
                names, width = ["_" + s for s in TENSOR_SUFFIX], 6
            else:
                names, width = ["_" + s for s in VECTOR_SUFFIX[:dim]], dim
            expected_columns += [f"p{p['index']}_{field}{n}" for n in names]
            scalar = kinds[field] == "scalar"
            for r, row in enumerate(values):
                cells = [row] if scalar else row
                if not scalar and (not isinstance(row, list) or len(row) != width):
                    problems.append(f"series.json: {field} row {r} of particle {p['index']} is {row!r}, "
                                    f"expected {width} components")
                    cells = [None] * width
                rows_from_json[r] += cells
    with open(os.path.join(d, "series.csv")) as f:
        table = list(csv.reader(f))
    if table[0] != expected_columns:
        problems.append(f"series.csv header {table[0][:6]}... differs from series.json {expected_columns[:6]}...")
    if len(table) - 1 != len(times):
        problems.append(f"series.csv has {len(table) - 1} rows, series.json {len(times)}")
    for r, (csv_row, json_row) in enumerate(zip(table[1:], rows_from_json)):
        values = [float(x) for x in csv_row]
        if len(values) != len(json_row) or not all(same(a, b) for a, b in zip(values, json_row)):
            problems.append(f"series.csv row {r} differs from series.json")
            break
    return series


def check_snapshots(d, particles, fields, problems, staged=False):
    import meshio  # Debian python3-meshio: an independent VTU reader

    root = ET.parse(os.path.join(d, "snapshots.pvd")).getroot()
    datasets = root.findall("./Collection/DataSet")
    if not datasets:
        problems.append("snapshots.pvd lists no data set")
    last_time = -math.inf
    for ds in datasets:
        t = float(ds.get("timestep"))
        if not t > last_time:
            problems.append(f"snapshots.pvd: timesteps not increasing at {t}")
        last_time = t
        mesh = meshio.read(os.path.join(d, ds.get("file")))
        if particles is not None and len(mesh.points) != particles:
            # A staged job's snapshot holds the particles in the run at its
            # time (bodies not yet added or already removed are absent).
            if not (staged and 0 < len(mesh.points) <= particles):
                problems.append(f"{ds.get('file')}: {len(mesh.points)} points, expected {particles}")
        names = set(mesh.point_data)
        for name in ["volume", "material"] + list(fields or []):
            if name != "position" and name not in names:
                problems.append(f"{ds.get('file')}: no point field '{name}' (has {sorted(names)})")
        for name, values in mesh.point_data.items():
            if len(values) != len(mesh.points):
                problems.append(f"{ds.get('file')}: field {name} has {len(values)} values")
    return len(datasets)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("dir")
    ap.add_argument("--hmpm", required=True, help="the built hmpm (its spec-keys gives the field kinds)")
    ap.add_argument("--status")
    ap.add_argument("--particles", type=int)
    ap.add_argument("--snapshot-fields", default="")
    ap.add_argument("--require-series", action="store_true")
    ap.add_argument("--require-snapshots", action="store_true")
    args = ap.parse_args()
    problems = []
    with open(os.path.join(args.dir, "summary.json")) as f:
        summary = json.load(f)
    for key in SUMMARY_KEYS:
        if key not in summary:
            problems.append(f"summary.json: no '{key}'")
    if args.status and summary.get("status") != args.status:
        problems.append(f"summary.json: status {summary.get('status')!r} ({summary.get('message')}), "
                        f"expected {args.status!r}")
    particles = args.particles if args.particles is not None else summary.get("particles")
    if args.require_series or os.path.exists(os.path.join(args.dir, "series.json")):
        check_series(args.dir, field_kinds(args.hmpm), problems)
    snapshots = 0
    if args.require_snapshots or os.path.exists(os.path.join(args.dir, "snapshots.pvd")):
        fields = [f for f in args.snapshot_fields.split(",") if f]
        staged = " stages" in summary.get("message", "")  # "completed N steps ... in K stages"
        snapshots = check_snapshots(args.dir, particles, fields, problems, staged)
    for name in summary.get("files", []):
        if not os.path.exists(os.path.join(args.dir, name)):
            problems.append(f"summary.json lists {name}, which does not exist")
    for p in problems:
        print(p)
    print(f"{args.dir}: {len(problems)} problem(s), {snapshots} snapshot(s) read with meshio")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
