"""The default bending rule is the plate-model calibration (issue 21, item 3): what it
gives, that it is cheap on big sheets (one plate solve per distinct face shape) and that it
gives a finite stiffness or a one-line error for every panel shape."""

from __future__ import annotations

import numpy as np
import pytest

import barhinge.model.model as model_mod
from barhinge.errors import ConfigError, PatternError
from barhinge.families import miura
from barhinge.model.compare import panel_errors
from barhinge.model.continuum import plate_corner_energy, polygon_mesh
from barhinge.model.material import Material
from barhinge.model.model import BarHingeModel
from barhinge.pattern.crease import CreasePattern
from barhinge.pattern.subdivide import subdivided

MAT = Material(E=1.0, nu=0.3, t=0.01)


def _panel(P) -> CreasePattern:
    P = np.asarray(P, float)
    k = len(P)
    return CreasePattern(P, [[i, (i + 1) % k] for i in range(k)], ["B"] * k, faces=[list(range(k))])


def _bend_k(cp: CreasePattern, scheme: str, **kw) -> np.ndarray:
    m = BarHingeModel.from_pattern(cp, scheme, MAT, **kw)
    return m.hinge_k[m.hinge_kind != "fold"]


@pytest.mark.parametrize("scheme", ["N4B5", "N5B8"])
def test_default_is_plate(scheme: str) -> None:
    cp = miura(2, 2, a=1.0, b=1.0, alpha=60.0, fold=20.0)
    np.testing.assert_array_equal(
        _bend_k(cp, scheme), _bend_k(cp, scheme, bend_calibration="plate")
    )
    m = BarHingeModel.from_pattern(cp, scheme, MAT)
    assert m.meta["bend_calibration"] == "plate" and m.meta["bend_coefficient"] is None


@pytest.mark.parametrize("scheme", ["N4B5", "N5B8"])
def test_default_rectangle_twist_closed_form(scheme: str) -> None:
    """Rectangle W x H under w = kappa x y at the corners, edges free: the default model's
    energy is D (1 - nu) kappa^2 W H (Timoshenko & Woinowsky-Krieger 1959, Sec. 11); the
    F17 rule (C_B = 0.55) stores 0.55 (D_L/t)^(1/3) / (1 - nu) times as much for a square
    (= 3.09 here: the plate rule is 0.245 times the F17 stiffness per hinge)."""
    W, H = 2.0, 1.0
    P = np.array([[0, 0], [W, 0], [W, H], [0, H]], float)
    D = MAT.E * MAT.t**3 / (12 * (1 - MAT.nu**2))
    w = (P[:, 0] - W / 2) * (P[:, 1] - H / 2)
    assert plate_corner_energy(P, MAT, w, 3) == pytest.approx(D * (1 - MAT.nu) * W * H, rel=1e-9)
    assert abs(panel_errors(P, MAT, scheme)["warp"]) < 1e-9  # default rules
    sq = _panel([[0, 0], [1, 0], [1, 1], [0, 1]])
    ratio = _bend_k(sq, scheme) / _bend_k(sq, scheme, bend_calibration="filipov")
    want = (1 - MAT.nu) / (0.55 * np.cbrt(np.sqrt(2) / MAT.t))
    np.testing.assert_allclose(ratio, want, rtol=1e-9)


def test_parallelogram_factor() -> None:
    """60-degree parallelogram (the default Miura's panels): the plate rule scales the
    rectangle (Kirchhoff) formula by 1/1.513 = 0.661, the Morley plate being exact for a
    free parallelogram's quadratic corner warping (tests/model/test_calibration_table.py)."""
    P = [[0, 0], [1, 0], [1.5, np.sqrt(0.75)], [0.5, np.sqrt(0.75)]]
    for scheme in ("N4B5", "N5B8"):
        r = _bend_k(_panel(P), scheme) / _bend_k(_panel(P), scheme, bend_calibration="kirchhoff")
        e = panel_errors(np.array(P), MAT, scheme, "fit", "kirchhoff", plate_refine=4)["warp"]
        np.testing.assert_allclose(r, 1.0 / (1.0 + e), rtol=1e-9)
        assert r[0] == pytest.approx(0.661, abs=5e-4)


def test_one_plate_solve_per_distinct_face_shape(monkeypatch: pytest.MonkeyPatch) -> None:
    """A 12 x 12 Miura sheet (576 faces, folded) has two panel shapes (a panel and its
    mirror image): two Morley solves, whatever the sheet size; subdividing the parallelogram
    panels 2 x 2 gives similar sub-panels with the same factor."""
    calls = []
    orig = model_mod.plate_corner_stiffness

    def counting(*a, **kw):
        calls.append(1)
        return orig(*a, **kw)

    monkeypatch.setattr(model_mod, "plate_corner_stiffness", counting)
    cp = miura(12, 12, a=1.0, b=1.0, alpha=60.0, fold=40.0)
    k = _bend_k(cp, "N5B8")
    assert len(calls) == 2
    kk = _bend_k(cp, "N5B8", bend_calibration="kirchhoff")
    np.testing.assert_allclose(k / kk, (k / kk)[0], rtol=1e-9)
    cp2 = subdivided(miura(2, 2, a=1.0, b=1.0, alpha=60.0), 2)[0]
    r2 = _bend_k(cp2, "N4B5") / _bend_k(cp2, "N4B5", bend_calibration="kirchhoff")
    np.testing.assert_allclose(r2, (k / kk)[0], rtol=1e-6)


@pytest.mark.parametrize(
    "P",
    [
        [[0, 0], [1, 0], [1, 1e-3], [0, 1e-3]],  # 1000:1 sliver
        [[0, 0], [1, 0.5], [0, 1], [0.3, 0.5]],  # arrow (non-convex, star from centroid)
        [[0, 0], [2, 0], [1, 0.3], [1, 2]],  # dart: the centroid fan is degenerate
        [[np.cos(a), np.sin(a)] for a in np.arange(6) * np.pi / 3],  # hexagon
        [[0, 0], [1, 0], [2, 1e-9], [1, 1]],  # nearly flat corner
    ],
)
def test_every_panel_shape_gives_finite_stiffness_or_an_error(P) -> None:
    for scheme in ("N4B5", "N5B8"):
        try:
            k = _bend_k(_panel(P), scheme)
        except PatternError as e:  # the triangulation rejects zero-area sub-triangles
            assert "degenerate" in str(e) and "\n" not in str(e)
            continue
        assert len(k) and np.all(np.isfinite(k)) and np.all(k > 0)


def test_triangles_have_no_bending_hinges() -> None:
    assert len(_bend_k(_panel([[0, 0], [1, 0], [0, 1]]), "N5B8")) == 0


def test_ear_clipping_matches_the_fan_mesh() -> None:
    """A convex quad meshed by the centroid fan and by ear clipping: same corner-warping
    energy (Morley is exact for a parallelogram's quadratic warping, so both are exact)."""
    import barhinge.model.continuum as cont

    P = np.array([[0, 0], [1, 0], [1.5, np.sqrt(0.75)], [0.5, np.sqrt(0.75)]])
    w = (P[:, 0] - P[:, 0].mean()) * (P[:, 1] - P[:, 1].mean())
    fan = plate_corner_energy(P, MAT, w, 2)
    ears = cont._ear_clip(P, 1.0)
    assert ears.shape == (2, 3)
    dart = np.array([[0, 0], [2, 0], [1, 0.3], [1, 2]], float)
    mesh = polygon_mesh(dart, 1)
    assert mesh.p.shape[1] > 4 and np.all(np.isfinite(mesh.p))
    a, b, c = (mesh.p[:, mesh.t[i]] for i in range(3))
    area = 0.5 * np.abs((b - a)[0] * (c - a)[1] - (b - a)[1] * (c - a)[0]).sum()
    assert area == pytest.approx(abs(cont._signed_area(dart)), rel=1e-12)
    assert fan > 0


def test_errors_are_one_line() -> None:
    with pytest.raises(ConfigError, match="bend_coefficient is the C_B"):
        BarHingeModel.from_pattern(
            _panel([[0, 0], [1, 0], [1, 1], [0, 1]]), "N5B8", MAT, bend_coefficient=0.5
        )
    with pytest.raises(ConfigError, match="zero area"):
        polygon_mesh(np.array([[0, 0], [1, 1], [1, 0], [0, 1]], float), 1)  # bow tie
    with pytest.raises(ConfigError, match="not simple"):
        polygon_mesh(np.array([[0, 0], [2, 0], [2, 2], [1, -1], [0, 2]], float), 1)
    k = _bend_k(
        _panel([[0, 0], [1, 0], [1, 1], [0, 1]]),
        "N5B8",
        bend_calibration="filipov",
        bend_coefficient=0.5,
    )
    assert np.all(k > 0)
