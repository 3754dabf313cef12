"""Keeps api/schema/job.schema.json honest.

1. The schema is a valid draft 2020-12 schema.
2. Every example in examples/ and tests/api/data/valid-2d.json validates.
3. For every object the parser reads (`hmpm spec-keys`), the schema's
   properties are exactly the parser's accepted keys.
4. A few malformed specs are rejected by the schema too.

Usage: check_schema.py HMPM
"""
import copy
import glob
import json
import os
import subprocess
import sys

import jsonschema

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))


def resolve(schema, node):
    while "$ref" in node:
        ref = node["$ref"]
        assert ref.startswith("#/"), ref
        node = schema
        for part in ref[2:].split("/"):
            node = node[part]
    return node


def object_branch(schema, node):
    """The object-typed alternative of a node (through $ref and oneOf/anyOf)."""
    node = resolve(schema, node)
    if "properties" in node or "additionalProperties" in node or "items" in node:
        return node
    for key in ("oneOf", "anyOf"):
        for branch in node.get(key, []):
            b = resolve(schema, branch)
            if "properties" in b or "items" in b or "additionalProperties" in b:
                return b
    raise KeyError(f"no object alternative in {node}")


def at(schema, location):
    node = schema
    for part in [p for p in location.split("/") if p]:
        node = object_branch(schema, node)
        if part == "*":
            node = node["items"] if "items" in node else node["additionalProperties"]
        else:
            node = node["properties"][part]
    return object_branch(schema, node)


def main():
    hmpm = sys.argv[1]
    with open(os.path.join(ROOT, "api", "schema", "job.schema.json")) as f:
        schema = json.load(f)
    problems = []
    jsonschema.Draft202012Validator.check_schema(schema)
    validator = jsonschema.Draft202012Validator(schema)
    specs = sorted(glob.glob(os.path.join(ROOT, "examples", "*.json")))
    specs.append(os.path.join(ROOT, "tests", "api", "data", "valid-2d.json"))
    for path in specs:
        with open(path) as f:
            spec = json.load(f)
        for e in validator.iter_errors(spec):
            problems.append(f"{os.path.relpath(path, ROOT)}: /{'/'.join(map(str, e.path))}: {e.message}")

    keys = json.loads(subprocess.run([hmpm, "spec-keys"], check=True, capture_output=True, text=True).stdout)
    for location, accepted in keys.items():
        try:
            props = set(at(schema, location).get("properties", {}))
        except KeyError as e:
            problems.append(f"schema has no object at '{location}': {e}")
            continue
        if props != set(accepted):
            problems.append(f"'{location}': schema names {sorted(props - set(accepted))} the parser does not "
                            f"accept; parser accepts {sorted(set(accepted) - props)} the schema does not name")

    with open(os.path.join(ROOT, "tests", "api", "data", "valid-2d.json")) as f:
        base = json.load(f)
    bad = []
    for mutate in (lambda s: s.pop("time"),
                   lambda s: s["materials"]["sand"].__setitem__("poisson_ratio", 0.5),
                   lambda s: s["materials"]["sand"]["hydraulic"].__setitem__("porosity", 1.5),
                   lambda s: s.__setitem__("dimensoin", 2),
                   lambda s: s["materials"]["a/b~c"].__setitem__("cohesion", 1),
                   lambda s: s["boundaries"][0].pop("velocity"),
                   lambda s: s["output"]["series"]["fields"].append("stress")):
        spec = copy.deepcopy(base)
        mutate(spec)
        bad.append(spec)
    for i, spec in enumerate(bad):
        if validator.is_valid(spec):
            problems.append(f"malformed spec {i} passes the schema")

    for p in problems:
        print(p)
    print(f"schema: {len(specs)} specs validated, {len(keys)} objects compared, {len(bad)} malformed rejected; "
          f"{len(problems)} problem(s)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
