"""Result files open with meshio and PyVista and hold the arrays they claim."""

from __future__ import annotations

import json

import meshio
import numpy as np
import pytest

from barhinge import CreasePattern, FoldPath
from barhinge.errors import ConfigError
from barhinge.fields import state_data
from barhinge.output.run import write_results
from barhinge.output.table import COLUMNS, actuator_columns


def simple_fold_path(n_states: int = 5) -> tuple[CreasePattern, FoldPath]:
    """A 2 x 2 sheet of unit squares folded rigidly about the valley crease x = 1 from 0 to
    90 deg (the right half rotates about the crease: no panel strains)."""
    xs, ys = np.meshgrid([0.0, 1.0, 2.0], [0.0, 1.0, 2.0])
    V = np.column_stack([xs.ravel(), ys.ravel()])
    faces = [(0, 1, 4, 3), (1, 2, 5, 4), (3, 4, 7, 6), (4, 5, 8, 7)]
    E = sorted({tuple(sorted((f[i], f[(i + 1) % 4]))) for f in faces for i in range(4)})
    asg = [
        "V" if {a, b} in ({1, 4}, {4, 7}) else "F" if {a, b} in ({3, 4}, {4, 5}) else "B"
        for a, b in E
    ]
    cp = CreasePattern(V, np.array(E), asg, faces=faces)
    X, FA = [], []
    for rho in np.linspace(0, np.pi / 2, n_states):
        P = cp.vertices3d.copy()
        right = P[:, 0] > 1.5
        P[right, 0] = 1 + np.cos(rho)
        P[right, 2] = np.sin(rho)
        X.append(P)
        FA.append(cp.replaced(vertices=P, validate=False).state_fold_angles())
    act = [cp.edge_between(1, 4)]
    path = FoldPath(
        X=np.array(X),
        fold_angles_deg=np.array(FA),
        actuator_edges=act,
        kind="rigid",
        actuator_targets_deg=np.degrees(np.linspace(0, np.pi / 2, n_states))[:, None],
    )
    return cp, path


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    cp, path = simple_fold_path()
    out = tmp_path_factory.mktemp("res")
    return cp, path, write_results(path, None, out, pattern=cp)


def test_vtu_opens_with_meshio_and_pyvista_and_holds_the_arrays(written):
    pv = pytest.importorskip("pyvista")
    cp, path, files = written
    m = meshio.read(files["vtu"])
    np.testing.assert_allclose(m.points, path.X[-1], atol=1e-12, rtol=0)
    assert [c.type for c in m.cells] == ["triangle", "line"]
    assert {"displacement", "angle_defect", "defect_density"} <= set(m.point_data)
    assert {"fold_angle_deg", "bar_strain", "energy_density", "kind"} <= set(m.cell_data)
    fa = m.cell_data["fold_angle_deg"][1]
    e = cp.edge_between(1, 4)
    assert fa[e] == pytest.approx(90.0, abs=1e-9)
    # rigid fold: no strain, no angle defect at the one interior vertex (4)
    assert np.nanmax(np.abs(m.cell_data["bar_strain"][1])) < 1e-12
    assert abs(m.point_data["angle_defect"][4]) < 1e-12
    np.testing.assert_allclose(
        m.point_data["displacement"], path.X[-1] - path.X[0], atol=1e-12, rtol=0
    )
    grid = pv.read(files["vtu"])
    assert grid.n_cells == len(m.cells[0].data) + len(cp.edges)
    assert "fold_angle_deg" in grid.cell_data and "angle_defect" in grid.point_data


def test_xdmf_time_series_holds_every_step_and_h5_lies_beside_it(written, tmp_path, monkeypatch):
    cp, path, files = written
    assert files["xdmf"].with_suffix(".h5").is_file()
    assert files["xdmf_bars"].with_suffix(".h5").is_file()
    monkeypatch.chdir(tmp_path)  # reading must not depend on the working directory
    with meshio.xdmf.TimeSeriesReader(files["xdmf_bars"]) as r:
        pts, cells = r.read_points_cells()
        assert r.num_steps == path.n_states
        np.testing.assert_allclose(pts, path.X[0], atol=1e-12, rtol=0)
        for s in range(path.n_states):
            t, pd, cd = r.read_data(s)
            np.testing.assert_allclose(
                pd["displacement"], path.X[s] - path.X[0], atol=1e-12, rtol=0
            )
            np.testing.assert_allclose(
                cd["fold_angle_deg"][0][cp.edge_between(1, 4)],
                path.fold_angles_deg[s, cp.edge_between(1, 4)],
                atol=1e-9,
            )
    assert not list(tmp_path.glob("*.h5"))


def test_csv_and_json_summaries(written):
    cp, path, files = written
    lines = files["csv"].read_text().splitlines()
    assert len(lines) == path.n_states + 1
    head = lines[0].split(",")
    e = int(path.actuator_edges[0])
    assert head == list(COLUMNS) + actuator_columns([e])  # the columns of every run
    last = dict(zip(head, lines[-1].split(","), strict=True))
    assert float(last[f"actuator_{e}_fold_deg"]) == pytest.approx(90.0)
    assert float(last[f"actuator_{e}_target_deg"]) == pytest.approx(90.0)
    assert last["energy_total"] == ""  # NaN for a rigid path -> an empty cell
    data = json.loads(files["json"].read_text())
    assert data["n_states"] == path.n_states and data["model"] == "rigid"
    assert data["results"]["actuator_fold_deg"] == [pytest.approx(90.0)]
    assert data["energy"]["total"] is None  # NaN for a rigid path -> null
    again = FoldPath.load(files["npz"])
    np.testing.assert_array_equal(again.X, path.X)


def test_state_data_needs_a_mesh_source():
    with pytest.raises(ConfigError, match="model or a pattern"):
        state_data(np.zeros((3, 3)))


def test_model_state_arrays_against_direct_formulas():
    """With a bar-and-hinge model: bar strains are (L - L0)/L0 of the model's bars and fold
    angles on crease bars equal the model's hinge angles."""
    bh = pytest.importorskip("barhinge")
    pytest.importorskip("barhinge.model.model")
    pytest.importorskip("barhinge.families")
    cp = bh.families.miura(2, 2, fold=40.0)
    model = bh.BarHingeModel.from_pattern(cp, material=bh.Material(E=1e3, nu=0.3, t=0.01))
    rng = np.random.default_rng(1)
    X = model.X0 + 1e-3 * rng.normal(size=model.X0.shape)
    d = state_data(X, model=model)
    L = np.linalg.norm(X[model.bars[:, 1]] - X[model.bars[:, 0]], axis=1)
    np.testing.assert_allclose(
        d.line_data["bar_strain"], (L - model.bar_L0) / model.bar_L0, atol=1e-14, rtol=0
    )
    rho = model.hinge_angles(X)
    fold = np.flatnonzero(np.asarray(model.hinge_kind) == "fold")
    key = {tuple(sorted(b)): i for i, b in enumerate(model.bars.tolist())}
    for h in fold:
        i = key[tuple(sorted(model.hinges[h, :2].tolist()))]
        assert d.line_data["fold_angle_deg"][i] == pytest.approx(np.degrees(rho[h]), abs=1e-9)
    assert np.isfinite(d.triangle_data["energy_density"]).all()


def test_write_results_of_a_bar_hinge_path(tmp_path):
    """A bar-and-hinge path (rigid Miura states on the model's nodes): files, FOLD frames and
    the summary; the energy densities integrate to the model's energy split."""
    bh = pytest.importorskip("barhinge")
    pytest.importorskip("barhinge.model.model")
    patterns = pytest.importorskip("barhinge.families")
    cp = patterns.miura(2, 2, fold=30.0)
    model = bh.BarHingeModel.from_pattern(cp, material=bh.Material(E=1e3, nu=0.3, t=0.01))
    rng = np.random.default_rng(3)
    X = np.array([model.X0 + 0.01 * s * rng.normal(size=model.X0.shape) for s in range(3)])
    ev = [model.evaluate(x, tangent=False) for x in X]
    path = FoldPath(
        X=X,
        fold_angles_deg=np.array([model.crease_fold_angles_deg(x) for x in X]),
        actuator_edges=[int(cp.crease_edges[0])],
        energy_bars=[e.energy_bars for e in ev],
        energy_bend=[e.energy_bend for e in ev],
        energy_fold=[e.energy_fold for e in ev],
    )
    files = write_results(path, model, tmp_path, vtu="last")
    m = meshio.read(files["vtu"])
    assert len(m.points) == model.n_nodes and len(m.cells[1].data) == model.n_bars
    d = state_data(X[-1], model=model)
    tri = d.triangles
    area = 0.5 * np.linalg.norm(
        np.cross(X[-1][tri[:, 1]] - X[-1][tri[:, 0]], X[-1][tri[:, 2]] - X[-1][tri[:, 0]]), axis=1
    )
    bend = (d.triangle_data["energy_density"] * area).sum()
    lines = (d.line_data["energy_density"] * model.bar_L0).sum()
    assert bend == pytest.approx(ev[-1].energy_bend, rel=1e-10)
    assert lines == pytest.approx(ev[-1].energy_bars + ev[-1].energy_fold, rel=1e-10)
    summary = json.loads(files["json"].read_text())["results"]
    assert summary["energy_total"] == pytest.approx(ev[-1].energy, rel=1e-12)
    assert summary["max_abs_bar_strain"] > 0
    if "fold" in files:
        from barhinge.pattern.fold import read_fold

        last = read_fold(files["fold"], frame=path.n_states, validate=False)
        np.testing.assert_allclose(last.vertices, X[-1][: cp.n_vertices], atol=1e-9, rtol=0)


def test_vtu_force_fields_match_the_strains_and_fold_angles(tmp_path):
    """bar_force = EA (e + e^2/2)(1 + e) for the default Green-strain bars, e the engineering
    strain of the bar_strain field (computed from lengths); crease moment = k (rho - rho0)
    from the fold_angle_deg field; reactions at supports only, summing to the applied load
    (none here: zero)."""
    import meshio

    import barhinge as bh
    from barhinge.families import miura_line_creases
    from barhinge.fields import write_state_vtu
    from barhinge.scene import Scene

    cp = bh.families.miura(2, 2, fold=20.0)
    model = bh.BarHingeModel.from_pattern(cp, material=bh.Material(E=1e3, nu=0.3, t=0.01))
    edges = miura_line_creases(cp)
    acts = bh.Actuators(edges=edges, targets_deg=np.asarray(cp.fold_angles)[edges] * 1.5)
    scene = Scene(model, actuators=acts, steps=6)
    path = bh.solve(scene)
    f = write_state_vtu(tmp_path / "s.vtu", path.X[-1], model=model, reactions=path.reactions[-1])
    m = meshio.read(f)
    line = [i for i, c in enumerate(m.cells) if c.type == "line"][0]
    eps = m.cell_data["bar_strain"][line]
    assert model.strain == "green"
    want = model.bar_EA * (eps + eps**2 / 2) * (1 + eps)
    # the strains come from coordinates of order 1: each carries a round-off of a few
    # machine epsilons, so the force of a nearly unstrained bar agrees to EA times that
    ulp = 8 * np.finfo(float).eps * np.asarray(model.bar_EA)
    np.testing.assert_allclose(m.cell_data["bar_force"][line], want, rtol=1e-9, atol=ulp.max())
    # crease moments from the fold angles of the same lines and the fold hinges' springs
    fold = np.flatnonzero(model.hinge_kind == "fold")
    axes = list(map(tuple, np.sort(model.hinges[fold, :2], axis=1)))
    k = dict(zip(axes, model.hinge_k[fold], strict=True))
    r0 = dict(zip(axes, model.rest_angle[fold], strict=True))
    bars = np.sort(m.cells[line].data, axis=1)
    mom, ang = m.cell_data["moment"][line], m.cell_data["fold_angle_deg"][line]
    creases = np.flatnonzero(np.isfinite(mom))
    assert len(creases) == len(fold)
    for i in creases:
        key = tuple(bars[i])
        assert mom[i] == pytest.approx(k[key] * (np.radians(ang[i]) - r0[key]), rel=1e-9, abs=1e-14)
    R = m.point_data["reaction"]
    assert np.all(R[~scene.fixed.any(axis=1)] == 0.0)
    assert np.linalg.norm(R.sum(axis=0)) < 1e-8


def test_membrane_N_field_of_a_homogeneous_stretch():
    """A flat sheet stretched by a uniform strain e_xx: every panel triangle carries the
    plane-stress resultant t E / (1 - nu^2) (E_xx, nu E_xx, 0) of the Green strain
    E_xx = e + e^2 / 2 (Timoshenko & Goodier: plane stress), in global axes."""
    import barhinge as bh
    from barhinge.fields import state_mesh

    cp = bh.families.miura(nx=2, ny=2, fold=0.0)
    mat = bh.Material(E=1e6, nu=0.3, t=0.01)
    model = bh.BarHingeModel.from_pattern(cp, "N5B8", mat)
    e = 1e-3
    X = np.asarray(model.X0, float).copy()
    X[:, 0] *= 1.0 + e
    data = state_data(X, model=model)
    N = data.triangle_data["membrane_N"].reshape(-1, 3, 3)
    Exx = e + e * e / 2
    c = mat.t * mat.E / (1 - mat.nu**2)
    np.testing.assert_allclose(N[:, 0, 0], c * Exx, rtol=1e-9)
    np.testing.assert_allclose(N[:, 1, 1], c * mat.nu * Exx, rtol=1e-9)
    np.testing.assert_allclose(N[:, 0, 1], 0.0, atol=1e-9 * c * Exx)
    assert np.isnan(data.line_data["membrane_N"]).all()
    mesh = state_mesh(data=data)
    assert any("membrane_N" in k for k in mesh.cell_data)


def test_state_files_written_side_by_side_are_the_states(tmp_path, monkeypatch):
    """Files written by two threads hold each its own state (read back with meshio, against
    the written arrays); a file that cannot be written raises after the others are done."""
    from barhinge.fields import path_state_data, write_state_vtus

    monkeypatch.setenv("BARHINGE_THREADS", "2")
    cp, path = simple_fold_path(n_states=6)
    states = path_state_data(path, pattern=cp)
    files = write_state_vtus([tmp_path / f"s{i}.vtu" for i in range(6)], states)
    assert [f.name for f in files] == [f"s{i}.vtu" for i in range(6)]
    for f, d in zip(files, states, strict=True):
        m = meshio.read(f)
        np.testing.assert_array_equal(m.points, d.points)
        for name, values in d.point_data.items():
            np.testing.assert_array_equal(m.point_data[name], values)
    bad = [tmp_path / "a.vtu", tmp_path / "missing" / "b.vtu", tmp_path / "c.vtu"]
    with pytest.raises(FileNotFoundError):
        write_state_vtus(bad, states[:3])
    assert (tmp_path / "a.vtu").exists() and (tmp_path / "c.vtu").exists()
    with pytest.raises(ValueError, match="2 paths for 3 states"):
        write_state_vtus(bad[:2], states[:3])
