"""Energy split of the final-state summary (folds, panel bending, bars) and its row in the
`barhinge fold` table, checked against the hinge and bar energies recomputed from the path's
coordinates: `1/2 k (rho - rho0)^2` per hinge, split by the hinge kind."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from typer.testing import CliRunner

import barhinge as bh
from barhinge.analysis.final_state import energy_split, final_state_results
from barhinge.cli import app
from barhinge.output.summary import energy_share_text, flat_start_text

MAT = bh.Material(E=1e6, nu=0.3, t=0.01)
KEYS = ("fold", "bend", "bars")


@pytest.fixture(scope="module")
def solved():
    """A 2 x 2 Miura sheet from flat, panels only 100 x stiffer than the folds (so bending
    and bars hold a visible share), one zig-zag actuator to half its target."""
    cp = bh.families.miura(2, 2)
    z = int(bh.families.miura_layout(2, 2).interior_zigzag_edges[0])
    model = bh.BarHingeModel.from_pattern(cp, scheme="N5B8", material=MAT, stiffness_ratio=100.0)
    acts = bh.Actuators(edges=[z], targets_deg=[0.5 * cp.fold_angles[z]])
    return model, bh.solve(bh.Scene(model, actuators=acts, steps=4))


def _recomputed(model, X) -> dict[str, float]:
    """Energies at X from the geometry: linear hinges by kind, bars by the model's law."""
    rho = model.hinge_angles(X)
    w = 0.5 * np.asarray(model.hinge_k) * (rho - np.asarray(model.rest_angle)) ** 2
    kind = np.asarray(model.hinge_kind)
    wb, _ = model.element_energies(X)
    return {"fold": w[kind == "fold"].sum(), "bend": w[kind == "bend"].sum(), "bars": wb.sum()}


@pytest.mark.parametrize("step", [2, -1])
def test_energy_split_sums_to_one_and_matches_the_geometry(solved, step):
    model, fp = solved
    e = energy_split(fp, step=step)
    ref = _recomputed(model, fp.X[step])
    total = sum(ref.values())
    assert sum(e[f"energy_fraction_{k}"] for k in KEYS) == pytest.approx(1.0, abs=1e-12)
    for k in KEYS:
        assert e[f"energy_{k}"] == pytest.approx(ref[k], rel=1e-9, abs=1e-12 * total)
        assert e[f"energy_fraction_{k}"] == pytest.approx(ref[k] / total, abs=1e-9)
    assert e["energy_total"] == fp.energy[step]
    # the case has all three parts (a split that hides one would pass the sum)
    assert min(e[f"energy_fraction_{k}"] for k in KEYS) > 1e-6


def test_summary_record_carries_the_split(solved):
    model, fp = solved
    s = final_state_results(fp, model, modes=0)
    e = energy_split(fp)
    for key, value in e.items():
        assert s[key] == value, key
    json.dumps(s)  # JSON-friendly


def test_rigid_path_has_no_fractions():
    cp = bh.families.miura(1, 1)
    z = int(bh.families.miura_layout(1, 1).interior_zigzag_edges[0])
    fp = bh.rigid_fold(cp, [z], targets_deg=[0.5 * cp.fold_angles[z]], steps=3)
    e = energy_split(fp)
    assert math.isnan(e["energy_total"]) or e["energy_total"] == 0.0
    assert all(e[f"energy_fraction_{k}"] is None for k in KEYS)
    assert energy_share_text(fp) == ""


def test_one_line_texts(solved):
    _, fp = solved
    e = energy_split(fp)
    text = energy_share_text(fp)
    assert text.startswith("folds ") and ", panel bending " in text and ", bars " in text
    pct = [float(p.split()[-1]) for p in text.replace(" %", "").split(", ")]
    want = [100 * e[f"energy_fraction_{k}"] for k in KEYS]
    np.testing.assert_allclose(pct, want, rtol=0.06, atol=0.05)  # printed to 1-2 digits
    assert flat_start_text(fp).startswith("rigid panels, ")
    assert fp.meta["flat_start"]["branch"] in flat_start_text(fp)


def test_fold_command_prints_the_split_and_the_flat_start(tmp_path):
    cp = bh.families.miura(2, 2)
    z = int(bh.families.miura_layout(2, 2).interior_zigzag_edges[0])
    scene = tmp_path / "flat.toml"
    scene.write_text(
        'name = "flat"\n'
        '[pattern]\nfamily = "miura"\nparams = { nx = 2, ny = 2 }\n'
        '[model]\nscheme = "N5B8"\nmaterial = { E = 1.0e6, nu = 0.3, t = 0.01 }\n'
        "stiffness_ratio = 100.0\n"
        f"[actuators]\nedges = [{z}]\ntargets_deg = [{float(0.5 * cp.fold_angles[z])!r}]\n"
        '[solve]\nsteps = 4\ncontrol = "fold_angle"\n'
    )
    out = tmp_path / "out"
    res = CliRunner().invoke(app, ["fold", str(scene), "--out", str(out)])
    assert res.exit_code == 0, res.output
    text = " ".join(res.stdout.split())  # the table may wrap long values
    assert "energy share" in text and "panel bending" in text
    assert "flat start" in text and "rigid panels" in text
    fp = bh.FoldPath.load(out / "fold_path.npz")
    rec = json.loads((out / "summary.json").read_text())["results"]
    ref = _recomputed(bh.load_scene(scene).model, fp.X[-1])
    total = sum(ref.values())
    assert sum(rec[f"energy_fraction_{k}"] for k in KEYS) == pytest.approx(1.0, abs=1e-12)
    for k in KEYS:
        assert rec[f"energy_fraction_{k}"] == pytest.approx(ref[k] / total, abs=1e-9)
