"""Periodic unit cells (barhinge.analysis.periodic) against independent references.

* Rigid-panel limit of the Miura-ori: in-plane ratio -cos^2(theta) tan^2(gamma) (Schenk &
  Guest 2013, PNAS 110(9):3276, Eq. 2; Wei et al. 2013, PRL 110:215501).
* Isometric limit (bars rigid against panel bending): bending ratio +cos^2(theta) tan^2(gamma),
  equal and opposite to the in-plane one (Schenk & Guest 2013; Wei et al. 2013).
* Finite sheets of n x n cells with the macroscopic field prescribed on the boundary (kinematic
  uniform boundary conditions; Hill 1963): an upper bound that tends to the periodic value at
  the rate 1/n (boundary layer / area), computed without any periodic machinery.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from barhinge import families
from barhinge.analysis.periodic import periodic_cell
from barhinge.errors import ConfigError
from barhinge.families.miura import miura_geometry
from barhinge.model.model import BarHingeModel


def _cell(a, b, gam, th, scheme="N5B8", n=2, **model_kw):
    g = miura_geometry(a, b, gam, th)
    cp = families.miura(n, n, a=a, b=b, alpha=gam, fold=th)
    model = BarHingeModel.from_pattern(cp, scheme, **model_kw)
    return g, model, [[2 * g.L, 0, 0], [0, 2 * g.S, 0]]


@pytest.mark.parametrize("scheme", ["N4B5", "N5B8"])
@pytest.mark.parametrize(
    "geom", [(1.0, 1.5, 60.0, 50.0), (1.0, 1.0, 60.0, 30.0), (1.0, 1.0, 45.0, 60.0)]
)
def test_miura_in_plane_ratio_tends_to_schenk_guest_as_panels_stiffen(geom, scheme):
    """nu_SL = -eps_L / eps_S under force along S. The rigid-panel mechanism dominates the
    compliance as the panels stiffen: the error falls as 1/ratio (measured 5e-8 at 1e4,
    5e-10 at 1e6)."""
    err = []
    for ratio in (1e4, 1e6):
        g, model, T = _cell(*geom, scheme, stiffness_ratio=ratio)
        nu_SL = periodic_cell(model, T).moduli()["nu21"]  # -eps_1 / eps_2, force along e2 = S
        err.append(abs(nu_SL / g.nu_SL - 1))
    assert err[1] < 1e-8
    assert np.log10(err[0] / err[1]) == pytest.approx(2.0, abs=0.2)  # error ~ 1 / ratio


@pytest.mark.parametrize("scheme", ["N4B5", "N5B8"])
def test_miura_bending_ratio_is_opposite_to_in_plane_in_the_isometric_limit(scheme):
    """Bent by a moment about e2 (kappa_L driven): -kappa_S / kappa_L = 1 / (cos^2 theta
    tan^2 gamma) when the bars are rigid against panel bending (measured error 9e-8 (N4B5),
    2e-7 (N5B8) at bar ratio 1e4, 100x smaller at 1e6: first order)."""
    err = []
    for bar_ratio in (1e4, 1e6):
        g, model, T = _cell(1.0, 1.5, 60.0, 50.0, scheme, stiffness_ratio=1e3)
        model = model.with_(bar_EA=model.bar_EA * bar_ratio)
        nu_b = periodic_cell(model, T).poisson_bending()  # -kappa_22 / kappa_11
        err.append(abs(1.0 / nu_b / (-g.nu_SL) - 1))
    assert err[1] < 1e-8
    assert np.log10(err[0] / err[1]) == pytest.approx(2.0, abs=0.2)


def test_free_folds_make_the_rigid_folding_mode_a_zero_energy_macroscopic_strain():
    """Folds without stiffness: the Miura's rigid-folding mechanism is a macroscopic strain
    of zero energy (ABD singular to round-off, 1e-14 of its norm) whose strain ratio is the
    kinematic one, -cos^2(theta) tan^2(gamma) (Schenk & Guest 2013, Eq. 2) to round-off."""
    g, model, T = _cell(1.0, 1.5, 60.0, 50.0, fold_k=0.0)
    cell = periodic_cell(model, T)
    w, v = np.linalg.eigh(cell.ABD)
    assert w[0] < 1e-14 * w[-1] and w[1] > 1e-6 * w[-1]
    mode = v[:, 0]
    assert abs(mode[0] / mode[1]) == pytest.approx(-g.nu_SL, rel=1e-9)  # eps_L / eps_S
    assert np.abs(mode[2:]).max() < 1e-9  # no shear, no curvature


def test_result_does_not_depend_on_the_sheet_cut_and_glide_symmetry_removes_coupling():
    """Sheets of 2x2, 3x2 and 3x3 periods describe the same tessellation: the same ABD to
    round-off. The Miura-ori maps onto itself by z -> H - z with a shift of L (glide
    reflection), which flips the sign of the curvatures but not of the strains: B = 0 about
    the mid-plane z0 = H/2; the mirrored sheet gives the same matrix."""
    g, model, T = _cell(1.0, 1.5, 60.0, 50.0)
    ref = periodic_cell(model, T)
    scale = np.abs(ref.ABD).max()
    for nx, ny in ((3, 2), (3, 3)):
        cp = families.miura(nx, ny, a=1.0, b=1.5, alpha=60.0, fold=50.0)
        c = periodic_cell(BarHingeModel.from_pattern(cp, "N5B8"), T)
        np.testing.assert_allclose(c.ABD, ref.ABD, rtol=0, atol=1e-11 * scale)
    assert ref.z0 == pytest.approx(g.H / 2, rel=1e-12)
    assert np.abs(ref.B).max() < 1e-12 * scale
    cp = families.miura(2, 2, a=1.0, b=1.5, alpha=60.0, fold=50.0)
    mirrored = BarHingeModel.from_pattern(cp.replaced(vertices=cp.vertices * [1, 1, -1]), "N5B8")
    np.testing.assert_allclose(periodic_cell(mirrored, T).ABD, ref.ABD, rtol=0, atol=1e-11 * scale)
    # symmetric, positive definite (finite fold stiffness: no periodic mechanism)
    np.testing.assert_allclose(ref.ABD, ref.ABD.T, rtol=0, atol=1e-12 * scale)
    assert np.linalg.eigvalsh(ref.ABD).min() > 0


def _kinematic_sheet_abd(n: int, z0: float, area: float) -> np.ndarray:
    """ABD of an n x n-cell Miura sheet with the macroscopic field prescribed on every
    boundary vertex and the interior free (energy per projected area of n^2 cells); built
    from the sheet's tangent only."""
    cp = families.miura(n, n, a=1.0, b=1.5, alpha=60.0, fold=50.0)
    m = BarHingeModel.from_pattern(cp, "N5B8")
    X = m.X0
    x, y, _ = (X - X.mean(0)).T
    z, o = X[:, 2] - z0, np.zeros(len(X))
    Phi = np.stack(
        [
            np.stack(c, 1)
            for c in (
                (x, o, o), (o, y, o), (y / 2, x / 2, o),
                (-z * x, o, x * x / 2), (o, -z * y, y * y / 2), (-z * y / 2, -z * x / 2, x * y / 2),
            )
        ],
        axis=2,
    ).reshape(-1, 6)  # fmt: skip
    K = sp.csr_matrix(m.tangent(X))
    free = np.ones(len(X), bool)
    free[cp.boundary_vertices] = False
    f = np.flatnonzero(np.repeat(free, 3))
    KP = (K @ Phi)[f]
    Keff = Phi.T @ (K @ Phi) - KP.T @ spla.splu(K[f][:, f].tocsc()).solve(KP)
    return Keff / (n * n * area)


def test_large_finite_sheet_tends_to_the_periodic_cell_at_rate_one_over_n():
    """Kinematic uniform boundary conditions give an upper bound of every diagonal term that
    closes as the boundary layer's share of the sheet, 1/n (measured slopes -0.97 to -1.2
    over n = 4, 8, 16; e.g. A_11: +30 %, +13 %, +6.3 %)."""
    g, model, T = _cell(1.0, 1.5, 60.0, 50.0)
    cell = periodic_cell(model, T)
    ns = np.array([4, 8, 16])
    rel = np.array([np.diag(_kinematic_sheet_abd(n, cell.z0, cell.area)) for n in ns])
    rel = rel / np.diag(cell.ABD) - 1
    assert (rel > 0).all()  # an upper bound
    assert (np.diff(rel, axis=0) < 0).all()  # closing monotonically
    slopes = np.polyfit(np.log(ns), np.log(rel), 1)[0]
    assert slopes == pytest.approx(-1.0, abs=0.3)
    assert rel[-1, :5].max() < 0.07  # A and the two bending terms within 7 % at 16 x 16


def _periodic_table():
    """scripts/periodic_table.py, the script that writes docs/periodic.md's tables."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[2] / "scripts" / "periodic_table.py"
    spec = importlib.util.spec_from_file_location("periodic_table", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_free_edge_sheet_centre_tends_to_the_periodic_compliance_at_rate_one_over_n():
    """Static check, free edges: under a uniform end load the centre cell of an n x n sheet
    strains as the periodic compliance column (a_1d, a_2d) predicts, with an error that falls
    like 1/n (measured at n = 8, 16, 32 for force along x: eps_x 5.2 %, 2.8 %, 1.4 %)."""
    # centre_strain: an n x n-cell Miura sheet (a=1, b=1.5, gamma=60, theta=50, N5B8) under a
    # unit stress resultant along x (d = 0) or y (d = 1), equal nodal forces on the two end
    # columns / rows, free edges, 3-2-1 restraint; eps_x averages both layers (mid-plane)
    centre_strain = _periodic_table().centre_strain
    g, model, T = _cell(1.0, 1.5, 60.0, 50.0)
    a = periodic_cell(model, T).in_plane_compliance(free_curvature=True)
    ns = np.array([8, 16, 32])
    signed = []
    for d in (0, 1):
        e = np.array([centre_strain(n, d) / a[:2, d] - 1 for n in ns])
        signed.append(e)
        slopes = np.polyfit(np.log(ns), np.log(np.abs(e)), 1)[0]
        assert np.all(slopes == pytest.approx(-1.0, abs=0.3)), slopes
        assert np.abs(e[-1]).max() < 0.03
    # docs/periodic.md, Table 3 (written by scripts/periodic_table.py) shows these numbers
    import re
    from pathlib import Path

    text = (Path(__file__).resolve().parents[2] / "docs" / "periodic.md").read_text("utf-8")
    t3 = text[text.index("### Table 3") : text.index("<!-- periodic-table:end -->")]
    rows = [ln for ln in t3.splitlines() if re.match(r"\| \d+ \|", ln)]
    doc = np.array([[float(x) for x in ln.strip("| ").split(" | ")[1:]] for ln in rows])
    got = np.concatenate([signed[0], signed[1]], axis=1)  # (n, [d0 ex, d0 ey, d1 ex, d1 ey])
    np.testing.assert_allclose(doc, got, rtol=0, atol=6e-5)  # 4 printed digits


def test_bad_input_is_a_config_error():
    g, model, T = _cell(1.0, 1.5, 60.0, 50.0)
    with pytest.raises(ConfigError, match="parallel"):
        periodic_cell(model, [[1.0, 0, 0], [2.0, 0, 0]])
    with pytest.raises(ConfigError, match="one lattice vector apart along t1"):
        periodic_cell(model, [[2 * g.L * 1.01, 0, 0], [0, 2 * g.S, 0]])
    with pytest.raises(ConfigError, match="shape"):
        periodic_cell(model, [1.0, 2.0])
    one = BarHingeModel.from_pattern(families.miura(1, 1, a=1.0, b=1.5, alpha=60.0, fold=50.0))
    with pytest.raises(ConfigError, match="2 x 2 periods"):
        periodic_cell(one, T)


def test_docs_example_runs_and_the_doc_table_matches_the_script():
    """docs/periodic.md: its example runs and gives the Schenk & Guest ratio's neighbourhood
    at the default material (folds soft against the panels: within 1e-3); its tables are
    the output of scripts/periodic_table.py (up to the date stamp)."""
    import re
    from pathlib import Path

    root = Path(__file__).resolve().parents[2]
    text = (root / "docs" / "periodic.md").read_text(encoding="utf-8")
    block = re.search(r"```python\n(.*?)```", text, flags=re.S)
    ns: dict = {"__name__": "periodic_doc", "print": lambda *a, **k: None}
    exec(compile(block.group(1), "docs/periodic.md", "exec"), ns)
    assert ns["cell"].moduli()["nu21"] == pytest.approx(ns["g"].nu_SL, rel=1e-3)
    mod = _periodic_table()
    ex, slopes, moduli = mod.sheet_rows()
    table = mod.render(mod.limit_rows(), ex, slopes, moduli)  # Table 3 is checked above
    body = text[text.index(mod.START) + len(mod.START) : text.index(mod.END)]
    body = body[: body.index("### Table 3")]

    def numbers(s: str) -> np.ndarray:
        lines = [ln for ln in s.strip().splitlines() if not ln.startswith("*Generated")]
        return np.array(
            [float(x) for x in re.findall(r"-?\d+\.?\d*(?:e[-+]\d+)?", "\n".join(lines))]
        )

    # the values to their printed digits; errors at round-off (~1e-9) may differ by machine
    np.testing.assert_allclose(numbers(body), numbers(table), rtol=2e-3, atol=1e-8)


def test_cst_membrane_is_refused_with_a_named_reason():
    """The cell weighs bars one by one; the CST membrane couples the sides of a triangle."""
    _, model, T = _cell(1.0, 1.0, 60.0, 30.0, bar_calibration="cst")
    with pytest.raises(ConfigError, match="CST membrane"):
        periodic_cell(model, T)
