"""ARINC-424 field readers that reject what they cannot read, and the record error they report.

A field reader takes the record text and 1-based columns (as in ``shared/notes/arinc424.md``),
checks the field against its format and its range, and returns the value in the unit its name
says; anything else raises :class:`FieldError`. The loader turns a FieldError into a
:class:`RecordError` — plain data (file, line, columns, field, reason, the record text) — and
carries on with the next record: a bad record is never an exception out of the load.

What is checked:

* the record: 132 columns, every character in the ARINC-424 character set (upper-case letters,
  digits, space and the punctuation ``"#&'()+,-./:``; no lower case, no control or non-ASCII
  characters: ``str.isdigit()`` accepts '²' and other Unicode digits, so no reader relies on it);
* numbers: ASCII digits only (an optional leading '-' where the field is signed), no internal
  blanks, no '+' or '_' (both of which ``int()`` accepts), and the field's range, stated in the
  field's coded unit next to each reader (:data:`RANGES`).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from fms_testbed.core.units import FT_M

RECORD_COLUMNS = 132
"""Length of every ARINC-424 record, characters."""

_CHARSET = re.compile(r"[A-Z0-9 \"#&'()+,\-./:@]*")
_UNSIGNED = re.compile(r"[0-9]+")
_SIGNED = re.compile(r"-?[0-9]+")

RANGES: dict[str, tuple[int, int, str]] = {
    # field: (lowest, highest, coded unit) -- inclusive
    "latitude degrees": (0, 90, "deg"),
    "longitude degrees": (0, 180, "deg"),
    "minutes": (0, 59, "arc min"),
    "seconds": (0, 5999, "hundredths of an arc second"),
    "magnetic variation": (0, 1800, "tenths of a degree"),
    "altitude": (-2000, 60000, "ft"),
    "flight level": (1, 600, "hundreds of ft"),
    "transition altitude": (1000, 60000, "ft"),
    "elevation": (-2000, 30000, "ft"),
    "course": (0, 3600, "tenths of a degree"),
    "true course": (0, 360, "deg"),
    "theta": (0, 3600, "tenths of a degree"),
    "rho": (0, 9999, "tenths of a NM"),
    "distance": (1, 9999, "tenths of a NM"),
    "time": (1, 999, "tenths of a minute"),
    "arc radius": (1, 999999, "thousandths of a NM"),
    "speed limit": (30, 450, "kt"),
    "vertical angle": (-1000, 0, "hundredths of a degree"),
    "sequence number": (1, 999, ""),
    "runway bearing": (0, 3600, "tenths of a degree"),
    "runway length": (1, 99999, "ft"),
}
"""Accepted range of each numeric field, in the unit it is coded in. Chosen from the ARINC-424
field definitions and checked against the FAA CIFP 2301 (every clean record passes; the real
extremes are in ``docs/procedures-integrity.md``)."""


class FieldError(ValueError):
    """A field reader's rejection: 1-based ``column`` .. ``last_column``, ``field``, ``reason``."""

    def __init__(self, column: int, field: str, reason: str, last_column: int | None = None):
        super().__init__(f"column {column}: {field}: {reason}")
        self.column = column
        self.last_column = column if last_column is None else last_column
        self.field = field
        self.reason = reason


REJECTED_COLUMNS = ("file", "line", "columns", "field", "reason", "record")
"""Columns of ``rejected_records.csv`` (:meth:`RecordError.row`)."""


@dataclass(frozen=True, slots=True)
class RecordError:
    """One rejected record: where (file, 1-based line, 1-based columns), which field, why.

    ``text`` is the record as read (without its line break).
    """

    file: str
    line: int
    column: int
    field: str
    reason: str
    last_column: int = 0
    text: str = ""

    @property
    def columns(self) -> str:
        """'71-74', or '71' for a one-column field."""
        last = max(self.last_column, self.column)
        return f"{self.column}" if last == self.column else f"{self.column}-{last}"

    def __str__(self) -> str:
        return f"{self.file}:{self.line}: column {self.columns}: {self.field}: {self.reason}"

    def row(self) -> dict:
        """The row of ``rejected_records.csv``: file, line, columns, field, reason, record."""
        return {"file": self.file, "line": self.line, "columns": self.columns,
                "field": self.field, "reason": self.reason, "record": self.text}

    @classmethod
    def from_field(cls, exc: FieldError, file: str, line: int, text: str) -> "RecordError":
        """The record error of a :class:`FieldError` raised while reading ``text``."""
        return cls(file, line, exc.column, exc.field, exc.reason, exc.last_column, text)


def check_record(rec: str) -> None:
    """Reject a record that is not 132 columns of the ARINC-424 character set.

    Raises
    ------
    FieldError
        at the first column past the end (length) or at the first bad character.
    """
    m = _CHARSET.match(rec)
    if m.end() < len(rec):
        k = m.end()
        ch = rec[k]
        raise FieldError(k + 1, "character set",
                         f"character {ch!r} (U+{ord(ch):04X}) is not in the ARINC-424 "
                         "character set (upper-case letters, digits, space, punctuation)")
    if len(rec) != RECORD_COLUMNS:
        raise FieldError(min(len(rec), RECORD_COLUMNS) + 1, "record length",
                         f"record has {len(rec)} columns, expected {RECORD_COLUMNS}")


def in_range(v: int, rng: str, col: int, last: int, shown: str, field: str = "") -> int:
    """``v`` when it lies in ``RANGES[rng]``; else :class:`FieldError` at ``col``..``last``
    naming ``field`` (default ``rng``)."""
    lo, hi, unit = RANGES[rng]
    if not lo <= v <= hi:
        raise FieldError(col, field or rng, f"{shown!r} is out of range [{lo}, {hi}]"
                         f"{' ' + unit if unit else ''}", last)
    return v


def read_int(rec: str, a: int, b: int, what: str, signed: bool = False,
             rng: str | None = None) -> int | None:
    """Integer field in 1-based columns ``a..b``: None when blank, else ASCII digits (and an
    optional '-' when ``signed``) checked against ``RANGES[rng or what]``."""
    raw = rec[a - 1:b]
    s = raw.strip()
    if not s:
        return None
    if not (_SIGNED if signed else _UNSIGNED).fullmatch(s):
        raise FieldError(a, what, f"{raw!r} is not {'a signed' if signed else 'an unsigned'} "
                                  "number of ASCII digits", b)
    return in_range(int(s), rng or what, a, b, raw, what)


def read_code(rec: str, a: int, b: int, what: str, allowed) -> str:
    """Code field in columns ``a..b`` that must be one of ``allowed`` (as coded, unstripped)."""
    s = rec[a - 1:b]
    if s not in allowed:
        shown = ", ".join(repr(x) for x in sorted(allowed))
        raise FieldError(a, what, f"{s!r} is not one of {shown}", b)
    return s


def read_ident(rec: str, a: int, b: int, what: str, procedure: bool = False,
               required: bool = False) -> str:
    """Ident field in columns ``a..b``, left-justified letters and digits ('-' too in a
    procedure ident), stripped; '' when blank (an error when ``required``)."""
    raw = rec[a - 1:b]
    s = raw.rstrip(" ")
    if not s:
        if required:
            raise FieldError(a, what, "is blank", b)
        return ""
    core = s.replace("-", "") if procedure and s[0] != "-" else s
    if not (core.isascii() and core.isalnum() and (core.isupper() or core.isdigit())):
        raise FieldError(a, what, f"{raw!r} is not a left-justified ident of upper-case "
                                  f"letters and digits{' (and -)' if procedure else ''}", b)
    return s


def _angle(s: str, col: int, hemis: str, ndeg: int, what: str) -> float:
    n = 1 + ndeg + 6
    if len(s) < n or s[0] not in hemis or not _UNSIGNED.fullmatch(s[1:n]):
        raise FieldError(col, what, f"{s!r} is not {'/'.join(hemis)} + "
                                    f"{'D' * ndeg}MMSSss in ASCII digits", col + n - 1)
    last = col + n - 1
    deg = in_range(int(s[1:1 + ndeg]), f"{what} degrees", col, last, s, what)
    mnt = in_range(int(s[1 + ndeg:3 + ndeg]), "minutes", col, last, s, f"{what} minutes")
    cs = in_range(int(s[3 + ndeg:n]), "seconds", col, last, s, f"{what} seconds")
    v = deg + mnt / 60.0 + cs / 360000.0
    if v > RANGES[f"{what} degrees"][1]:
        raise FieldError(col, what, f"{s!r} is beyond {RANGES[f'{what} degrees'][1]} deg", last)
    return -v if s[0] in "SW" else v


def parse_lat(rec: str, col: int) -> float:
    """Latitude 'NDDMMSSss' at ``col`` (9 columns), deg (north +)."""
    return _angle(rec[col - 1:col + 8], col, "NS", 2, "latitude")


def parse_lon(rec: str, col: int) -> float:
    """Longitude 'EDDDMMSSss' at ``col`` (10 columns), deg (east +)."""
    return _angle(rec[col - 1:col + 9], col, "EW", 3, "longitude")


def parse_magvar(rec: str, col: int) -> float:
    """Magnetic variation 'E0127' / 'W0127' (tenths of a degree) at ``col``, deg (east +).

    'T' (true-referenced station) and blank give 0. At most 180.0°.
    """
    s = rec[col - 1:col + 4]
    if not s.strip() or s[0] == "T":
        return 0.0
    if s[0] not in "EW" or not _UNSIGNED.fullmatch(s[1:]):
        raise FieldError(col, "magnetic variation",
                         f"{s!r} is not E/W + tenths of a degree in 4 ASCII digits", col + 4)
    v = in_range(int(s[1:]), "magnetic variation", col, col + 4, s) / 10.0
    return v if s[0] == "E" else -v


def parse_alt_ft(rec: str, a: int, what: str = "altitude") -> float | None:
    """Altitude field (5 columns) at ``a``: feet or 'FLnnn'; blank, 'UNKNN', 'NESTB' -> None.

    Returns metres.
    """
    raw = rec[a - 1:a + 4]
    s = raw.strip()
    if not s or s in ("UNKNN", "NESTB"):
        return None
    if s.startswith("FL"):
        if not re.fullmatch(r"FL[0-9]{3}", s):
            raise FieldError(a, what, f"flight level {raw!r} is not FL + 3 ASCII digits", a + 4)
        return in_range(int(s[2:]), "flight level", a, a + 4, raw, what) * 100 * FT_M
    if not _SIGNED.fullmatch(s):
        raise FieldError(a, what, f"{raw!r} is neither feet in ASCII digits nor FLnnn", a + 4)
    return in_range(int(s), "altitude", a, a + 4, raw, what) * FT_M
