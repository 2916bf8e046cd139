#!/usr/bin/env python3
"""validate_json.py SCHEMA FILE...: each FILE against the JSON Schema SCHEMA (python3-jsonschema,
deploy/install-deps.sh); prints every violation with its path, exits 1 if there is any."""
import json
import sys

try:
    import jsonschema
except ImportError:
    sys.exit("validate_json.py: python3-jsonschema is missing (deploy/install-deps.sh installs it)")

schema = json.load(open(sys.argv[1]))
validator = jsonschema.Draft202012Validator(schema)
bad = 0
for path in sys.argv[2:]:
    errors = sorted(validator.iter_errors(json.load(open(path))), key=lambda e: list(e.absolute_path))
    for e in errors[:10]:
        print(f"{path}: {'/'.join(map(str, e.absolute_path)) or '(top)'}: {e.message[:200]}")
    bad += len(errors)
    if not errors:
        print(f"{path}: valid")
sys.exit(1 if bad else 0)
