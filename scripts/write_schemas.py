"""Write the JSON Schemas shipped in ``fms_testbed/data/schemas/`` from the types they describe
(run from the repository root; ``tests/run/test_summary_schema.py`` checks the files are current).

    python scripts/write_schemas.py
"""

from __future__ import annotations

from pathlib import Path

from fms_testbed.run.schemas import ROW_SCHEMA, SUMMARY_SCHEMA, arrow_row_schema, dumps_schema
from fms_testbed.run.summary import summary_schema

OUT = Path(__file__).resolve().parents[1] / "fms_testbed" / "data" / "schemas"


def row_schema() -> dict:
    """The schema of a regression run's row, from :mod:`fms_testbed.campaign.rows`."""
    from fms_testbed.campaign import rows

    doc = (rows.__doc__ or "").strip().split("\n\n")[0]
    return arrow_row_schema(rows.SCHEMA, "fms-testbed regress row", doc,
                            {"status": list(rows.STATUSES),
                             "error_class": sorted(rows.ERROR_CLASSES)})


def schemas() -> dict[str, dict]:
    """File name → schema of every shipped schema."""
    return {SUMMARY_SCHEMA: summary_schema(), ROW_SCHEMA: row_schema()}


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    for name, schema in schemas().items():
        (OUT / name).write_text(dumps_schema(schema))
        print(f"wrote {OUT / name}")


if __name__ == "__main__":
    main()
