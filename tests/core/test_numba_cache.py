"""The guard that clears a package's numba cache when any of the sources its kernels inline changes."""

from __future__ import annotations

from fms_testbed.core._numba_cache import _STAMP, invalidate_if_sources_changed


def test_cache_cleared_when_a_source_changes_and_kept_otherwise(tmp_path):
    pkg = tmp_path / "pkg"
    pkg.mkdir()
    (pkg / "a.py").write_text("x = 1\n")
    (pkg / "b.py").write_text("y = 2\n")
    cache = pkg / "__pycache__"
    cache.mkdir()
    (cache / "a.f-1.py311.nbi").write_text("index")
    (cache / "b.g-2.py311.1.nbc").write_text("code")
    invalidate_if_sources_changed(pkg)          # first sight: no stamp yet -> cleared, stamped
    assert (cache / _STAMP).is_file() and not list(cache.glob("*.nb?"))
    (cache / "b.g-2.py311.1.nbc").write_text("code")
    assert invalidate_if_sources_changed(pkg) is False          # unchanged sources: kept
    assert (cache / "b.g-2.py311.1.nbc").exists()
    (pkg / "a.py").write_text("x = 3\n")                        # another file changed
    assert invalidate_if_sources_changed(pkg) is True
    assert not (cache / "b.g-2.py311.1.nbc").exists()


def test_an_inlined_file_of_another_package_invalidates_too(tmp_path):
    # the SINS kernels inline core/earth.py: an edit there must clear the SINS caches
    pkg, other = tmp_path / "pkg", tmp_path / "core"
    pkg.mkdir()
    other.mkdir()
    (pkg / "a.py").write_text("x = 1\n")
    (other / "earth.py").write_text("A = 1\n")
    (other / "unrelated.py").write_text("B = 1\n")
    invalidate_if_sources_changed(pkg, also_hash=(other / "earth.py",))
    (pkg / "__pycache__" / "a.f-1.py311.1.nbc").write_text("code")
    (other / "unrelated.py").write_text("B = 2\n")          # not hashed: cache kept
    assert invalidate_if_sources_changed(pkg, also_hash=(other / "earth.py",)) is False
    (other / "earth.py").write_text("A = 2\n")
    assert invalidate_if_sources_changed(pkg, also_hash=(other / "earth.py",)) is True
    assert not list((pkg / "__pycache__").glob("*.nbc"))


def test_unwritable_cache_is_not_an_error(tmp_path):
    pkg = tmp_path / "pkg"
    pkg.mkdir()
    (pkg / "a.py").write_text("x = 1\n")
    (pkg / "__pycache__").write_text("a file where the folder should be")
    assert invalidate_if_sources_changed(pkg) is False
