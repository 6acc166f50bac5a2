"""The calibration's answers kept between processes (``barhinge._disk_cache``): a kept answer
is bit for bit the one the code computes, a second process does not import the libraries
that compute it, and a damaged or unwritable cache costs a recomputation, never an error."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from barhinge import _disk_cache
from barhinge.cli import main
from barhinge.families import miura
from barhinge.model import calibrate
from barhinge.model import model as model_mod
from barhinge.model.material import Material
from barhinge.model.model import BarHingeModel

MAT = Material(E=1e6, nu=0.3, t=0.01)


def _sheet() -> BarHingeModel:
    """The default scene's model on a 2 x 2 sheet: bounded bar fits and the plate rule."""
    cp = miura(2, 2, a=1.0, b=1.0, alpha=60.0, fold=5.0)
    return BarHingeModel.from_pattern(cp, scheme="N5B8", material=MAT, fold_stiffness=1e-3)


@pytest.fixture
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """The cache on, in an empty folder of this test."""
    monkeypatch.delenv(_disk_cache.CACHE_SWITCH_ENV, raising=False)
    monkeypatch.setenv(_disk_cache.CACHE_DIR_ENV, str(tmp_path / "cache"))
    return tmp_path / "cache" / "arrays"


@pytest.fixture
def counted(monkeypatch: pytest.MonkeyPatch) -> dict[str, int]:
    """Counts of the two computations the cache keeps."""
    calls = {"fit": 0, "plate": 0}
    fit, plate = calibrate._bounded_fit, model_mod.plate_corner_stiffness

    def counting_fit(*a, **kw):
        calls["fit"] += 1
        return fit(*a, **kw)

    def counting_plate(*a, **kw):
        calls["plate"] += 1
        return plate(*a, **kw)

    monkeypatch.setattr(calibrate, "_bounded_fit", counting_fit)
    monkeypatch.setattr(model_mod, "plate_corner_stiffness", counting_plate)
    return calls


def _stiffnesses(m: BarHingeModel) -> tuple[np.ndarray, np.ndarray]:
    return np.array(m.bar_EA), np.array(m.hinge_k)


def test_kept_answers_are_bit_identical_and_not_recomputed(
    cache: Path, counted: dict[str, int], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv(_disk_cache.CACHE_SWITCH_ENV, "off")
    EA0, k0 = _stiffnesses(_sheet())
    computed = dict(counted)
    assert computed["fit"] > 0 and computed["plate"] > 0  # the sheet needs both
    assert not cache.exists()  # off writes nothing
    monkeypatch.delenv(_disk_cache.CACHE_SWITCH_ENV)
    EA1, k1 = _stiffnesses(_sheet())  # fills the cache
    # the plate rule's panel model has bounded fits of its own: kept too
    n_entries = _disk_cache.cache_info().entries
    assert n_entries >= 3
    before = dict(counted)
    EA2, k2 = _stiffnesses(_sheet())  # reads it
    assert counted == before  # nothing computed again
    for a, b in ((EA0, EA1), (EA0, EA2), (k0, k1), (k0, k2)):
        np.testing.assert_array_equal(a, b)
    assert _disk_cache.cache_info().entries == n_entries
    assert not list(cache.rglob(".tmp-*"))  # atomic writes leave no temporary files


def test_a_second_process_imports_neither_scipy_optimize_nor_scikit_fem(
    cache: Path, tmp_path: Path
) -> None:
    code = (
        "import sys, json; from barhinge.scene import default_scene; s = default_scene(); "
        "print(json.dumps([m in sys.modules for m in ('scipy.optimize', 'skfem')] + "
        "[float(s.model.bar_EA.sum()), float(s.model.hinge_k.sum())]))"
    )
    runs = [
        json.loads(
            subprocess.run(
                [sys.executable, "-c", code], capture_output=True, text=True, check=True
            ).stdout
        )  # fmt: skip
        for _ in range(2)
    ]
    assert runs[0][:2] == [True, True]  # the first process computes
    assert runs[1][:2] == [False, False]  # the second reads
    assert runs[1][2:] == runs[0][2:]


@pytest.mark.parametrize("damage", ["garbage", "empty", "shape", "nan"])
def test_a_damaged_entry_is_computed_again(
    cache: Path, counted: dict[str, int], damage: str
) -> None:
    EA0, k0 = _stiffnesses(_sheet())
    entries = sorted(cache.rglob("*.npy"))
    for path in entries:
        if damage == "garbage":
            path.write_bytes(b"not an array")
        elif damage == "empty":
            path.write_bytes(b"")
        elif damage == "shape":
            np.save(path, np.ones(7))
        else:
            np.save(path, np.full(np.load(path).shape, np.nan))
    before = dict(counted)
    EA1, k1 = _stiffnesses(_sheet())
    assert counted["fit"] > before["fit"] and counted["plate"] > before["plate"]
    np.testing.assert_array_equal(EA0, EA1)
    np.testing.assert_array_equal(k0, k1)
    for path in entries:  # rewritten whole
        assert np.all(np.isfinite(np.load(path)))


def test_an_unwritable_cache_is_skipped(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, counted: dict[str, int]
) -> None:
    monkeypatch.setenv(_disk_cache.CACHE_SWITCH_ENV, "off")
    EA0, k0 = _stiffnesses(_sheet())
    blocker = tmp_path / "a-file"
    blocker.write_text("the cache folder cannot be made inside a file")
    monkeypatch.delenv(_disk_cache.CACHE_SWITCH_ENV)
    monkeypatch.setenv(_disk_cache.CACHE_DIR_ENV, str(blocker))
    EA1, k1 = _stiffnesses(_sheet())
    np.testing.assert_array_equal(EA0, EA1)
    np.testing.assert_array_equal(k0, k1)
    assert _disk_cache.cache_info().entries == 0


def test_key_names_every_input() -> None:
    a = np.arange(6.0)
    base = _disk_cache.make_key("ns", a, "N5B8", 0.3, 4)
    assert base == _disk_cache.make_key("ns", a.copy(), "N5B8", 0.3, 4)
    others = [
        _disk_cache.make_key("other", a, "N5B8", 0.3, 4),
        _disk_cache.make_key("ns", a.reshape(2, 3), "N5B8", 0.3, 4),  # same bytes
        _disk_cache.make_key("ns", a.astype(np.float32), "N5B8", 0.3, 4),
        _disk_cache.make_key("ns", a + 1e-15 * (a == 1), "N5B8", 0.3, 4),  # one ulp
        _disk_cache.make_key("ns", a, "N4B5", 0.3, 4),
        _disk_cache.make_key("ns", a, "N5B8", 0.3000000000000001, 4),
        _disk_cache.make_key("ns", a, "N5B8", 0.3, 4.0),  # int and float differ
        _disk_cache.make_key("ns", a, "N5B8", 0.3, 4, libraries=("scipy",)),
    ]
    assert len({base, *others}) == len(others) + 1
    with pytest.raises(TypeError, match="cannot key the cache on a dict"):
        _disk_cache.make_key("ns", {"a": 1})


def test_the_code_fingerprint_follows_the_sources(tmp_path: Path) -> None:
    """Any edit of a source file makes every key new, so an entry is never an answer of
    older code."""
    (tmp_path / "pkg").mkdir()
    (tmp_path / "pkg" / "a.py").write_text("x = 1\n")
    (tmp_path / "pkg" / "b.py").write_text("y = 2\n")
    first = _disk_cache.source_fingerprint(tmp_path / "pkg")
    assert first == _disk_cache.source_fingerprint(tmp_path / "pkg")
    (tmp_path / "pkg" / "b.py").write_text("y = 3\n")
    assert _disk_cache.source_fingerprint(tmp_path / "pkg") != first


def test_cache_command_shows_and_clears(cache: Path, capsys: pytest.CaptureFixture) -> None:
    _sheet()
    main(["cache", "--json"])
    shown = json.loads(capsys.readouterr().out)
    assert shown["folder"] == str(cache) and shown["entries"] >= 3 and shown["bytes"] > 0
    main(["cache", "--clear"])
    assert f"removed {shown['entries']} entries" in capsys.readouterr().out
    assert _disk_cache.cache_info().entries == 0 and not cache.exists()


def test_cache_command_says_when_off(monkeypatch: pytest.MonkeyPatch, capsys) -> None:
    monkeypatch.setenv(_disk_cache.CACHE_SWITCH_ENV, "OFF")
    main(["cache"])
    assert "calibration cache: off" in capsys.readouterr().out
