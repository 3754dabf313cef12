"""Keeps api/schema/job.schema.json honest.

1. The schema is a valid draft 2020-12 schema.
2. Every example in examples/ and tests/api/data/valid-2d.json validates.
3. The parser's tables (`hmpm spec-keys`) are the reference, not a copy here:
   a. for every object the parser reads, the schema's properties are exactly
      the parser's accepted keys;
   b. every enumeration (output fields from the solver's field table, material
      models, shape functions, traction faces) has exactly the parser's values;
   c. for every material model of the parser's table, the schema accepts a
      material with its required parameters, refuses one without any of them
      or with a parameter of another model, and bounds each parameter as the
      parser does.
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


def value_node(schema, location):
    """The schema node with the enum of the values at `location`."""
    parts = [p for p in location.split("/") if p]
    node = schema
    for part in parts[:-1]:
        node = object_branch(schema, node)
        node = node["items"] if part == "*" and "items" in node else (
            node["additionalProperties"] if part == "*" else node["properties"][part])
    node = object_branch(schema, node)
    last = parts[-1]
    node = resolve(schema, node["items"] if last == "*" else node["properties"][last])
    for key in ("oneOf", "anyOf"):
        for branch in node.get(key, []):
            b = resolve(schema, branch)
            if "enum" in b:
                return b
    return node


def check_models(schema, validator, base, tables, problems):
    """Each model of the parser's table against the schema's material."""
    models = tables["models"]
    material_props = at(schema, "/materials/*").get("properties", {})
    everyone = {p["key"] for m in models for p in m["parameters"]}

    def accepted(material):
        spec = copy.deepcopy(base)
        spec["materials"]["a/b~c"] = material
        return validator.is_valid(spec)

    for model in models:
        name = model["name"]
        own = {p["key"] for p in model["parameters"]}
        material = {"model": name, "density": 1000, "youngs_modulus": 1e6, "poisson_ratio": 0.2}
        for p in model["parameters"]:
            if p["required"]:
                material[p["key"]] = p["default"]
        if not accepted(material):
            problems.append(f"model '{name}': the schema refuses a material with its required parameters")
        for p in model["parameters"]:
            if p["required"]:
                without = {k: v for k, v in material.items() if k != p["key"]}
                if accepted(without):
                    problems.append(f"model '{name}': the schema accepts a material without '{p['key']}'")
            bounds = {k: v for k, v in material_props.get(p["key"], {}).items()
                      if k in ("minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum")}
            if bounds != p["range"]:
                problems.append(f"model '{name}': '{p['key']}' is bounded {bounds} in the schema, "
                                f"{p['range']} by the parser")
        for key in sorted(everyone - own):
            other = next(p for m in models for p in m["parameters"] if p["key"] == key)
            if accepted(dict(material, **{key: other["default"]})):
                problems.append(f"model '{name}': the schema accepts '{key}', which the model does not read")


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

    tables = json.loads(subprocess.run([hmpm, "spec-keys"], check=True, capture_output=True, text=True).stdout)
    keys = tables["objects"]
    for location, accepted in keys.items():
        try:
            props = set(at(schema, location).get("properties", {}))
        except KeyError as e:
            problems.append(f"schema has no object at '{location}': {e}")
            continue
        if props != set(accepted):
            problems.append(f"'{location}': schema names {sorted(props - set(accepted))} the parser does not "
                            f"accept; parser accepts {sorted(set(accepted) - props)} the schema does not name")

    for location, allowed in tables["values"].items():
        try:
            enum = value_node(schema, location).get("enum")
        except KeyError as e:
            problems.append(f"schema has no value at '{location}': {e}")
            continue
        if enum != allowed:
            problems.append(f"'{location}': schema enum {enum}, parser accepts {allowed}")

    with open(os.path.join(ROOT, "tests", "api", "data", "valid-2d.json")) as f:
        base = json.load(f)
    check_models(schema, validator, base, tables, problems)
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
    print(f"schema: {len(specs)} specs validated, {len(keys)} objects, {len(tables['values'])} enumerations "
          f"and {len(tables['models'])} models compared, {len(bad)} malformed rejected; "
          f"{len(problems)} problem(s)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
