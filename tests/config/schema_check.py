#!/usr/bin/python3
"""The shipped JSON schemas, read by an independent validator (python3-jsonschema) the way an
editor reads them: every example file is valid, and typical mistakes are flagged."""
import copy
import glob
import json
import sys

import jsonschema
import yaml

recipe_schema = json.load(open("recipes/recipe.schema.json"))
station_schema = json.load(open("recipes/station.schema.json"))
for schema in (recipe_schema, station_schema):
    jsonschema.Draft7Validator.check_schema(schema)
recipes = jsonschema.Draft7Validator(recipe_schema)
station = jsonschema.Draft7Validator(station_schema)

failures = []
files = sorted(glob.glob("recipes/*.recipe.yaml"))
if len(files) < 4:
    failures.append(f"expected at least 4 example recipes, found {files}")
for name in files:
    for error in recipes.iter_errors(yaml.safe_load(open(name))):
        failures.append(f"{name}: {error.message}")
for error in station.iter_errors(yaml.safe_load(open("recipes/station.yaml"))):
    failures.append(f"recipes/station.yaml: {error.message}")

# Mistakes the schema must flag, each on a copy of a valid recipe.
base = yaml.safe_load(open("recipes/bracket_registration.recipe.yaml"))
def mistake(description, change):
    broken = copy.deepcopy(base)
    change(broken)
    if not list(recipes.iter_errors(broken)):
        failures.append(f"schema accepts {description}")
mistake("an unknown key", lambda r: r["steps"][0].update(min_scor=0.5))
mistake("an unknown step kind", lambda r: r["steps"][1].update(kind="circel"))
mistake("a negative tolerance", lambda r: r["steps"][1]["checks"]["diameter"].update(tol_plus=-1))
mistake("a text id", lambda r: r.update(id="seven"))
mistake("an unknown PLC type", lambda r: r["steps"][1]["checks"]["diameter"]["plc"].update(type="u16"))
mistake("a circle without centre", lambda r: r["steps"][1].pop("centre"))

for f in failures:
    print(f)
print("ok" if not failures else f"{len(failures)} problem(s)")
sys.exit(1 if failures else 0)
