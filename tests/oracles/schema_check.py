"""Validates design YAML files against fabkit's design JSON Schema with an independent
validator (the `jsonschema` package, draft 2020-12).

usage: schema_check.py SCHEMA.json DESIGN.yaml [DESIGN.yaml ...]

Each design is read with yaml.safe_load. Every error is printed as `file: path: message`
(path as `layers[0].thickness_mm`, `(root)` for the document); the last line counts the files
as `N passed, N failed`. Exit status 1 when any design fails (or cannot be read), 2 on bad
usage or an invalid schema.
"""

import json
import sys

import yaml
from jsonschema import Draft202012Validator


def path_text(path):
    out = ""
    for p in path:
        if isinstance(p, int):
            out += f"[{p}]"
        else:
            out += ("." if out else "") + str(p)
    return out or "(root)"


def leaves(error):
    """The innermost errors under `error`: for an `anyOf` / `oneOf` that no branch matched (an
    optional section, a body profile), the errors of its branches that reach deepest into the
    document, which name the offending key rather than the whole section."""
    if not error.context:
        return [error]
    found = [leaf for sub in error.context for leaf in leaves(sub)]
    deepest = max(len(e.absolute_path) for e in found)
    return [e for e in found if len(e.absolute_path) == deepest]


def main(argv):
    if len(argv) < 3:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    with open(argv[1], encoding="utf-8") as f:
        schema = json.load(f)
    try:
        Draft202012Validator.check_schema(schema)
    except Exception as e:  # jsonschema.SchemaError: the schema itself is wrong
        print(f"{argv[1]}: not a valid draft 2020-12 schema: {e}", file=sys.stderr)
        return 2
    validator = Draft202012Validator(schema)
    passed = failed = 0
    for name in argv[2:]:
        try:
            with open(name, encoding="utf-8") as f:
                doc = yaml.safe_load(f)
        except Exception as e:
            print(f"{name}: cannot be read as YAML: {e}")
            failed += 1
            continue
        errors = sorted(validator.iter_errors(doc), key=lambda e: list(map(str, e.absolute_path)))
        if errors:
            failed += 1
            for top in errors:
                for e in leaves(top):
                    print(f"{name}: {path_text(e.absolute_path)}: {e.message}")
        else:
            passed += 1
    print(f"schema_check: {passed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
