"""The pattern catalogue (data/patterns/*.fold) and the ``barhinge patterns`` command."""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path

import numpy as np
import pytest

import barhinge as bh
from barhinge.cli import main

REPO = Path(__file__).resolve().parents[2]
DATA = REPO / "data" / "patterns"
FILES = sorted(DATA.glob("*.fold"))


def _catalogue_script():
    """scripts/make_catalogue.py as a module (registered so its dataclass can resolve)."""
    name = "barhinge_make_catalogue"
    if name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.spec_from_file_location(name, REPO / "scripts" / "make_catalogue.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules[name] = mod
    spec.loader.exec_module(mod)
    return mod


def _same(a, b) -> None:
    np.testing.assert_allclose(a.vertices, b.vertices, rtol=0, atol=1e-12)
    assert np.array_equal(a.edges, b.edges)
    assert np.array_equal(a.assignment, b.assignment)
    np.testing.assert_allclose(a.fold_angles, b.fold_angles, rtol=0, atol=1e-12)
    assert a.faces == b.faces
    assert a.developable == b.developable


def test_catalogue_has_at_least_40_patterns():
    assert len(FILES) >= 40
    assert (DATA / "LICENSES.md").is_file()
    assert (DATA / "miura_4x4_a60.fold").is_file()  # quoted in docs/index.md


@pytest.mark.parametrize("path", FILES, ids=[p.stem for p in FILES])
def test_catalogue_file_round_trips(path, tmp_path):
    cp = bh.read_fold(path)
    out = bh.write_fold(cp, tmp_path / path.name)
    again = bh.read_fold(out)
    _same(cp, again)
    data = json.loads(path.read_text())
    for k in range(1, len(data.get("file_frames", [])) + 1):
        _same(bh.read_fold(path, frame=k), bh.read_fold(out, frame=k))


def test_generated_files_are_up_to_date():
    """Regenerating every catalogue entry reproduces its FOLD file (flat and folded frame)."""
    mod = _catalogue_script()
    assert len(mod.ENTRIES) >= 40 - len(mod.REAL)
    for entry in mod.ENTRIES:
        cp, folded = mod.make_entry(entry)
        path = DATA / f"{entry.name}.fold"
        _same(cp, bh.read_fold(path))
        if folded is not None:
            f1 = bh.read_fold(path, frame=1)
            np.testing.assert_allclose(f1.vertices, folded.vertices, rtol=0, atol=1e-12)


def test_real_files_carry_their_source():
    mod = _catalogue_script()
    lic = (DATA / "LICENSES.md").read_text()
    for name, rel, _source, _ in mod.REAL:
        path = DATA / f"{name}.fold"
        if not path.exists():
            continue
        meta = bh.read_fold(path).meta
        assert "MIT" in meta["file_description"]
        assert rel in meta["barhinge:source"]
        assert f"`{name}.fold`" in lic


# ----------------------------------------------------------------------- CLI
def _run(monkeypatch, capsys, *args):
    monkeypatch.setattr(sys, "argv", ["barhinge", *args])
    code = 0
    try:
        main()
    except SystemExit as exc:
        code = exc.code or 0
    out = capsys.readouterr()
    return code, out.out, out.err


def test_cli_lists_families(monkeypatch, capsys):
    code, out, _ = _run(monkeypatch, capsys, "patterns", "--json")
    assert code == 0
    data = json.loads(out)
    assert set(data) == set(bh.families.FAMILIES)
    assert data["miura"]["parameters"]["alpha"] == 60.0
    assert data["miura"]["exact_fold"] is True
    code, out, _ = _run(monkeypatch, capsys, "patterns")
    assert code == 0 and "russo_pleat" in out


def test_cli_writes_a_pattern(monkeypatch, capsys, tmp_path):
    path = tmp_path / "m.fold"
    code, out, _ = _run(
        monkeypatch, capsys, "patterns", "miura", "--param", "nx=2", "--param", "alpha=50",
        "-p", "fold=30", "--out", str(path),
    )  # fmt: skip
    assert code == 0, out
    cp = bh.read_fold(path)
    _same(cp, bh.families.miura(2, 4, alpha=50.0, fold=30.0))
    code, out, _ = _run(
        monkeypatch, capsys, "patterns", "miura_nonuniform", "-p", "a=1,2,1", "-p", "b=[1, 0.5]",
        "--json",
    )  # fmt: skip
    assert code == 0
    assert json.loads(out)["n_vertices"] == 4 * 3


@pytest.mark.parametrize(
    "args,needle",
    [
        (("patterns", "miura", "--param", "beta=3"), "unknown parameter 'beta'"),
        (("patterns", "miura", "--param", "alpha=95"), "alpha = 95"),
        (("patterns", "miura", "--param", "alpha"), "NAME=VALUE"),
        (("patterns", "nosuch"), "unknown pattern family"),
    ],
)
def test_cli_bad_input_exits_2_with_one_line(monkeypatch, capsys, args, needle):
    code, _, err = _run(monkeypatch, capsys, *args)
    assert code == 2
    assert needle in err
    assert len(err.strip().splitlines()) == 1


# ------------------------------------------------- CreasePattern.edge_faces (vectorised)
def _edge_faces_loop(cp) -> np.ndarray:
    """Slow reference: walk every face side (the original per-face loop)."""
    EF = -np.ones((cp.n_edges, 2), dtype=np.int64)
    idx = {(min(a, b), max(a, b)): e for e, (a, b) in enumerate(cp.edges.tolist())}
    for fi, f in enumerate(cp.faces):
        for a, b in zip(f, f[1:] + f[:1], strict=True):
            e = idx[(min(a, b), max(a, b))]
            EF[e, 0 if cp.edges[e, 0] == a else 1] = fi
    return EF


@pytest.mark.parametrize("stem", ["miura_4x4_a60", "resch_6x6", "os_huffmanWaterbomb", "hypar_5"])
def test_edge_faces_matches_reference_loop(stem):
    cp = bh.read_fold(DATA / f"{stem}.fold")
    assert np.array_equal(cp.edge_faces, _edge_faces_loop(cp))


def test_edge_faces_errors():
    V = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    E = np.array([[0, 1], [1, 2], [2, 3], [3, 0]])
    twice = bh.CreasePattern(V, E, ["B"] * 4, faces=[[0, 1, 2, 3]] * 2, validate=False)
    with pytest.raises(bh.PatternError, match="same direction by faces 0 and 1"):
        _ = twice.edge_faces
    missing = bh.CreasePattern(V, E, ["B"] * 4, faces=[[0, 1, 2]], validate=False)
    with pytest.raises(bh.PatternError, match=r"face 0 uses side \(2, 0\)"):
        _ = missing.edge_faces
