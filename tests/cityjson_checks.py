"""cjval's checks of a CityJSON 2.0 document, for tests (``cjvalpy`` has no Linux cp311 wheel).

:func:`cityjson_errors` runs what ``cjval`` (the official validator, cityjson/cjval
``src/lib.rs``) runs on a file without Extensions, appearances or templates: the
official schema (``tests/fixtures/cityjson``, through ``jsonschema``),
``parents_children_consistency``, ``wrong_vertex_index``, ``semantics_arrays``, and
its warnings ``extra_root_properties``, ``duplicate_vertices``, ``unused_vertices``.
Only the geometry types the export writes (MultiSurface, CompositeSurface) are walked.
"""

from __future__ import annotations

import gzip
import json
from functools import cache
from pathlib import Path

SCHEMA = Path(__file__).parent / "fixtures" / "cityjson" / "cityjson-2.0.min.schema.json.gz"
ROOT_PROPERTIES = ("type", "version", "extensions", "transform", "metadata", "CityObjects",
                   "vertices", "appearance", "geometry-templates")


@cache
def _validator():
    import jsonschema

    schema = json.loads(gzip.decompress(SCHEMA.read_bytes()))
    return jsonschema.Draft7Validator(schema)


def cityjson_errors(doc: dict) -> list[str]:
    """Every error and warning cjval would report (an empty list: valid, no warnings)."""
    errors = [f"schema: {e.message} at {'/'.join(map(str, e.absolute_path))}"
              for e in _validator().iter_errors(doc)]
    if errors:
        return errors
    errors += [f"extra root property {k}" for k in doc
               if not k.startswith("+") and k not in ROOT_PROPERTIES]
    objects = doc["CityObjects"]
    for key, co in objects.items():
        for child in co.get("children", []):
            if child not in objects or key not in objects[child].get("parents", []):
                errors.append(f"CityObject {child} does not reference its parent {key}")
        errors += [f"CityObject {key} is an orphan of {p}" for p in co.get("parents", [])
                   if p not in objects]
    n = len(doc["vertices"])
    used: set[int] = set()
    for key, co in objects.items():
        for g in co.get("geometry", []):
            if g["type"] not in ("MultiSurface", "CompositeSurface"):
                errors.append(f"{key}: geometry {g['type']} not checked here")
                continue
            indices = [i for surface in g["boundaries"] for ring in surface for i in ring]
            used.update(indices)
            errors += [f"{key}: vertex index {i} out of range" for i in indices if i >= n]
            sem = g.get("semantics")
            if sem is not None:
                if len(sem["values"]) != len(g["boundaries"]):
                    errors.append(f"{key}: semantic values not the shape of the boundaries")
                errors += [f"{key}: semantic value {v} overflows" for v in sem["values"]
                           if v is not None and v >= len(sem["surfaces"])]
    vertices = [tuple(v) for v in doc["vertices"]]
    if len(set(vertices)) != len(vertices):
        errors.append("duplicate vertices")
    if used != set(range(n)):
        errors.append(f"{n - len(used & set(range(n)))} unused vertices")
    return errors
