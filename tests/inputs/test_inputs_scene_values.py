"""Every value of a TOML scene is checked where it enters: one line naming the key and the
bad value (issue 16, items 2 and 4)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import barhinge as bh
from barhinge.errors import BarhingeError, ConfigError, PatternError
from barhinge.scene import load_scene, scene_from_dict

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from _scenes import DELETE, base, mutated, to_toml  # noqa: E402

NAN, INF = float("nan"), float("inf")

# (path into the scene mapping, bad value, words the one-line message must contain)
BAD = [
    # solve
    (("solve", "steps"), "ten", ["solve.steps", "'ten'", "integer"]),
    (("solve", "steps"), True, ["solve.steps = True", "integer"]),
    (("solve", "steps"), 2.7, ["solve.steps = 2.7", "integer"]),
    (("solve", "steps"), 0, ["solve.steps = 0", ">= 1"]),
    (("solve", "steps"), -3, ["solve.steps = -3"]),
    (("solve", "steps"), 10**12, ["solve.steps", "1000000"]),
    (("solve", "control"), "fast", ["solve.control", "'fast'", "fold_angle"]),
    (("solve", "control"), 3, ["solve.control = 3"]),
    (("solve",), "quick", ["solve must be a table"]),
    (("solve", "options"), "fast", ["options", "'fast'"]),
    (("solve", "options", "tol_force"), NAN, ["solve.options.tol_force = nan", "finite"]),
    (("solve", "options", "tol_force"), -1.0, ["solve.options.tol_force = -1.0", "> 0"]),
    (("solve", "options", "tol_force"), "small", ["solve.options.tol_force", "number"]),
    (("solve", "options", "tol_disp"), INF, ["solve.options.tol_disp = inf"]),
    (("solve", "options", "max_iter"), True, ["solve.options.max_iter = True", "integer"]),
    (("solve", "options", "max_iter"), 2.5, ["solve.options.max_iter = 2.5"]),
    (("solve", "options", "max_iter"), 0, ["solve.options.max_iter = 0"]),
    (("solve", "options", "max_cutbacks"), 10**9, ["solve.options.max_cutbacks"]),
    (("solve", "options", "max_cutbacks"), -1, ["solve.options.max_cutbacks = -1"]),
    (("solve", "options", "reuse_factorization"), 1, ["reuse_factorization = 1", "true or"]),
    (("solve", "options", "stability_check"), "yes", ["stability_check = 'yes'"]),
    (("solve", "options", "linear_solver"), "mumps", ["linear_solver = 'mumps'", "pardiso"]),
    (("solve", "options", "augmentation"), "big", ["augmentation = 'big'"]),
    (("solve", "options", "augmentation"), -1.0, ["augmentation = -1.0"]),
    (("solve", "options", "predictor"), 5, ["predictor = 5", "quadratic"]),
    (("solve", "options", "flat_start"), "bent", ["flat_start = 'bent'"]),
    (("solve", "options", "force_floor"), NAN, ["force_floor = nan"]),
    (("solve", "options", "max_arc_steps"), 1.5, ["max_arc_steps = 1.5"]),
    (("solve", "options", "arc_length_increment"), 0.0, ["arc_length_increment = 0.0"]),
    (("solve", "options", "bogus"), 1, ["bogus", "not a solver option"]),
    # model and material
    (("model", "material", "E"), INF, ["model.material.E = inf", "finite"]),
    (("model", "material", "E"), NAN, ["model.material.E = nan"]),
    (("model", "material", "E"), -1.0, ["model.material.E = -1.0", "> 0"]),
    (("model", "material", "E"), 0, ["model.material.E = 0"]),
    (("model", "material", "E"), "steel", ["model.material.E = 'steel'", "number"]),
    (("model", "material", "E"), True, ["model.material.E = True"]),
    (("model", "material", "nu"), 0.5, ["model.material.nu = 0.5", "[0, 0.5)"]),
    (("model", "material", "nu"), -0.1, ["model.material.nu = -0.1"]),
    (("model", "material", "t"), 0.0, ["model.material.t = 0.0"]),
    (("model", "material", "t"), [0.01], ["model.material.t"]),
    (("model", "material", "rho"), 1.0, ["rho", "model.material"]),
    (("model", "material"), 5, ["model.material must be a table"]),
    (("model", "fold_stiffness"), NAN, ["model.fold_stiffness = nan", "finite"]),
    (("model", "fold_stiffness"), INF, ["model.fold_stiffness = inf"]),
    (("model", "fold_stiffness"), -1.0, ["model.fold_stiffness = -1.0", ">= 0"]),
    (("model", "fold_stiffness"), "soft", ["model.fold_stiffness = 'soft'"]),
    (("model", "stiffness_ratio"), 0.0, ["model.stiffness_ratio = 0.0"]),
    (("model", "crease_length_scale"), -2.0, ["model.crease_length_scale"]),
    (("model", "bend_coefficient"), NAN, ["model.bend_coefficient = nan"]),
    (("model", "scheme"), "N9B9", ["model.scheme = 'N9B9'", "N5B8"]),
    (("model", "scheme"), 4, ["model.scheme = 4"]),
    (("model", "fold_law"), "cubic", ["model.fold_law = 'cubic'"]),
    (("model", "strain"), "log", ["model.strain = 'log'"]),
    (("model", "bar_calibration"), 1, ["model.bar_calibration = 1"]),
    (("model", "bend_calibration"), "x", ["model.bend_calibration = 'x'"]),
    (("model", "fold_limits_deg"), [0.0, 10.0], ["fold_limits_deg", "-180"]),
    (("model", "fold_limits_deg"), ["a", 1.0], ["model.fold_limits_deg", "'a'"]),
    (("model", "fold_limits_deg"), [-90.0], ["model.fold_limits_deg", "shape"]),
    (("model", "bar_EA"), [1.0, 2.0], ["model.bar_EA", "shape"]),
    (("model", "fold_k"), NAN, ["model.fold_k", "nan"]),
    (("model", "bend_k"), -1.0, ["model.bend_k", "-1.0"]),
    (("model",), "stiff", ["model must be a table"]),
    # pattern
    (("pattern", "params", "nx"), "two", ["pattern.params.nx = 'two'", "integer"]),
    (("pattern", "params", "nx"), 2.5, ["pattern.params.nx = 2.5"]),
    (("pattern", "params", "nx"), True, ["pattern.params.nx = True"]),
    (("pattern", "params", "nx"), 10**9, ["pattern.params.nx", "10000"]),
    (("pattern", "params", "nx"), 0, ["nx", "0"]),
    (("pattern", "params", "a"), INF, ["pattern.params.a = inf"]),
    (("pattern", "params", "a"), "one", ["pattern.params.a = 'one'"]),
    (("pattern", "params", "a"), -1.0, ["a = -1", "range"]),
    (("pattern", "params", "alpha"), NAN, ["pattern.params.alpha = nan"]),
    (("pattern", "params", "a"), 1e300, ["overflow"]),
    (("pattern", "params", "nxx"), 3, ["nxx", "pattern.params"]),
    (("pattern", "family"), 3, ["pattern.family = 3"]),
    (("pattern", "family"), "nosuch", ["pattern.family = 'nosuch'", "miura"]),
    (("pattern", "file"), 5, ["exactly one of family or file"]),
    (("pattern",), DELETE, ["needs a pattern table"]),
    (("pattern",), [1, 2], ["pattern must be a table"]),
    # supports
    (("supports", 0, "where"), 5, ["supports.0.where = 5"]),
    (("supports", 0, "where"), "middle", ["supports.0.where", "'middle'"]),
    (("supports", 0, "where"), ["left", 3], ["supports.0.where"]),
    (("supports", 0, "dofs"), "w", ["supports.0.dofs = 'w'", "xyz"]),
    (("supports", 0, "dofs"), True, ["supports.0.dofs = True"]),
    (("supports", 0, "dofs"), "", ["supports.0.dofs = ''"]),
    (("supports", 1, "vertices"), ["a"], ["supports.1.vertices", "'a'", "integers"]),
    (("supports", 1, "vertices"), [1.5], ["supports.1.vertices", "1.5"]),
    (("supports", 1, "vertices"), [True], ["supports.1.vertices", "True"]),
    (("supports", 1, "vertices"), [999], ["supports.1.vertices", "999", "0..24"]),
    (("supports", 1, "vertices"), [-1], ["supports.1.vertices", "-1"]),
    (("supports", 1, "nodes"), [10**6], ["supports.1.nodes", "1000000"]),
    (("supports", 1, "edges"), [2**70], ["supports.1.edges"]),
    (("supports", 1, "bogus"), 1, ["bogus", "supports.1"]),
    (("supports",), "all", ["supports must be a table"]),
    (("supports",), [1, 2], ["supports must be a table"]),
    # loads
    (("loads", 0, "self_weight", "g"), [0.0, -9.8], ["loads.0.self_weight.g", "shape"]),
    (("loads", 0, "self_weight", "g"), [0.0, 0.0, NAN], ["loads.0.self_weight.g", "nan"]),
    (("loads", 0, "self_weight", "g"), "down", ["loads.0.self_weight.g"]),
    (("loads", 0, "self_weight", "area_density"), -1.0, ["area_density = -1.0"]),
    (("loads", 0, "self_weight", "area_density"), "heavy", ["area_density = 'heavy'"]),
    (("loads", 0, "self_weight", "area_density"), 1e308, ["loads.0", "overflow"]),
    (("loads", 0, "self_weight"), {"g": [0.0, 0.0, -1.0]}, ["needs area_density"]),
    (("loads", 1, "force"), [0.0, "a", 1.0], ["loads.1.force", "'a'"]),
    (("loads", 1, "force"), [INF, 0.0, 0.0], ["loads.1.force", "inf"]),
    (("loads", 1, "force"), [0.0, 0.0, 0.0, 1.0], ["loads.1.force", "shape"]),
    (("loads", 1, "force"), DELETE, ["loads.1", "force"]),
    (("loads", 1, "force"), [True, False, True], ["loads.1.force", "True"]),
    # prescribed
    (("prescribed", 0, "displacement"), [NAN, 0.0, 0.0], ["prescribed.0.displacement", "nan"]),
    (("prescribed", 0, "displacement"), [1.0], ["prescribed.0.displacement", "shape"]),
    (("prescribed", 0, "displacement"), DELETE, ["prescribed.0 needs displacement"]),
    (("prescribed", 0, "dofs"), "q", ["prescribed.0.dofs = 'q'"]),
    # actuators
    (("actuators", "edges"), ["a"], ["actuators.edges", "'a'", "integers"]),
    (("actuators", "edges"), [21.7], ["actuators.edges", "21.7"]),
    (("actuators", "edges"), [True], ["actuators.edges", "True"]),
    (("actuators", "edges"), [-1], ["actuators.edges", "-1"]),
    (("actuators", "edges"), [9999], ["actuator edge 9999", "not an edge id"]),
    (("actuators", "edges"), [0], ["actuator edge 0", "no fold hinge"]),
    (("actuators", "edges"), "all", ["actuators.edges = 'all'"]),
    (("actuators", "edges"), [21, 21], ["actuators.edges repeat"]),
    (("actuators", "edges"), DELETE, ["actuators needs edges"]),
    (("actuators", "targets_deg"), [200.0], ["actuators.targets_deg = 200.0", "180"]),
    (("actuators", "targets_deg"), [-180.0], ["actuators.targets_deg = -180.0"]),
    (("actuators", "targets_deg"), [NAN], ["actuators.targets_deg", "nan"]),
    (("actuators", "targets_deg"), ["x"], ["actuators.targets_deg", "'x'"]),
    (("actuators", "targets_deg"), [1.0, 2.0], ["actuators.targets_deg has 2", "edges has 1"]),
    (("actuators", "targets_deg"), DELETE, ["exactly one of targets_deg"]),
    (("actuators", "table_deg"), [[10.0], [20.0], [30.0]], ["exactly one of targets_deg"]),
    (
        ("actuators",),
        {"edges": [21], "table_deg": [[10.0], [190.0], [30.0]]},
        ["actuators.table_deg = 190.0", "step 2", "180"],
    ),
    (
        ("actuators",),
        {"edges": [21], "table_deg": [[10.0], [NAN], [30.0]]},
        ["actuators.table_deg", "nan"],
    ),
    (("actuators",), {"edges": [21], "table_deg": [[10.0, 1.0]]}, ["actuators.table_deg", "shape"]),
    (("actuators",), {"edges": [21], "table_deg": [[10.0], [20.0]]}, ["table_deg has 2 rows"]),
    (("actuators",), {"edges": [21], "table_deg": [["a"], [20.0], [3.0]]}, ["table_deg", "'a'"]),
    (("actuators", "bogus"), 1, ["bogus", "actuators"]),
    # top level
    (("name",), 5, ["name = 5", "string"]),
    (("bogus",), 1, ["bogus", "the scene"]),
]


@pytest.mark.parametrize(("path", "value", "words"), BAD, ids=[str(b[:2]) for b in BAD])
def test_bad_scene_value_is_named_in_one_line(path, value, words, tmp_path):
    d = mutated(path, value)
    f = tmp_path / "scene.toml"
    f.write_text(to_toml(d))
    with pytest.raises(BarhingeError) as info:
        load_scene(f)
    msg = str(info.value)
    assert "\n" not in msg
    for w in words:
        assert w in msg, (w, msg)


def test_base_scene_loads_and_the_writer_round_trips(tmp_path):
    f = tmp_path / "scene.toml"
    f.write_text(to_toml(base()))
    scene = load_scene(f)
    assert scene.steps == 3 and scene.control == "fold_angle" and scene.actuators.n == 1
    assert scene.supports.sum() > 0 and np.isfinite(scene.prescribed).sum() == 1


def test_unreadable_scene_files_are_config_errors(tmp_path):
    with pytest.raises(ConfigError, match="cannot be read"):
        load_scene(tmp_path)  # a folder
    bad = tmp_path / "bad.toml"
    bad.write_bytes(b"\xff\xfe name = 1")
    with pytest.raises(ConfigError, match="invalid TOML"):
        load_scene(bad)
    d = base()
    d["pattern"] = {"file": "nosuch.fold"}
    with pytest.raises(ConfigError, match="pattern.file"):
        scene_from_dict(d, base_dir=tmp_path)


# ------------------------------------------------------------------ the Python API
def test_material_checks_type_finiteness_and_range():
    for kw, words in [
        ({"E": float("inf")}, "material.E = inf"),
        ({"E": True}, "material.E = True"),
        ({"nu": 0.5}, "material.nu = 0.5"),
        ({"nu": -0.2}, "material.nu = -0.2"),
        ({"t": -1e-3}, "material.t = -0.001"),
        ({"t": "thin"}, "material.t = 'thin'"),
    ]:
        with pytest.raises(ConfigError, match=words.replace(".", r"\.")):
            bh.Material(**kw)
    assert bh.Material(E=np.float64(2.0), nu=0, t=1).E == 2.0


def test_actuators_reject_float_and_bool_edges_and_bad_targets():
    with pytest.raises(ConfigError, match="21.7"):
        bh.Actuators(edges=[21.7], targets_deg=[10.0])
    with pytest.raises(ConfigError, match="True"):
        bh.Actuators(edges=[True], targets_deg=[10.0])
    with pytest.raises(ConfigError, match="inf"):
        bh.Actuators(edges=[1], targets_deg=[float("inf")])
    with pytest.raises(ConfigError, match="180"):
        bh.Actuators(edges=[1], table_deg=[[10.0], [-185.0]])
    a = bh.Actuators(edges=np.array([3, 4]), targets_deg=30.0)
    assert a.edges.dtype == np.int64 and a.targets_deg.tolist() == [30.0, 30.0]
    with pytest.raises(ConfigError, match="steps"):
        a.schedule(2.0)


def test_solver_options_check_every_field():
    from barhinge.solver_options import SolverOptions

    for kw in [
        {"max_iter": True},
        {"grow_iters": 1.0},
        {"krylov_max": 0},
        {"line_search": -1},
        {"tol_angle": float("nan")},
        {"divergence_ratio": 0},
        {"reuse_factorization": 0},
        {"linear_solver": None},
        {"force_floor": -1.0},
    ]:
        with pytest.raises(ConfigError, match="options." + next(iter(kw))):
            SolverOptions(**kw)
    assert SolverOptions(tol_force=np.float64(1e-6), max_iter=np.int64(5)).max_iter == 5


def test_scene_checks_steps_arrays_and_model():
    scene = scene_from_dict(base())
    m, n = scene.model, scene.model.n_nodes
    kw = {"actuators": scene.actuators}
    for steps in (True, 2.7, "ten", 0):
        with pytest.raises(ConfigError, match="steps"):
            bh.Scene(m, steps=steps, **kw)
    L = np.zeros((n, 3))
    L[0, 0] = np.nan
    with pytest.raises(ConfigError, match="loads"):
        bh.Scene(m, loads=L, **kw)
    P = np.full((n, 3), np.nan)
    P[0, 0] = np.inf
    with pytest.raises(ConfigError, match="prescribed"):
        bh.Scene(m, prescribed=P, **kw)
    with pytest.raises(ConfigError, match="boolean"):
        bh.Scene(m, supports=np.zeros((n, 3)), **kw)
    with pytest.raises(ConfigError, match="loads"):
        bh.Scene(m, loads=[["a"] * 3] * n, **kw)
    with pytest.raises(ConfigError, match="model"):
        bh.Scene(object(), **kw)


def test_from_pattern_checks_stiffness_arguments():
    cp = bh.families.miura(1, 1)
    for kw, key in [
        ({"fold_stiffness": float("nan")}, "fold_stiffness"),
        ({"fold_stiffness": -1.0}, "fold_stiffness"),
        ({"crease_length_scale": 0.0}, "crease_length_scale"),
        ({"stiffness_ratio": float("inf")}, "stiffness_ratio"),
        ({"bar_EA": float("nan")}, "bar_EA"),
        ({"fold_k": [1.0, 2.0]}, "fold_k"),
        ({"material": "steel"}, "material"),
        ({"fold_limits_deg": (-90.0, "a")}, "fold_limits_deg"),
    ]:
        with pytest.raises(ConfigError, match=key):
            bh.BarHingeModel.from_pattern(cp, **kw)


def test_pattern_of_overflowing_size_is_named():
    d = mutated(("pattern", "params", "a"), 1e300)
    with pytest.raises((ConfigError, PatternError), match="overflow"):
        scene_from_dict(d)


# ------------------------------------------------------------------ nothing non-finite reaches
# a factorisation (E = inf segfaulted in PARDISO)
def test_infinite_E_is_one_line_and_exit_2_without_a_crash(tmp_path):
    d = mutated(("model", "material", "E"), float("inf"))
    f = tmp_path / "scene.toml"
    f.write_text(to_toml(d))
    code = (
        "import sys, barhinge as bh\n"
        "try:\n    bh.solve(bh.load_scene(sys.argv[1]))\n"
        "except bh.errors.ConfigError as exc:\n    print(exc); sys.exit(2)\n"
    )
    r = subprocess.run(
        [sys.executable, "-c", code, str(f)], capture_output=True, text=True, timeout=120
    )
    assert r.returncode == 2, r.stderr
    assert r.stdout.strip().count("\n") == 0 and "model.material.E = inf" in r.stdout


def test_non_finite_stiffness_injected_after_building_never_reaches_the_solver():
    scene = scene_from_dict(base())
    k = np.array(scene.model.hinge_k)
    k[0] = np.nan
    bad = scene.with_(model=scene.model.with_(hinge_k=k))
    with pytest.raises(ConfigError, match="hinge_k has non-finite"):
        bh.solve(bad)


def test_non_finite_tangent_is_reported_as_singular_not_factorised():
    import scipy.sparse as sp

    from barhinge.linalg.backends import SingularMatrixError
    from barhinge.solver.diagnose import check_finite_tangent

    K = sp.csr_matrix(np.array([[1.0, np.inf], [np.inf, 1.0]]))
    with pytest.raises(SingularMatrixError, match="non-finite"):
        check_finite_tangent(K)
    check_finite_tangent(sp.identity(3, format="csr"))


def test_control_curves_check_their_numbers():
    from barhinge.actuators.curves import (
        CircularArc,
        Parabola,
        SplineCurve,
        chain_on_curve,
        curve_schedule,
        synchronised,
    )

    for make, key in [
        (lambda: CircularArc(float("nan")), "kappa"),
        (lambda: CircularArc("round"), "kappa"),
        (lambda: Parabola(float("inf")), "c"),
        (lambda: SplineCurve([0.0, float("nan")], [0.0, 1.0]), "spline x"),
        (lambda: SplineCurve([0.0, 1.0], ["a", 1.0]), "spline z"),
        (lambda: chain_on_curve(Parabola(1.0), [0.0, 1.0, float("inf")]), "section"),
        (lambda: synchronised([1, 2], 200.0), "angle_deg"),
        (lambda: synchronised([1.5], 20.0), "actuators.edges"),
        (lambda: curve_schedule(bh.families.pleats(4), [1], Parabola(1.0), 2.5), "steps"),
    ]:
        with pytest.raises(ConfigError, match=key):
            make()
