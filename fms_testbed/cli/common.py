"""What several commands share: the scenario overrides (``--wind``, ``--isa-dev-c``, ``--nav``, ``--imu``,
``--aircraft``, ``--rnp``, ``--seed``), given and applied the same way in every command, and the
printed summary of a flight."""

from __future__ import annotations

import math
import re

from fms_testbed.core.errors import UserError
from fms_testbed.core.units import KMH_MPS, KT_MPS

WIND_HELP = ("steady wind FROM_DEG/SPEED_KT (deg true it blows from / kt), e.g. 270/20; "
             "a unit suffix selects another speed unit: 270/10mps, 270/36kmh")
_WIND_UNITS = {"": "speed_kt", "kt": "speed_kt", "mps": "speed_mps"}


def parse_wind(text: str) -> dict:
    """``FROM_DEG/SPEED[kt|mps|kmh]`` → the scenario's ``wind`` mapping (speed in kt by default).

    Raises
    ------
    UserError : the text is not of that form, or the direction/speed is out of range
    """
    m = re.fullmatch(r"\s*(\d+(?:\.\d*)?)\s*/\s*(\d+(?:\.\d*)?)\s*(kt|mps|kmh)?\s*", text or "")
    if not m:
        raise UserError(f"--wind {text!r}: expected FROM_DEG/SPEED_KT, e.g. 270/20 "
                        "(deg true from / kt; or 270/10mps, 270/36kmh)")
    d, s, unit = float(m.group(1)), float(m.group(2)), m.group(3) or ""
    kt = (s if unit in ("", "kt") else s / KT_MPS if unit == "mps"
          else s * KMH_MPS / KT_MPS)
    if d > 360 or kt > 200:
        raise UserError(f"--wind {text!r}: direction must be 0-360 deg and speed ≤ 200 kt")
    if unit == "kmh":
        return {"from_deg": d, "speed_mps": s * KMH_MPS}
    return {"from_deg": d, _WIND_UNITS[unit]: s}


ISA_DEV_HELP = ("temperature deviation from the ISA, °C, e.g. 15 or -20 (the same at every "
                "altitude; planned for and flown in JSBSim)")


def parse_isa_dev(value) -> float:
    """``--isa-dev-c`` text → the ISA deviation, °C (−60..60).

    Raises
    ------
    UserError : not a number, or out of range
    """
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise UserError(f"--isa-dev-c {value!r}: expected a number of °C, e.g. 15 or -20") from None
    if not (math.isfinite(v) and -60.0 <= v <= 60.0):
        raise UserError(f"--isa-dev-c {value!r}: must be within -60..60 °C")
    return v


SEED_MAX = 2 ** 63 - 1
"""Largest seed a command takes (the run records hold it as a signed 64-bit integer)."""


def bounded_int(lo: int, hi: int, what: str = "a whole number"):
    """An argparse ``type`` taking a whole number in ``lo..hi`` (anything else: argparse's
    one-line usage error, exit 2).

    Parameters
    ----------
    lo, hi : the bounds (inclusive); what : what the number is, for the message
    """
    import argparse

    def parse(text: str) -> int:
        try:
            v = int(str(text).strip())
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r}: expected {what}") from None
        if not lo <= v <= hi:
            raise argparse.ArgumentTypeError(f"{text!r}: must be within {lo}..{hi}")
        return v

    parse.__name__ = what
    return parse


def bounded_float(lo: float, hi: float, unit: str, lo_open: bool = False):
    """An argparse ``type`` taking a finite number in ``lo..hi`` (``unit`` named in the message;
    ``lo_open``: ``lo`` itself refused).

    Parameters
    ----------
    lo, hi : the bounds; unit : the unit of the value (for the message)
    lo_open : the lower bound is excluded
    """
    import argparse

    def parse(text: str) -> float:
        try:
            v = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r}: expected a number of {unit}") from None
        if not (math.isfinite(v) and (lo < v if lo_open else lo <= v) and v <= hi):
            raise argparse.ArgumentTypeError(
                f"{text!r}: must be {'>' if lo_open else '>='} {lo:g} and <= {hi:g} {unit}")
        return v

    parse.__name__ = f"number of {unit}"
    return parse


SEED = bounded_int(0, SEED_MAX, "a seed (whole number >= 0)")
"""``--seed`` type of the commands that seed numpy only: 0..2**63 - 1."""
FLIGHT_SEED_MAX = 2 ** 31 - 1
"""Largest seed of a flight: JSBSim's ``simulation/randomseed`` is a signed 32-bit integer (a
larger value becomes -2**31, so every larger seed would fly the same turbulence)."""
FLIGHT_SEED = bounded_int(0, FLIGHT_SEED_MAX, "a seed (whole number >= 0)")
"""``--seed`` type of the flight commands: 0..2**31 - 1."""


def _cell(v) -> str:
    if isinstance(v, (list, tuple)):
        return " ".join(str(x) if str(x) else "-" for x in v)
    if isinstance(v, float):
        return "—" if not math.isfinite(v) else f"{v:.4g}"
    return str(v)


def text_table(df, right: tuple[str, ...] = ()) -> str:
    """A DataFrame as an aligned plain-text table for the terminal: text columns left-aligned,
    numbers (and the columns named in ``right``) right-aligned, lists joined with spaces (an
    empty item as '-'), non-finite floats as '—'."""
    cols = list(df.columns)
    cells = [[_cell(v) for v in df[c]] for c in cols]
    numeric = [df[c].dtype.kind in "iuf" or c in right for c in cols]
    widths = [max([len(c)] + [len(x) for x in col]) for c, col in zip(cols, cells)]

    def line(values):
        return "  ".join(v.rjust(w) if num else v.ljust(w)
                         for v, w, num in zip(values, widths, numeric)).rstrip()

    out = [line(cols), line(["-" * w for w in widths])]
    out += [line(row) for row in zip(*cells)]
    return "\n".join(out)


def _md(v) -> str:
    if isinstance(v, float):
        return "—" if not math.isfinite(v) else f"{v:.3g}" if abs(v) < 1000 else f"{v:.0f}"
    return str(v)


def markdown_table(df) -> str:
    """A DataFrame as a GitHub Markdown table (floats to 3 significant digits, non-finite '—')."""
    cols = list(df.columns)
    lines = ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    for _, r in df.iterrows():
        lines.append("| " + " | ".join(_md(r[c]) for c in cols) + " |")
    return "\n".join(lines)


def add_override_options(p, aircraft_default: str | None = None) -> None:
    """Add the scenario overrides to a command's parser (the same options in ``run`` and ``fly``)."""
    p.add_argument("--aircraft", default=aircraft_default,
                   help="aircraft name or YAML file" + (f" (default {aircraft_default})"
                                                        if aircraft_default else
                                                        " (overrides the scenario's)"))
    p.add_argument("--wind", help=WIND_HELP)
    p.add_argument("--isa-dev-c", metavar="DEG_C", help=ISA_DEV_HELP)
    p.add_argument("--nav", metavar="SOURCE",
                   help="navigation source guidance flies on: truth, or one of the registered "
                        "sources with an IMU (sins, ins_gnss, attitude_reference; an unknown "
                        "name lists them)")
    p.add_argument("--imu", help="IMU preset of the INS (with a --nav source other than truth)")
    p.add_argument("--rnp", type=bounded_float(0.0, 30.0, "NM", lo_open=True),
                   help="RNP, NM, where the procedure's records code none")
    p.add_argument("--allow-degraded", action="store_true",
                   help="fly a procedure with a rejected or duplicated record of its own "
                        "(refused by default; the summary lists what is in doubt)")
    p.add_argument("--seed", type=FLIGHT_SEED, default=0,
                   help="seed for turbulence and sensor errors (default 0; a scenario's "
                        "navigation.seed seeds the navigation errors instead)")
    p.add_argument("--missed", action="store_true",
                   help="approaches: go around at the MAP and fly the missed approach to its "
                        "holding fix and one holding circuit (procedure.missed)")


def overrides_from_args(args) -> dict:
    """The scenario overrides the command-line options give (only the options that were set)."""
    out: dict = {}
    if getattr(args, "aircraft", None):
        out["aircraft"] = args.aircraft
    if getattr(args, "wind", None):
        out["wind"] = parse_wind(args.wind)
    if getattr(args, "isa_dev_c", None) is not None:
        out["atmosphere"] = {"isa_dev_c": parse_isa_dev(args.isa_dev_c)}
    nav, imu = getattr(args, "nav", None), getattr(args, "imu", None)
    if nav is not None and nav != "truth":
        from fms_testbed.navigation import SOURCES     # lazy: the registry imports the filters

        if nav not in SOURCES:
            raise UserError(f"--nav {nav}: unknown navigation source (available: "
                            f"{', '.join(SOURCES)})")
        if not imu:
            raise UserError(f"--nav {nav} needs --imu PRESET")
        out["navigation"] = {"source": nav, "imu": imu}
    elif imu:
        raise UserError("--imu is only used with a --nav source other than truth")
    elif nav == "truth":
        out["navigation"] = {"source": "truth"}
    proc: dict = {}
    if getattr(args, "rnp", None) is not None:
        proc["rnp_nm"] = args.rnp
    if getattr(args, "allow_degraded", False):
        proc["allow_degraded"] = True
    if getattr(args, "missed", False):
        proc["missed"] = True
    if proc:
        out["procedure"] = proc
    return out


def print_results(res) -> None:
    """One line per result group: status; for procedure flights errors, RNP, constraints and
    sequencing; where the outputs are."""
    s = res.summary
    p = s.get("procedure")
    if p is None:
        print(f"{s['scenario']}: {s['status']} ({s['reason']}), {s['duration_s']:.0f} s flown in "
              f"{s['wall_time_s']:.1f} s wall ({s['real_time_factor']}x real time)")
    else:
        print(f"{p['name']} ({p['type']}, {len(p['legs'])} legs, {p['length_nm']} NM, monitor "
              f"{p['monitor_status']}): {s['status']} ({s['reason']}), {s['duration_s']:.0f} s "
              f"flown in {s['wall_time_s']:.1f} s wall")
        for d in p.get("degraded", []):
            print(f"  DEGRADED (--allow-degraded): {d}")
        e = s.get("errors", {})
        if e:
            f, t, n = e["fte"], e["tse"], e["nse"]
            print(f"  FTE95 {f['all']['p95_m']} m (straight {f['straight']['p95_m']} m), FTE max "
                  f"{f['all']['max_m']} m; TSE95 {t['all']['p95_m']} m; NSE95 "
                  f"{n['all']['p95_m']} m")
            r = s["rnp"]
            print(f"  RNP {r['min_rnp_nm']} NM: "
                  f"{'contained' if r['contained'] else 'NOT contained'}"
                  + (f" (legs {r['legs_not_contained']})" if r["legs_not_contained"] else ""))
        bad = [c for c in s.get("constraints", []) if c.get("ok") is False]
        print(f"  constraints: {len(s.get('constraints', []))} checked, {len(bad)} missed"
              + "".join(f"; leg {c['leg']} {c['fix']}: {c.get('why')}" for c in bad))
        thr = s.get("threshold")
        if thr and thr.get("crossed"):
            def fmt(v, f):
                return "n/a" if v is None else format(v, f)
            print(f"  threshold {thr['runway']}: CAS {thr['cas_kt']:.0f} kt (Vapp "
                  f"{fmt(thr['cas_minus_vapp_kt'], '+.1f')} kt), height {thr['height_ft']:.0f} ft "
                  f"(TCH {fmt(thr['height_minus_tch_ft'], '+.0f')} ft), path "
                  f"{fmt(thr['path_angle_deg'], '.2f')} deg (VPA "
                  f"{fmt(thr['path_angle_minus_vpa_deg'], '+.2f')} deg), "
                  f"{'configured' if thr['configured'] else 'not configured'}")
        elif thr:
            print(f"  threshold {thr['runway']}: {thr.get('reason')}")
        q = s.get("sequencing", {})
        print(f"  sequencing: {q.get('legs_entered')}/{q.get('legs')} legs entered, skipped "
              f"{q.get('skipped')}, repeated {q.get('repeated')}")
    if res.out_dir is not None:
        print(f"  outputs in {res.out_dir}: "
              + ", ".join(["timeseries.parquet", "summary.json"] + s.get("plots", [])
                        + s.get("tracks", [])))


def out_path(value: str | None, default=None):
    """The ``--out`` folder of a command: ``value``, or ``default`` when it is not given; an
    empty or blank value is refused (a one-line :class:`UserError`), never taken as ``.``.

    Parameters
    ----------
    value : the ``--out`` text (None: not given); default : the folder used then
    """
    from pathlib import Path

    if value is None:
        if default is None:
            raise UserError("--out: give the output folder")
        return Path(default)
    if not value.strip():
        raise UserError(f"--out {value!r}: give a folder name")
    return Path(value)


def add_overwrite_option(p) -> None:
    """``--overwrite``: replace an ``--out`` folder that holds other files than a previous run
    (a previous run of the testbed is always replaced as a whole)."""
    p.add_argument("--overwrite", action="store_true",
                   help="replace an --out folder that holds other files than a previous run")
