"""``--accuracy``: the lightest model meeting a requested accuracy (barhinge.analysis.accuracy).

References: a roof-like Miura sheet's stiffness extrapolated from finer levels than the chooser
computes (m = 8, 16, 32; Richardson) and from an independent model, the facet shell of
:mod:`barhinge.model.shell` (scikit-fem: CST membrane and Morley plate triangles on every
facet, meshes graded towards the corners, Richardson over r = 3, 4, 5); the default Miura
scene's form from the bar-and-hinge solver.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import barhinge as bh
from barhinge.analysis.accuracy import (
    _response,
    choose_model,
    parse_accuracy,
    richardson,
    subdivided_scene,
)
from barhinge.errors import ConfigError
from barhinge.loads import projected_load
from barhinge.scene import Scene, default_scene
from barhinge.solver.form import rigid_form

MAT = bh.Material(E=70e9, nu=0.33, t=2e-3)


def test_parse_accuracy():
    assert parse_accuracy("2%") == pytest.approx(0.02)
    assert parse_accuracy("0.5 %") == pytest.approx(0.005)
    assert parse_accuracy(0.1) == pytest.approx(0.1)
    for bad in ("two", "0%", "150%", -0.1):
        with pytest.raises(ConfigError, match="accuracy"):
            parse_accuracy(bad)


def test_richardson_recovers_a_power_law():
    # s(m) = 3 + 2 m^-1.5: exact limit and rate from three levels
    vals = [3 + 2 * m**-1.5 for m in (4, 8, 16)]
    ref, p, corr = richardson(vals)
    assert ref == pytest.approx(3.0, rel=1e-12)
    assert p == pytest.approx(1.5, rel=1e-12)


#: downward load per unit plan area on the roof (N/m^2)
Q = 1000.0


def _roof(fold: float = 50.0) -> Scene:
    """A 2 x 2 Miura sheet pinned along its two y-ends under a downward load per unit plan
    area, lumped to the facets' corners (a load every subdivision level reads back exactly)."""
    cp = bh.families.miura(nx=2, ny=2, fold=fold)
    model = bh.BarHingeModel.from_pattern(cp, "N5B8", MAT)
    S = np.zeros((model.n_nodes, 3), bool)
    S[_support_vertices(cp)] = True
    return Scene(model=model, supports=S, loads=projected_load(model, Q), name="miura roof")


def _support_vertices(cp) -> np.ndarray:
    y = np.asarray(cp.vertices3d)[:, 1]
    return np.flatnonzero((y < y.min() + 1e-9) | (y > y.max() - 1e-9))


@pytest.fixture(scope="module")
def levels() -> dict:
    """The chooser's level responses, shared by the tests of one roof."""
    return {}


@pytest.fixture(scope="module")
def roof_reference() -> tuple[float, list[float]]:
    """(Richardson limit of the roof's stiffness from m = 8, 16, 32; the values at m = 2 ...
    32): levels finer than the chooser computes."""
    scene = _roof()
    values = [_response(subdivided_scene(scene, m))[0]["stiffness"] for m in (2, 4, 8, 16, 32)]
    return richardson(values[2:])[0], values


@pytest.fixture(scope="module")
def shell_reference() -> tuple[float, float]:
    """(stiffness Q_t^2 / (f . u), relative Richardson correction) of the roof's facet shell:
    the same folded geometry, load per plan area, pinned support lines and crease stiffness
    per length, meshes graded 2 towards the corners, r = 2 ... 5."""
    from barhinge.analysis.accuracy import _crease_k_per_length
    from barhinge.model.shell import shell_model

    scene = _roof()
    cp = scene.model.pattern
    kpl = _crease_k_per_length(scene.model)
    ck = float(kpl[kpl > 0][0])
    assert np.allclose(kpl[kpl > 0], ck)
    sv = _support_vertices(cp)
    E = np.asarray(cp.edges)
    se = np.flatnonzero(np.isin(E, sv).all(axis=1))
    vals = []
    for r in (2, 3, 4, 5):
        sh = shell_model(cp, MAT, r, crease_stiffness=ck, grading=2)
        f = sh.surface_load((0.0, 0.0, -Q), per="plan")
        u = sh.solve(f, np.union1d(sh.nodes_on_edges(se), sv))
        qt = float(-sh.translations(f)[:, 2].sum())
        vals.append(qt**2 / float(f @ u))
    ref, _, corr = richardson(vals)
    return ref, corr / ref


def test_lumped_face_loads_are_read_back_exactly():
    """A load lumped from face loads (plan load) is the m = 1 level's load to round-off, and
    every level carries the same total; equal loads on every vertex are no lumped face load
    and are spread over the tributary areas instead."""
    from barhinge.analysis.accuracy import _spread_loads
    from barhinge.pattern.subdivide import subdivided

    scene = _roof()
    cp, nv = scene.model.pattern, scene.model.pattern.n_vertices
    F = np.asarray(scene.loads)[:nv]
    assert np.abs(_spread_loads(cp, F, cp, 1, nv) - F).max() < 1e-10 * np.abs(F).max()
    cp4, _ = subdivided(cp, 4)
    F4 = _spread_loads(cp, F, cp4, 4, cp4.n_vertices)
    np.testing.assert_allclose(F4.sum(axis=0), F.sum(axis=0), rtol=1e-12, atol=1e-9)
    # a uniform plan load on 4 x 4 cells is the plan load of the subdivided pattern
    m4 = bh.BarHingeModel.from_pattern(cp4, "N5B8", MAT)
    np.testing.assert_allclose(F4, projected_load(m4, Q)[: cp4.n_vertices], atol=1e-9)
    equal = np.zeros_like(F)
    equal[:, 2] = -100.0
    spread = _spread_loads(cp, equal, cp, 1, nv)
    assert np.abs(spread - equal).max() > 1.0  # smoothed, not reproduced


def test_refined_roof_converges_to_the_shell(roof_reference, shell_reference):
    """Each halving of the cells changes the stiffness less than the one before, at an
    observed order of at least 1 in m, towards a limit within 1 % of the facet shell's
    (measured 0.5 %; the shell's own Richardson correction is below 2 %)."""
    limit, values = roof_reference
    change = np.abs(np.diff(values)) / np.abs(values[:-1])
    assert np.all(np.diff(change) < 0), change
    _, rate, _ = richardson(values[2:])
    assert rate >= 1.0, rate
    shell, shell_unc = shell_reference
    assert abs(shell_unc) < 0.02
    assert abs(limit / shell - 1.0) < 0.01, (limit, shell)


@pytest.mark.parametrize("target", ["10%", "5%"])
def test_choice_meets_its_target_against_the_shell(target, levels, shell_reference):
    ch = choose_model(_roof(), target, cache=levels)
    shell, _ = shell_reference
    assert ch.chosen.m >= 2
    assert abs(ch.chosen.values["stiffness"] / shell - 1.0) <= parse_accuracy(target)
    assert ch.summary()["refined_model"].startswith("N5B8")


@pytest.mark.parametrize("target", ["20%", "10%", "5%"])
def test_choice_meets_its_target_against_a_finer_reference(target, roof_reference, levels):
    scene = _roof()
    ch = choose_model(scene, target, cache=levels)
    acc = parse_accuracy(target)
    assert ch.chosen.error <= acc
    assert ch.chosen.name != "rigid"
    ref, _ = roof_reference
    assert abs(ch.chosen.values["stiffness"] / ref - 1.0) <= acc
    # lighter candidates were estimated above the target
    lighter = ch.candidates[: ch.candidates.index(ch.chosen)]
    assert all(c.error > acc for c in lighter)
    # every refined candidate's estimate is conservative against the finer reference
    for c in ch.candidates:
        if c.m >= 2:
            assert abs(c.values["stiffness"] / ref - 1.0) <= c.error, c.name


@pytest.mark.parametrize("target", ["2%", "15%"])
def test_actuated_scene_rigid_form_only_when_it_meets_the_target(target):
    scene = default_scene()
    ch = choose_model(scene, target, outputs=("form",))
    path = bh.solve(scene)  # the reference: the scene's own model, all its steps
    rigid = rigid_form(scene)
    a, b = rigid.fold_angles_deg[-1], path.fold_angles_deg[-1]
    true_err = np.abs(a - b).max() / np.abs(b).max()
    rigid_est = ch.candidates[0].errors["form"]
    assert rigid_est == pytest.approx(true_err, rel=0.1)
    if ch.chosen.name == "rigid":
        assert true_err <= parse_accuracy(target)
    else:
        assert true_err > parse_accuracy(target) * 0.9 and ch.chosen.name == scene.model.scheme


def test_bad_outputs_and_unreachable_accuracy_are_named_errors():
    with pytest.raises(ConfigError, match="output"):
        choose_model(_roof(), "2%", outputs=("stress",))
    with pytest.raises(bh.errors.ConvergenceError, match="no model up to m = 2"):
        choose_model(_roof(), "0.1%", max_m=2)
    with pytest.raises(ConfigError, match="max_dofs"):
        choose_model(_roof(), "2%", max_dofs=100)


def test_cli_fold_accuracy(tmp_path, capsys):
    import json

    from typer.testing import CliRunner

    from barhinge.cli import app

    def fold(target: float) -> dict:
        out = tmp_path / f"run-{target:g}"
        args = ["fold", "--out", str(out), "--accuracy", f"{100 * target:g}%", "--no-viewer"]
        res = CliRunner().invoke(app, args)
        assert res.exit_code == 0, res.output
        return json.loads((out / "summary.json").read_text())["model_choice"]

    # the lightest candidate (rigid first) whose estimated form error meets the target
    choice = fold(0.15)
    rigid = choice["candidates"][0]
    assert rigid["model"] == "rigid"
    meets = [c for c in choice["candidates"] if c["estimated_error"]["form"] <= 0.15]
    assert choice["model"] == meets[0]["model"]
    assert choice["estimated_error"]["form"] <= 0.15
    # a target just above the rigid form's estimated error takes the rigid form
    loose = fold(1.1 * rigid["estimated_error"]["form"])
    assert loose["model"] == "rigid"
    from barhinge.cli import main

    with pytest.raises(SystemExit) as exc:
        main(["fold", "--out", str(tmp_path / "bad"), "--accuracy", "two"])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert "accuracy" in err and "Traceback" not in err


def test_richardson_does_not_extrapolate_below_its_minimum_order():
    """Changes that barely shrink (order 0.06: 1439, 1334, 1234) would extrapolate 17 times
    the last change away, to a negative value; the finest value stands with an unknown
    correction instead. Just above ``MIN_ORDER`` the power law is still recovered."""
    from barhinge.analysis.accuracy import MIN_ORDER

    ref, p, corr = richardson([1439.1, 1334.3, 1233.9])
    assert p < MIN_ORDER and ref == 1233.9 and math.isinf(corr)
    q = MIN_ORDER + 0.05
    ref, p, corr = richardson([3 + 2 * m**-q for m in (4, 8, 16)])
    assert ref == pytest.approx(3.0, rel=1e-12) and p == pytest.approx(q, rel=1e-12)


def test_richardson_gives_no_error_bound_where_the_changes_grow():
    """The miura60 75 roof's levels m = 2, 4, 8 (250.6, 238.9, 226.6 kN/m: changes -11.7,
    -12.3) once passed for converged to 5.4 % with the last change as the bound, 21 % above
    the shell; growing changes bound nothing (infinite correction). Alternating shrinking
    changes bracket the limit: the last change bounds it. Two levels bound nothing."""
    ref, p, corr = richardson([250.6, 238.9, 226.6])
    assert ref == 226.6 and math.isinf(corr) and math.isnan(p)
    ref, _, corr = richardson([10.0, 12.0, 11.0])  # 2, -1: alternating, shrinking
    assert ref == 11.0 and corr == pytest.approx(1.0)
    assert math.isinf(richardson([10.0, 11.0])[2])
    assert richardson([5.0, 5.0, 5.0])[2] == 0.0


def test_cli_fold_accuracy_on_a_loaded_scene(tmp_path, capsys):
    """A loaded scene (the shipped Yoshimura roof under self-weight): every candidate is
    reported as it is estimated, the run uses the refined model, and its summary names it;
    a target no level up to the DOF budget meets exits with code 3."""
    import json
    from pathlib import Path

    from barhinge.cli import main

    scene = Path(__file__).resolve().parents[2] / "data" / "scenes" / "yoshimura_roof.toml"
    out = tmp_path / "roof"
    args = ["fold", str(scene), "--out", str(out), "--accuracy", "10%", "--no-viewer"]
    main([*args, "--pictures", "none"])
    err = capsys.readouterr().err
    assert "estimated with N4B5" in err and "estimated with N5B8 m=2" in err
    choice = json.loads((out / "summary.json").read_text())["model_choice"]
    assert choice["refined_model"].startswith("N5B8") and choice["model"].startswith("N5B8 m=")
    assert all(c["estimated_error"]["stiffness"] > 0.10 for c in choice["candidates"][:3])
    strict = ["--accuracy", "0.01%", "--accuracy-max-dofs", "50000"]
    with pytest.raises(SystemExit) as exc:
        main(["fold", str(scene), "--out", str(tmp_path / "strict"), *strict])
    assert exc.value.code == 3
    err = capsys.readouterr().err
    assert "no model up to m = 32 meets the accuracy 0.01 %" in err  # m = 64: 86,979 DOFs
    assert "estimated with N5B8 m=64" not in err


def test_the_asymptotic_range_is_checked_before_an_extrapolation_is_trusted():
    """The waterbomb 0.15 roof's levels m = 2, 4, 8 (338.6, 382.8, 379.8 kN/m) shrink with
    alternating signs and once bracketed the limit within 0.8 %; m = 16 and 32 fall to 365.0
    and 354.1 (the facet shell: 346.3), so the choice at m = 4 was 10.5 % off. Four levels and
    the observed orders of the last two triples within a factor 2 (Roache 1994) are asked
    before the extrapolation counts; a power law passes."""
    from barhinge.analysis.accuracy import in_asymptotic_range

    early = [338.55, 382.75, 379.82]
    assert math.isfinite(richardson(early)[2]) and not in_asymptotic_range(early)
    assert not in_asymptotic_range([382.75, 379.82, 364.98, 354.1])
    assert in_asymptotic_range([3 + 2 * m**-1.5 for m in (2, 4, 8, 16)])
    # a rate that changes from 1 to 3: not yet asymptotic
    assert not in_asymptotic_range([10.0, 9.0, 8.5, 8.4375])


def test_levels_are_refined_while_they_fit_in_the_dof_budget(monkeypatch):
    """The chooser refines past m = 32 where the DOF budget allows it. On a sequence of
    known first order, ``k(m) = 100 (1 + 1/m)``, Richardson's limit is exact and its
    correction from m is ``100/m``, so a level's estimated error is ``2/m``: 2 % is first met
    at m = 128 (1.6 %), 1 % at m = 256; with the budget of m = 64 (or ``max_m = 32``) the
    target is refused and the best estimate named."""
    import barhinge.analysis.accuracy as acc

    scene = _roof()

    def fake_scene(static, m, scheme="N5B8"):
        return (m, scheme)

    def fake_response(sc):
        m, scheme = sc
        return {"stiffness": 100.0 * (1.0 + 1.0 / m), "displacement": 1.0 + 1.0 / m}, m

    monkeypatch.setattr(acc, "subdivided_scene", fake_scene)
    monkeypatch.setattr(acc, "_response", fake_response)
    ch = choose_model(scene, "2%", max_dofs=10**9)
    assert ch.chosen.m == 128
    assert ch.chosen.error == pytest.approx(2 / 128, rel=1e-9)
    assert [c.m for c in ch.candidates if c.m > 1][-1] == 128  # stopped where it was met
    assert choose_model(scene, "1%", max_dofs=10**9).chosen.m == 256
    budget_64 = acc._level_dofs(scene.model.pattern, 64)
    with pytest.raises(bh.errors.ConvergenceError, match=r"up to m = 64 .* 3.1 %"):
        choose_model(scene, "2%", max_dofs=budget_64)
    with pytest.raises(bh.errors.ConvergenceError, match=r"up to m = 32 .* 6.2 %"):
        choose_model(scene, "2%", max_m=32, max_dofs=10**9)
    # the CLI's --accuracy-max-dofs states the default it leaves to MAX_DOFS
    import inspect

    from barhinge import cli

    assert f"(default {acc.MAX_DOFS:,};" in inspect.getsource(cli.fold_cmd)


def test_a_refinement_out_of_its_asymptotic_range_is_refused_with_its_changes(monkeypatch):
    """Where no refined level's error can be estimated (changes that do not shrink like a
    power law), the refusal says so and names the changes, not the rigid form's 100 %."""
    import barhinge.analysis.accuracy as acc

    def fake_response(sc):
        m, _ = sc
        return {
            "stiffness": 100.0 * (1.0 + 0.1 * (-1) ** int(math.log2(m))),
            "displacement": 1.0,
        }, m

    monkeypatch.setattr(acc, "subdivided_scene", lambda static, m, scheme="N5B8": (m, scheme))
    monkeypatch.setattr(acc, "_response", fake_response)
    with pytest.raises(bh.errors.ConvergenceError) as exc:
        choose_model(_roof(), "10%", max_m=16, max_dofs=10**9)
    msg = str(exc.value)
    assert "no model up to m = 16 meets the accuracy 10 %: the refinement is not in its " in msg
    assert "stiffness changes from m = 2 to 16: +22.2 %, -18.2 %, +22.2 %" in msg  # 90, 110, ...
    assert "(rigid)" not in msg


def test_richardson_caps_the_order_it_extrapolates_with():
    """An observed order above ``max_order`` extrapolates with ``max_order``: on
    ``3 + 2 m^-2`` the changes from m = 4, 8, 16 are -0.09375 and -0.0234375 (order 2); capped
    at 1 the correction is the last change itself, and the observed order is still returned."""
    vals = [3 + 2 * m**-2.0 for m in (4, 8, 16)]
    ref, p, corr = richardson(vals, max_order=1.0)
    assert p == pytest.approx(2.0, rel=1e-12)
    assert corr == pytest.approx(abs(vals[-1] - vals[-2]), rel=1e-12)
    assert ref == pytest.approx(vals[-1] + (vals[-1] - vals[-2]), rel=1e-12)
    assert richardson(vals, max_order=3.0) == richardson(vals)  # below the cap: unchanged


def test_a_late_slow_error_of_opposite_sign_does_not_pass_for_converged(monkeypatch):
    """``k(m) = 100 + 20/m - 200/m^2`` (limit 100): the fast m^-2 part dominates m = 2 ... 16
    (changes +32.5, +6.9, +1.1: observed orders 2.24 and 2.65, within Roache's factor 2), the
    slow m^-1 part of the other sign turns the sequence back from m = 32 on, as the refined
    miura_arc 120 roof does. Extrapolated with the observed order, m = 16 would be estimated
    at 0.41 % and chosen for 0.45 % while its true error is 0.47 %; with the order capped at
    ``ESTIMATE_MAX_ORDER`` no candidate's estimate is below its true error, and the target
    is refused instead."""
    import barhinge.analysis.accuracy as acc

    def k(m: int) -> float:
        return 100.0 + 20.0 / m - 200.0 / m**2

    monkeypatch.setattr(acc, "subdivided_scene", lambda static, m, scheme="N5B8": (m, scheme))
    monkeypatch.setattr(
        acc, "_response", lambda sc: ({"stiffness": k(sc[0]), "displacement": 1.0}, sc[0])
    )
    # the uncapped extrapolation of m = 2 ... 16 underestimates the error of m = 16
    vals = [k(m) for m in (2, 4, 8, 16)]
    ref, _, corr = richardson(vals)
    assert acc.in_asymptotic_range(vals)
    assert abs(vals[-1] / ref - 1) + corr / ref < abs(vals[-1] / 100.0 - 1)
    # the chooser's estimates bound every candidate's true error
    ch = choose_model(_roof(), "5%", max_m=64, max_dofs=10**9)
    assert ch.chosen.m == 8  # estimated 3.2 %, true 0.6 %
    for c in ch.candidates:
        if c.m >= 2 and math.isfinite(c.error):
            assert abs(c.values["stiffness"] / 100.0 - 1.0) <= c.error, c.name
    with pytest.raises(bh.errors.ConvergenceError, match="no model up to m = 16"):
        choose_model(_roof(), "0.45%", max_m=16, max_dofs=10**9)
    # past m = 16 the sequence turns back: not in its asymptotic range, nothing passes 2 %
    with pytest.raises(bh.errors.ConvergenceError, match="not in its asymptotic range"):
        choose_model(_roof(), "2%", max_m=64, max_dofs=10**9)


def test_a_refusal_names_what_stopped_the_refinement(monkeypatch):
    """A refused target says what a finer level would cost: the next level's DOFs against
    the budget (and the CLI option that raises it), or that ``max_m`` was the finest."""
    import barhinge.analysis.accuracy as acc

    def fake_response(sc):
        m, _ = sc
        return {"stiffness": 100.0 * (1.0 + 1.0 / m), "displacement": 1.0 + 1.0 / m}, m

    monkeypatch.setattr(acc, "subdivided_scene", lambda static, m, scheme="N5B8": (m, scheme))
    monkeypatch.setattr(acc, "_response", fake_response)
    scene = _roof()
    budget = acc._level_dofs(scene.model.pattern, 16)
    with pytest.raises(bh.errors.ConvergenceError) as exc:
        choose_model(scene, "2%", max_dofs=budget)
    nxt = acc._level_dofs(scene.model.pattern, 32)
    assert str(exc.value).endswith(
        f"the next level, m = 32, would have {nxt:,} DOFs, more than max_dofs = {budget:,} "
        "(CLI: --accuracy-max-dofs)"
    )
    with pytest.raises(bh.errors.ConvergenceError, match=r"m = 16 is the finest level tried"):
        choose_model(scene, "2%", max_m=16, max_dofs=10**9)
