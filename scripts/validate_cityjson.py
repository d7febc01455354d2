#!/usr/bin/python3
"""Validates a CityJSON file (or each line of a CityJSONSeq) against the CityJSON 2.0.2 JSON
schemas, offline: every schema file is put in a $ref store under its $id.
Usage: scripts/validate_cityjson.py SCHEMA_DIR FILE [--seq]
Prints "valid" and exits 0, or prints the first errors and exits 1 (2: validator missing)."""
import json
import os
import sys

try:
    import jsonschema
except ImportError:
    print("python3-jsonschema is not installed")
    sys.exit(2)


def main():
    schema_dir, path = sys.argv[1], sys.argv[2]
    seq = "--seq" in sys.argv[3:]
    store = {}
    for name in os.listdir(schema_dir):
        if name.endswith(".json"):
            with open(os.path.join(schema_dir, name)) as f:
                s = json.load(f)
            store[s["$id"]] = s
    def validator(name):
        schema = store[next(k for k in store if k.endswith("/" + name))]
        resolver = jsonschema.RefResolver(base_uri=schema["$id"], referrer=schema, store=store)
        return jsonschema.Draft7Validator(schema, resolver=resolver)
    with open(path) as f:
        if seq:
            lines = [json.loads(l) for l in f if l.strip()]
            docs = [(validator("cityjson.schema.json"), lines[0])] + [
                (validator("cityjsonfeature.schema.json"), l) for l in lines[1:]]
        else:
            docs = [(validator("cityjson.schema.json"), json.load(f))]
    errors = []
    for v, doc in docs:
        errors += [f"{'/'.join(map(str, e.absolute_path))}: {e.message[:200]}" for e in v.iter_errors(doc)]
    if errors:
        print(f"{len(errors)} schema error(s):")
        print("\n".join(errors[:10]))
        sys.exit(1)
    print("valid")


if __name__ == "__main__":
    main()
