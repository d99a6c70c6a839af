"""The published JSON Schemas of what a run writes, shipped in ``fms_testbed/data/schemas/``:

* ``summary.schema.json`` — ``summary.json`` of every flight, generated from the
  :class:`~fms_testbed.run.summary.Summary` types (:func:`~fms_testbed.run.summary.summary_schema`);
* ``regress_row.schema.json`` — one row of a regression run's ``flights/`` dataset, generated
  from the row's Arrow schema (:data:`fms_testbed.campaign.rows.SCHEMA`) and its status
  vocabulary by :func:`arrow_row_schema`.

``python scripts/write_schemas.py`` regenerates both; a test checks the shipped files equal the
generated ones, and validates the summaries and rows the package writes against them
(:func:`validator`).
"""

from __future__ import annotations

import json
from importlib import resources

import pyarrow as pa

SUMMARY_SCHEMA = "summary.schema.json"
ROW_SCHEMA = "regress_row.schema.json"
DRAFT = "https://json-schema.org/draft/2020-12/schema"


def _json_type(t: pa.DataType) -> str:
    if pa.types.is_string(t) or pa.types.is_large_string(t):
        return "string"
    if pa.types.is_integer(t):
        return "integer"
    if pa.types.is_floating(t):
        return "number"
    if pa.types.is_boolean(t):
        return "boolean"
    raise ValueError(f"no JSON type for Arrow type {t}")


def arrow_row_schema(schema: pa.Schema, title: str, description: str = "",
                     enums: dict[str, list] | None = None) -> dict:
    """A JSON Schema for one row (a mapping column → value) of an Arrow table: every column
    required, no other; each column's JSON type from its Arrow type (string, integer, number,
    boolean), null allowed where the Arrow field is nullable; ``enums``: the allowed values of
    some columns.

    Parameters
    ----------
    schema : the table's Arrow schema; title, description : the schema's
    enums : column → allowed values (null stays allowed where the column is nullable)
    """
    enums = enums or {}
    props = {}
    for f in schema:
        typ = _json_type(f.type)
        p: dict = {"type": [typ, "null"] if f.nullable else typ}
        if f.name in enums:
            p["enum"] = list(enums[f.name]) + ([None] if f.nullable else [])
        props[f.name] = p
    return {"$schema": DRAFT, "title": title, "description": description, "type": "object",
            "properties": props, "required": list(schema.names), "additionalProperties": False}


def dumps_schema(schema: dict) -> str:
    """A schema as the shipped files hold it (sorted keys, 2-space indent, final newline)."""
    return json.dumps(schema, indent=2, sort_keys=True, ensure_ascii=False) + "\n"


def shipped(name: str) -> dict:
    """The schema ``name`` shipped in the package (``fms_testbed/data/schemas/NAME``)."""
    return json.loads(resources.files("fms_testbed.data").joinpath("schemas", name).read_text())


def validator(name: str):
    """A ``jsonschema`` validator of the shipped schema ``name`` (a test dependency)."""
    import jsonschema

    schema = shipped(name)
    cls = jsonschema.validators.validator_for(schema)
    cls.check_schema(schema)
    return cls(schema)


__all__ = ["DRAFT", "ROW_SCHEMA", "SUMMARY_SCHEMA", "arrow_row_schema", "dumps_schema",
           "shipped", "validator"]
