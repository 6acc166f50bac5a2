"""DOF counts, ranks, redundancy, local DOF and actuators.

Counting estimate: Tachi (2010), "Geometric considerations for the design of rigid origami
structures", Proc. IASS: DOF >= E_in - 3 V_in - sum_panels (n - 3) (E_in counted on the
triangulated pattern). For a triangulated disk the count equals (boundary edges) - 3 (Euler's
formula; Tachi 2010). The true DOF comes from the rank of the loop-closure Jacobian and is
checked here against the independent nodal formulation (bar lengths + panel planarity).
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sla

import barhinge as bh
from barhinge.kinematics.constraints import NodalConstraints, RigidConstraints
from barhinge.kinematics.dof import folded_sample


def _tachi_count(cp, triangulated=False) -> int:
    """E_in(triangulated) - 3 V_in - sum(n - 3) over rigid panels (none when the panels may
    fold along their diagonals), computed from the pattern directly."""
    EF = cp.edge_faces
    interior_edges = int(np.sum((EF >= 0).all(1) & np.isin(cp.assignment, list("MVFU"))))
    extra = sum(len(f) - 3 for f in cp.faces)
    v_in = len(cp.interior_vertices)
    return (interior_edges + extra) - 3 * v_in - (0 if triangulated else extra)


def _nodal_dof(cp, X, triangulated=False) -> int:
    nc = NodalConstraints.from_pattern(cp, triangulated=triangulated)
    r, J = nc.evaluate(X)
    assert np.abs(r).max() < 1e-12 * max(cp.size, 1.0) ** 2  # squared lengths
    s = sla.svd(J.toarray(), compute_uv=False)
    return 3 * cp.n_vertices - int(np.sum(s > 1e-8 * s[0])) - 6


def _family(name, **kw):
    if name not in bh.families.FAMILIES:
        pytest.skip(f"pattern family {name} not available")
    return bh.families.FAMILIES[name](**kw)


def test_miura_rigid_quads_one_dof_from_redundant_constraints():
    """Miura-ori with rigid quads: the count is negative (more equations than creases) but the
    sheet folds with 1 DOF because the vertex conditions are redundant (Tachi 2009, 2010):
    redundant = 1 - count. The flat state is a bifurcation point with a larger first-order
    DOF."""
    cp = bh.families.miura(3, 3)
    rep = bh.dof(cp)
    assert rep.counted_dof == _tachi_count(cp) == 60 - 3 * 25  # 60 creases, 25 int. vertices
    assert rep.flat and rep.folded is not None
    f = rep.folded
    assert f.global_dof == 1
    assert f.redundant == 1 - f.counted_dof == 16
    assert rep.global_dof > 1 and rep.global_dof == _nodal_dof(cp, cp.vertices3d)
    assert np.all(f.local[f.local >= 0] == 1) and np.all(f.region[f.region >= 0] == 1)
    assert len(f.actuators) == 1
    # at an exact folded state from the closed form: same numbers
    g = bh.dof(bh.families.miura(3, 3, fold=50.0))
    assert not g.flat and g.global_dof == 1 and g.redundant == 16


def test_miura_triangulated_dof_equals_boundary_edges_minus_three():
    cp = bh.families.miura(3, 3)
    rep = bh.dof(cp, triangulated=True)
    f = rep.folded
    n_boundary = len(cp.boundary_edges)
    assert f.global_dof == f.counted_dof == n_boundary - 3  # Tachi 2010
    assert f.redundant == 0
    rc = RigidConstraints.from_pattern(cp, triangulated=True)
    rho = folded_sample(rc)
    assert f.global_dof == _nodal_dof(cp, rc.coordinates(rho), triangulated=True)
    # local DOF of a triangulated vertex = degree - 3
    deg = rc.pattern.vertex_degree
    assert np.all(f.local[rc.vertices] == deg[rc.vertices] - 3)


@pytest.mark.parametrize(
    "name, kw",
    [
        ("yoshimura", dict(nx=3, ny=2)),
        ("waterbomb", dict(nx=2, ny=2)),
        ("square_twist", dict(nx=2, ny=2)),
        ("resch", dict(nx=3, ny=3)),
        ("hypar", dict(n=3)),
        ("miura", dict(nx=2, ny=3)),
    ],
)
@pytest.mark.parametrize("triangulated", [False, True])
def test_family_dof_rank_agrees_with_nodal_formulation(name, kw, triangulated):
    """At the flat state and at a folded state nearby (when one exists) the angle-formulation
    DOF equals the nodal one; DOF - count = redundant >= 0. All-triangle patterns (Yoshimura,
    waterbomb) and triangulated ones have no redundancy at a folded state and DOF = boundary
    edges - 3."""
    cp = _family(name, **kw)
    rep = bh.dof(cp, triangulated=triangulated)
    assert rep.counted_dof == _tachi_count(cp, triangulated)
    assert rep.redundant == rep.global_dof - rep.counted_dof >= 0
    assert rep.global_dof == _nodal_dof(cp, cp.vertices3d, triangulated)
    all_tri = all(len(f) == 3 for f in cp.faces)
    rc = RigidConstraints.from_pattern(cp, triangulated=triangulated)
    if rep.folded is None:
        # rigid quads that cannot fold (hypar: Demaine et al. 2011; see docs): no folded state
        assert not triangulated and not all_tri
        assert "not rigidly foldable" in rep.note or "no rigidly folded" in rep.note
        return
    f = rep.folded
    rho = folded_sample(rc)
    assert f.global_dof == _nodal_dof(cp, rc.coordinates(rho), triangulated)
    assert f.redundant >= 0
    if triangulated or all_tri:
        assert f.redundant == 0
        assert f.global_dof == len(cp.boundary_edges) - 3


def test_dof_of_a_given_state_by_angles_and_coordinates():
    cp = bh.families.miura(2, 2)
    ref = bh.families.miura(2, 2, fold=35.0)
    by_angles = bh.dof(cp, state=ref.fold_angles)
    by_coords = bh.dof(cp, state=ref.vertices3d)
    assert by_angles.global_dof == by_coords.global_dof == 1
    assert by_angles.closure < 1e-12 and not by_angles.flat
    np.testing.assert_allclose(by_angles.fold_angles_deg, ref.fold_angles, atol=1e-9)
    with pytest.raises(bh.ConfigError, match="state must be"):
        bh.dof(cp, state=np.zeros(5))


def test_actuators_determine_the_motion_and_can_be_steered():
    cp = _family("yoshimura", nx=4, ny=3)
    rep = bh.dof(cp).mechanism
    k = rep.global_dof
    assert len(rep.actuators) == k
    rc = RigidConstraints.from_pattern(cp)
    rho = folded_sample(rc)
    from barhinge.linalg.nullspace import null_space

    N = null_space(rc.jacobian(rho)).basis
    for prefer in (None, "boundary", "interior", "spread"):
        acts = bh.dof(cp, prefer=prefer).mechanism.actuators
        A = rc.var_of_source_edge[acts]
        assert len(A) == k and np.linalg.matrix_rank(N[A], tol=1e-8) == k
    # a preferred region is used as far as it can be
    region = rc.var_source_edge[np.flatnonzero(np.abs(N).sum(1) > 1e-9)][: k + 3]
    acts = bh.dof(cp, prefer=region.tolist()).mechanism.actuators
    assert len(set(acts.tolist()) & set(region.tolist())) >= min(k, 3)
    # boundary preference: chosen creases closer to the boundary on average than interior
    hops = lambda a: np.mean(  # noqa: E731
        [
            min(
                np.linalg.norm(cp.vertices[cp.edges[e]].mean(0) - cp.vertices[v])
                for v in cp.boundary_vertices
            )
            for e in a
        ]
    )
    b = bh.dof(cp, prefer="boundary").mechanism.actuators
    i = bh.dof(cp, prefer="interior").mechanism.actuators
    assert hops(b) <= hops(i)
    with pytest.raises(bh.ConfigError, match="prefer"):
        bh.dof(cp, prefer="nowhere")


def test_suggested_actuators_drive_a_rigid_path():
    """Driving exactly the suggested actuators folds the pattern without under- or
    over-determination errors (waterbomb, 11 DOF)."""
    cp = _family("waterbomb", nx=2, ny=2)
    rep = bh.dof(cp).mechanism
    acts = rep.actuators
    targets = 0.5 * rep.fold_angles_deg[acts]  # half way back to flat along the same branch
    path = bh.rigid_fold(cp, acts.tolist(), (2 * targets).tolist(), steps=4)
    assert path.converged and path.meta["max_closure"] < 1e-10
    np.testing.assert_allclose(path.fold_angles_deg[-1, acts], 2 * targets, atol=1e-9)


def _holed_miura(fold=None, drop=(14,)):
    cp = bh.families.miura(4, 4) if fold is None else bh.families.miura(4, 4, fold=fold)
    faces = [f for i, f in enumerate(cp.faces) if i not in drop]  # remove inner panels
    return bh.CreasePattern(
        cp.vertices, cp.edges, cp.assignment, cp.fold_angles, faces=faces, validate=False
    )


@pytest.mark.parametrize("fold", [None, 50.0])
@pytest.mark.parametrize("drop", [(14,), (14, 30)])
@pytest.mark.parametrize("triangulated", [False, True])
def test_pattern_with_holes_closes_the_chain_around_each_hole(fold, drop, triangulated):
    """Loops of panels around a hole are not generated by the vertex loops: each hole adds 6
    closure conditions (holes = components - (V - E + F)). The DOF with them equals the
    independent nodal count (bar lengths and planarity in coordinates, dense SVD), and on a
    triangulated folded sheet it equals the generic count E_in - 3 V_in - 6 h (Euler's formula
    for a disk with h holes), while the vertex loops alone over-count by 6 per hole."""
    holed = _holed_miura(fold, drop)
    rc = RigidConstraints.from_pattern(holed, triangulated=triangulated)
    assert rc.holes == len(drop)
    rep = bh.dof(holed, triangulated=triangulated)
    assert f"{len(drop)} hole(s)" in rep.note
    assert rep.global_dof == _nodal_dof(holed, holed.vertices3d, triangulated)
    assert rep.n_equations == 3 * len(rc.vertices) + 6 * len(drop)
    if fold is not None and triangulated:
        assert rep.global_dof == rep.counted_dof
        vertex_only = rc.n_var - np.linalg.matrix_rank(rc.jacobian(rc.rho0).toarray(), 1e-8)
        assert vertex_only == rep.global_dof + 6 * len(drop)


def test_hole_chain_jacobian_matches_finite_differences():
    from barhinge.kinematics.holes import hole_loops

    holed = _holed_miura(drop=(14, 30))
    rc = RigidConstraints.from_pattern(holed)
    hl = hole_loops(rc)
    assert hl.n_holes == 2 and hl.unclosed == 0
    # a rigid folded state from the closed form closes every chain
    ref = bh.families.miura(4, 4, fold=50.0)
    rho = np.zeros(rc.n_var)
    vs = rc.var_source_edge
    rho[vs >= 0] = np.radians(ref.fold_angles[vs[vs >= 0]])
    assert hl.closure_error(rho).max() < 1e-12
    x = rho + 0.1 * np.random.default_rng(0).standard_normal(rc.n_var)
    assert hl.closure_error(x).min() > 1e-3
    J = hl.evaluate(x)[1].toarray()
    h = 1e-6
    fd = np.column_stack(
        [
            (hl.evaluate(x + h * e)[0] - hl.evaluate(x - h * e)[0]) / (2 * h)
            for e in np.eye(rc.n_var)
        ]
    )
    np.testing.assert_allclose(J, fd, atol=1e-8)


def test_reflex_panel_corner_closes_the_flat_hypar(shared_patterns):
    """Origami Simulator's hypar has a non-convex quad (a crossing a few units off a corner):
    its reflex corner (> 180°) must be measured as such, so every vertex closes flat (the
    sector angles sum to 2 pi, as the pattern's own angle defect says)."""
    cp = bh.read(shared_patterns / "origami-simulator/hypar.svg")
    rc = RigidConstraints.from_pattern(cp)
    assert np.nanmax(np.abs(cp.angle_defect)) < 1e-9
    assert rc.loop_alpha.max() > np.pi
    np.testing.assert_allclose(rc.loop_alpha.sum(1), 2 * np.pi, atol=1e-9)
    assert rc.closure_error(rc.rho0).max() < 1e-12


def test_hypar_with_unassigned_triangulation_creases_folds_with_the_generic_dof(
    shared_patterns,
):
    """The hypar drawn with 96 unassigned (U) triangulation creases: they fold with no sign
    imposed. Triangulated (its two quads split), the sheet is a triangulated disk with 4
    boundary edges, whose generic DOF is 4 - 3 = 1 (Tachi 2010); the rank at the folded state
    found agrees, and so does the nodal formulation at the same coordinates. With its two
    quads rigid the report says why no folded state was found."""
    cp = bh.read(shared_patterns / "origami-simulator/hypar.svg")
    assert np.sum(cp.assignment == "U") == 96
    rep = bh.dof(cp)
    assert rep.folded is None and "non-triangular panel" in rep.note
    rep = bh.dof(cp, triangulated=True)
    f = rep.folded
    assert f is not None and f.certain
    assert f.global_dof == f.counted_dof == len(cp.boundary_edges) - 3 == 1
    rc = RigidConstraints.from_pattern(cp, triangulated=True)
    rho = folded_sample(rc)
    assert f.global_dof == _nodal_dof(cp, rc.coordinates(rho), triangulated=True)
    u = rc.var_of_source_edge[np.flatnonzero(cp.assignment == "U")]
    assert np.abs(rho[u]).max() > 1e-2  # the unassigned creases fold too


def test_unassigned_creases_fold_either_way():
    """A Yoshimura sheet with half its creases unassigned folds; all-triangle, so its DOF at
    a generic folded state is boundary edges - 3 (Tachi 2010), as with full M/V, and the nodal
    formulation agrees."""
    cp = _family("yoshimura", nx=3, ny=2)
    asg = cp.assignment.copy()
    crease = np.flatnonzero(np.isin(asg, ["M", "V"]))
    asg[crease[::2]] = "U"
    u = bh.CreasePattern(cp.vertices, cp.edges, asg, np.where(asg == "U", 0.0, 0.0))
    f = bh.dof(u).folded
    assert f is not None
    assert f.global_dof == len(cp.boundary_edges) - 3 == bh.dof(cp).folded.global_dof
    rc = RigidConstraints.from_pattern(u)
    assert f.global_dof == _nodal_dof(u, rc.coordinates(folded_sample(rc)))


def test_progress_reports_every_stage_in_order():
    """``bh.dof(progress=...)`` is called before each stage and once at the end (the CLI's
    progress bar); a flat pattern with a folded state nearby has 8 stages."""
    calls = []
    rep = bh.dof(bh.families.miura(3, 3), progress=lambda *a: calls.append(a))
    assert rep.folded is not None
    stages = [c[0] for c in calls]
    assert stages[0] == "loop-closure constraints" and stages[-1] == "done"
    assert "folded state nearby" in stages and stages.count("actuators") == 2
    done = [c[1] for c in calls]
    assert done == sorted(done) and calls[-1][1] == calls[-1][2] == 8


def test_wide_flat_null_space_gives_the_same_report_without_flat_actuators(monkeypatch):
    """Flat Yoshimura 16 x 16 (sparse method): with the flat null vectors skipped (limit
    below the nullity) every count, gap, local/region DOF and the folded state's actuators
    equal those of the full computation; the flat state chooses no actuators and says why."""
    import importlib

    dof_mod = importlib.import_module("barhinge.kinematics.dof")
    cp = bh.families.FAMILIES["yoshimura"](nx=16, ny=16)
    full = bh.dof(cp)
    monkeypatch.setattr(dof_mod, "FLAT_BASIS_LIMIT", 50)
    wide = bh.dof(cp)
    assert (
        full.method == "sparse-inertia"
        and full.global_dof > 50
        and len(full.actuators) == full.global_dof
    )
    for a, b in ((wide, full), (wide.folded, full.folded)):
        assert (a.global_dof, a.counted_dof, a.redundant, a.rank, a.dof_range, a.certain) == (
            b.global_dof, b.counted_dof, b.redundant, b.rank, b.dof_range, b.certain
        )  # fmt: skip
        assert abs(a.sigma_gap - b.sigma_gap) <= 2e-4 * b.sigma_gap
        assert np.array_equal(a.local, b.local) and np.array_equal(a.region, b.region)
    assert np.array_equal(wide.folded.actuators, full.folded.actuators)
    assert len(wide.actuators) == 0 and "no actuators chosen at this flat state" in wide.note
    assert wide.global_dof == _nodal_dof(cp, cp.vertices3d)
