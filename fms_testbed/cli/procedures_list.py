"""``fms-testbed procedures list``: what an ARINC-424 database holds.

    fms-testbed procedures list [--db FILE]                        # airports
    fms-testbed procedures list --airport KJFK                     # its procedures
    fms-testbed procedures list --airport KJFK --procedure DEEZZ5  # its transitions
    ... [--json]

The queries are :mod:`fms_testbed.procedures.catalogue`'s; this module only formats them, as an
aligned table on stdout (with a one-line header) or as a JSON array of records (``--json``).
An unknown airport or procedure is a one-line error naming the near matches (exit 2).
"""

from __future__ import annotations

import json

from fms_testbed.cli.common import text_table
from fms_testbed.core.errors import UserError


def cmd_list(args) -> int:
    """List the airports, one airport's procedures, or one procedure's transitions."""
    from fms_testbed.procedures import catalogue
    from fms_testbed.procedures.database import load_database

    if args.procedure and not args.airport:
        raise UserError("procedures list: --procedure needs --airport")
    db = load_database(args.db)
    if args.procedure:
        df = catalogue.transitions(db, args.airport, args.procedure)
        head = (f"{args.airport.upper()} {args.procedure.upper()}: {len(df)} transitions "
                f"(legs: path terminators; fixes: the fix of each leg, - when none)")
    elif args.airport:
        df = catalogue.procedures(db, args.airport)
        counts = df["type"].value_counts()
        head = (f"{args.airport.upper()}: " + ", ".join(
            f"{counts.get(t, 0)} {label}" for t, label in
            (("SID", "SIDs"), ("STAR", "STARs"), ("APPROACH", "approaches")))
            + f" in {db.path}")
    else:
        df = catalogue.airports(db)
        head = (f"{len(df)} airports with procedures in {db.path} "
                f"({int(df['transitions'].sum())} procedure transitions)")
    if args.json:
        print(json.dumps(df.to_dict(orient="records"), indent=1))
    else:
        print(head)
        print(text_table(df))
    return 0


def register(sub, db_option: dict) -> None:
    """Add ``procedures list`` to the ``procedures`` sub-parsers (``db_option``: the ``--db``
    keyword arguments the other sub-commands use)."""
    p = sub.add_parser("list", help="list the airports, procedures and transitions of a database",
                       description=__doc__.split("\n\n")[0])
    p.add_argument("--db", **db_option)
    p.add_argument("--airport", help="ICAO airport ident: list its procedures")
    p.add_argument("--procedure", help="procedure ident (with --airport): list its transitions")
    p.add_argument("--json", action="store_true", help="JSON records instead of a table")
    p.set_defaults(func=cmd_list)
