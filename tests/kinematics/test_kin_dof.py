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
    assert np.abs(r).max() < 1e-9
    s = sla.svd(J.toarray(), compute_uv=False)
    return 3 * cp.n_vertices - int(np.sum(s > 1e-8 * s[0])) - 6


def _family(name, **kw):
    if name not in bh.patterns.FAMILIES:
        pytest.skip(f"pattern family {name} not available")
    return bh.patterns.FAMILIES[name](**kw)


def test_miura_rigid_quads_one_dof_from_redundant_constraints():
    """Miura-ori with rigid quads: the count is negative (more equations than creases) but the
    sheet folds with 1 DOF because the vertex conditions are redundant (Tachi 2009, 2010):
    redundant = 1 - count. The flat state is a bifurcation point with a larger first-order
    DOF."""
    cp = bh.patterns.miura(3, 3)
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
    g = bh.dof(bh.patterns.miura(3, 3, fold=50.0))
    assert not g.flat and g.global_dof == 1 and g.redundant == 16


def test_miura_triangulated_dof_equals_boundary_edges_minus_three():
    cp = bh.patterns.miura(3, 3)
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
    cp = bh.patterns.miura(2, 2)
    ref = bh.patterns.miura(2, 2, fold=35.0)
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


def test_pattern_with_a_hole_is_flagged():
    """Loops of panels around a hole are not constrained by vertex loop closure: the report
    says so (Euler characteristic: holes = components - (V - E + F))."""
    cp = bh.patterns.miura(3, 3)
    faces = [f for i, f in enumerate(cp.faces) if i != 14]  # remove an inner panel
    holed = bh.CreasePattern(
        cp.vertices, cp.edges, cp.assignment, cp.fold_angles, faces=faces, validate=False
    )
    assert RigidConstraints.from_pattern(cp).holes == 0
    assert RigidConstraints.from_pattern(holed).holes == 1
    assert "1 hole" in bh.dof(holed).note
