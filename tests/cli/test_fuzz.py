"""Seeded CLI fuzzing (issue 11): corrupted databases and corrupted scenario files never give a
traceback — every run ends with exit 0, 1 or 2, and a 2 comes with one line on stderr.

The default suite runs a small sample; ``pytest -m slow`` runs ≥ 200 corrupted database files and
≥ 100 corrupted scenario files. Every case is reproducible from its seed (printed on failure).
"""

from __future__ import annotations

import random

import pytest
import yaml

from fms_testbed.cli import main
from fms_testbed.data import procedures_dir

EXCERPT = procedures_dir() / "cifp_excerpt.dat"
AIRPORT = "KDLS"          # small airport of the excerpt: 24 procedure records

_BYTES = [b"\xb2", b"\xe9", b"\x85", b"\x0c", b"\x1c", b"\x00", b"9", b" ", b"-", b"X", b"\t"]


def _slice() -> list[bytes]:
    """Header + every record that mentions the airport or its region's fixes (small, flyable)."""
    lines = EXCERPT.read_bytes().split(b"\n")
    keep = [ln for ln in lines if ln.startswith(b"HDR") or AIRPORT.encode() in ln[:20]
            or ln[:5] in (b"SUSAD", b"SUSAE", b"SUSAP")]
    return [ln for ln in keep if ln]


def corrupt_database(rng: random.Random, lines: list[bytes]) -> bytes:
    """One seeded corruption of the database lines (bytes changed, lines truncated, extended,
    duplicated, reordered, deleted, the whole file doubled)."""
    lines = list(lines)
    for _ in range(rng.randint(1, 4)):
        op = rng.choice(["byte", "byte", "truncate", "extend", "dup", "swap", "delete", "double",
                         "garbage", "digits"])
        i = rng.randrange(len(lines))
        ln = lines[i]
        if op == "byte" and ln:
            j = rng.randrange(len(ln))
            lines[i] = ln[:j] + rng.choice(_BYTES) + ln[j + 1:]
        elif op == "digits" and ln:
            j = rng.randrange(len(ln))
            lines[i] = ln[:j] + str(rng.randint(0, 9)).encode() * rng.randint(1, 5) + ln[j + 5:]
        elif op == "truncate":
            lines[i] = ln[: rng.randrange(len(ln) + 1)]
        elif op == "extend":
            lines[i] = ln + b"X" * rng.randint(1, 40)
        elif op == "dup":
            lines.insert(i, ln)
        elif op == "swap":
            k = rng.randrange(len(lines))
            lines[i], lines[k] = lines[k], lines[i]
        elif op == "delete" and len(lines) > 2:
            del lines[i]
        elif op == "double":
            lines = lines + lines
        elif op == "garbage":
            lines.insert(i, bytes(rng.randrange(256) for _ in range(rng.randint(0, 140))))
    return b"\n".join(lines) + b"\n"


BASE_SCENARIO = {
    "name": "fuzz", "aircraft": "737", "duration_s": 3,
    "initial": {"lat_deg": 47.0, "lon_deg": 8.0, "alt_m": 3000, "tas_kmh": 400,
                "heading_deg": 90},
    "wind": {"from_deg": 270, "speed_kt": 10},
    "navigation": {"source": "truth"},
    "events": [{"t_s": 1, "bank_deg": 10}, {"when": {"alt_m_above": 2900}, "cas_kt": 250}],
}
_VALUES = [True, None, "x", -1, 0, 1e308, float("inf"), float("nan"), [], {}, "737", 1e-9,
           "ñ", 10 ** 20, -400, 999999]


def corrupt_scenario(rng: random.Random) -> bytes:
    """One seeded corruption of a small scenario: a value replaced by another type or an extreme,
    a key renamed or dropped, or the YAML text damaged."""
    raw = yaml.safe_load(yaml.safe_dump(BASE_SCENARIO))
    nodes = [(raw, k) for k in raw] + [(raw["initial"], k) for k in raw["initial"]] + \
        [(raw["wind"], k) for k in raw["wind"]] + [(raw["events"][0], k) for k in raw["events"][0]]
    for _ in range(rng.randint(1, 3)):
        parent, key = rng.choice(nodes)
        if key not in parent:
            continue
        op = rng.choice(["value", "value", "rename", "drop"])
        if op == "value":
            parent[key] = rng.choice(_VALUES)
        elif op == "rename":
            parent[key + "_x"] = parent.pop(key)
        else:
            parent.pop(key)
    if isinstance(raw.get("duration_s"), (int, float)) and not isinstance(raw["duration_s"], bool) \
            and raw["duration_s"] == raw["duration_s"] and abs(raw["duration_s"]) > 10:
        raw["duration_s"] = 3          # keep flights short; validation of the rest is the point
    text = yaml.safe_dump(raw, allow_unicode=True).encode()
    if rng.random() < 0.3:
        j = rng.randrange(len(text))
        text = text[:j] + rng.choice([b":", b"{", b"\xff", b"\t", b"- ", b"\n  "]) + text[j:]
    return text


def _run(argv, capsys):
    try:
        rc = main(argv)
    except SystemExit as exc:            # argparse errors exit 2 with usage: allowed
        rc = exc.code
    err = capsys.readouterr().err
    assert rc in (0, 1, 2), (argv, rc, err[-1500:])
    assert "Traceback" not in err, err[-3000:]
    if rc == 2 and not err.startswith("usage:"):
        assert len(err.strip().splitlines()) == 1, err
    return rc


def _database_cases(n: int, seed0: int, tmp_path, capsys):
    lines = _slice()
    for seed in range(seed0, seed0 + n):
        rng = random.Random(seed)
        db = tmp_path / f"db{seed}.dat"
        db.write_bytes(corrupt_database(rng, lines))
        _run(["procedures", "check", "--db", str(db), "--no-progress", "--out",
              str(tmp_path / f"check{seed}")], capsys)
        _run(["procedures", "build", "--db", str(db), "--airport", AIRPORT, "--out",
              str(tmp_path / f"build{seed}")], capsys)


def _scenario_cases(n: int, seed0: int, tmp_path, capsys):
    for seed in range(seed0, seed0 + n):
        rng = random.Random(seed)
        f = tmp_path / f"s{seed}.yaml"
        f.write_bytes(corrupt_scenario(rng))
        _run(["run", str(f), "--no-plots", "--out", str(tmp_path / f"run{seed}")], capsys)


def test_corrupted_databases_sample(tmp_path, capsys):
    _database_cases(12, 0, tmp_path, capsys)


def test_corrupted_scenarios_sample(tmp_path, capsys):
    _scenario_cases(12, 0, tmp_path, capsys)


@pytest.mark.slow
def test_corrupted_databases_200(tmp_path, capsys):
    _database_cases(200, 1000, tmp_path, capsys)


@pytest.mark.slow
def test_corrupted_scenarios_100(tmp_path, capsys):
    _scenario_cases(100, 1000, tmp_path, capsys)
