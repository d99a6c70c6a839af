"""Cut the embedded ARINC-424 excerpt out of the FAA CIFP (run from the repository root).

    python procedures/make_excerpt.py /work/shared/data/cifp/FAACIFP18_230126 procedures/cifp_excerpt.dat

Keeps the header records, every record of the chosen airports (airport, runways, localizers,
terminal waypoints/NDBs, SIDs, STARs, approaches, continuation records included) and the
enroute waypoints, VHF navaids and NDBs their procedures reference, in file order.
"""

from __future__ import annotations

import sys

from fms_testbed.procedures.database import load_database

#: Chosen so that every path terminator present in FAA data occurs (see procedures/README.md).
AIRPORTS = ("KJFK", "KBFI", "PAFA", "PABE", "KDLS", "2R6", "KENV", "KFXY", "PASD")


def main(src: str, dst: str) -> None:
    db = load_database(src)
    refs = set()
    for apt in AIRPORTS:
        for seq in db.sequences(apt):
            for leg in seq.legs:
                for r in (leg.fix, leg.navaid, leg.centre):
                    if r is not None:
                        f = db.find_fix(r, apt)
                        if f is not None:
                            refs.add(f.line)
    keep = []
    with open(src, encoding="latin-1") as fh:
        for i, rec in enumerate(fh, 1):
            if rec.startswith("HDR") or i in refs or (
                    rec[4:5] in ("P", "H") and rec[6:10].strip() in AIRPORTS):
                keep.append(rec)
    with open(dst, "w", encoding="latin-1") as out:
        out.writelines(keep)
    print(f"{dst}: {len(keep)} records from {src}")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
