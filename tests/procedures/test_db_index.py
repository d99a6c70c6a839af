"""The database index: a database loaded through it answers every query as the parsed one does,
it is rebuilt when the file or the parser changes, a broken index is ignored, and the whole CIFP
loads in ≤ 1 s (slow)."""

from __future__ import annotations

import os
import time
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fms_testbed.procedures import index as idx
from fms_testbed.procedures.database import load_database
from fms_testbed.procedures.index import PackedMapping, load_index

CIFP = Path(__file__).resolve().parents[3] / "shared" / "data" / "cifp" / "FAACIFP18_230126"


@pytest.fixture
def cache(tmp_path, monkeypatch):
    folder = tmp_path / "cache"
    monkeypatch.setenv("FMS_TESTBED_CACHE", str(folder))
    return folder


def _same_database(a, b) -> None:
    assert a.airport_idents() == b.airport_idents()
    for apt in a.airport_idents():
        assert a.procedure_index(apt) == b.procedure_index(apt)
        sa, sb = a.sequences(apt), b.sequences(apt)
        assert sa == sb
        for seq in sa:
            for lg in seq.legs:
                for ref in (lg.fix, lg.navaid, lg.centre):
                    assert a.find_fix(ref, apt) == b.find_fix(ref, apt)
        assert a.airports.get(apt) == b.airports.get(apt)


def test_index_answers_as_the_parsed_database(cache):
    first = load_index(None)
    second = load_index(None)
    assert (first.source, second.source) == ("parsed", "index")
    assert isinstance(second.db.fixes, PackedMapping)
    _same_database(load_database(None), second.db)
    assert second.sha256 == first.sha256
    assert (second.line_digests == first.line_digests).all()
    assert second.line_digests.size == second.db.n_lines


def test_changed_file_is_parsed_again(cache, tmp_path):
    src = Path(load_index(None).path)
    copy = tmp_path / "db.dat"
    copy.write_bytes(src.read_bytes())
    a = load_index(copy)
    assert load_index(copy).source == "index"
    lines = copy.read_text(encoding="latin-1").split("\n")
    k = next(i for i, ln in enumerate(lines) if ln.startswith("SUSAP KBFIK1D"))
    lines[k] = lines[k][:40] + ("A" if lines[k][40] != "A" else "B") + lines[k][41:]
    copy.write_text("\n".join(lines), encoding="latin-1")
    os.utime(copy, ns=(time.time_ns(), time.time_ns() + 10**9))   # a new stat as well
    b = load_index(copy)
    assert b.source == "parsed" and b.sha256 != a.sha256
    changed = (a.line_digests != b.line_digests).nonzero()[0]
    assert list(changed) == [k]
    assert len(list(cache.glob("*.pickle"))) == 2     # embedded + the copy's newest only


def test_parser_change_rebuilds_the_index(cache, monkeypatch):
    load_index(None)
    assert load_index(None).source == "index"
    monkeypatch.setattr(idx, "parser_hash", lambda: "0" * 64)
    assert load_index(None).source == "parsed"


def test_broken_index_is_ignored_and_rebuilt(cache):
    load_index(None)
    (f,) = cache.glob("*.pickle")
    f.write_bytes(b"not a pickle")
    assert load_index(None).source == "parsed"
    assert load_index(None).source == "index"


def test_use_cache_false_writes_nothing(cache):
    assert load_index(None, use_cache=False).source == "parsed"
    assert not cache.exists()


@settings(max_examples=40, deadline=None)
@given(st.dictionaries(st.tuples(st.text(max_size=4), st.text(max_size=2)),
                       st.lists(st.integers(), max_size=3), max_size=20))
def test_packed_mapping_is_the_dict(d):
    m = PackedMapping.pack(d)
    assert dict(m) == d and len(m) == len(d) and list(m) == list(d)
    for k, v in d.items():
        assert k in m and m.get(k) == v and m[k] == v
    assert m.get(("absent", "key!")) is None
    import pickle
    assert dict(pickle.loads(pickle.dumps(m))) == d


@pytest.mark.slow
@pytest.mark.skipif(not CIFP.exists(), reason="the FAA CIFP is not beside the repository")
def test_whole_cifp_index_loads_within_one_second(cache):
    load_index(CIFP)                 # parse and write the index
    best = min(load_index(CIFP).load_s for _ in range(3))
    assert best <= 1.0, f"index load {best:.2f} s"
