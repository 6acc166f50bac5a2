"""Property tests (hypothesis): generators never produce an invalid pattern inside their
parameter ranges and reject out-of-range parameters with a PatternError naming them."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from barhinge.errors import PatternError
from barhinge.families import (
    curved_pleats,
    diagonal,
    eggbox,
    hypar,
    kresling,
    miura,
    miura_arc,
    miura_nonuniform,
    pleats,
    resch,
    russo_pleat,
    square_twist,
    waterbomb,
    yoshimura,
)
from barhinge.families.properties import kawasaki_error, maekawa_count, sector_sum_error
from barhinge.families.yoshimura import yoshimura_max_fold

SETTINGS = settings(max_examples=20, deadline=None)
small = st.integers(1, 3)
length = st.floats(0.2, 3.0)


def _check_flat(cp, flat_foldable: bool) -> None:
    assert cp.vertices.shape[1] == 2
    assert np.all(cp.face_normals[:, 2] > 0.999)
    iv = cp.interior_vertices
    np.testing.assert_allclose(sector_sum_error(cp)[iv], 0.0, atol=1e-9)
    if flat_foldable:
        assert np.all(np.abs(maekawa_count(cp)[iv]) == 2)
        np.testing.assert_allclose(kawasaki_error(cp)[iv], 0.0, atol=1e-9)


def _check_isometric(flat, folded) -> None:
    def lengths(c):
        X = c.vertices3d
        return np.linalg.norm(X[c.edges[:, 1]] - X[c.edges[:, 0]], axis=1)

    np.testing.assert_allclose(lengths(folded), lengths(flat), atol=1e-9 * flat.size)
    np.testing.assert_allclose(folded.state_fold_angles(), folded.fold_angles, atol=1e-7)


@SETTINGS
@given(small, small, length, length, st.floats(1.0, 89.0), st.floats(0.0, 89.0))
def test_miura_valid(nx, ny, a, b, alpha, theta):
    _check_flat(miura(nx, ny, a=a, b=b, alpha=alpha), True)
    _check_isometric(miura(nx, ny, a=a, b=b, alpha=alpha), miura(nx, ny, a, b, alpha, fold=theta))


@SETTINGS
@given(small, small, st.floats(0.3, 2.0), st.floats(0.2, 2.0), st.floats(0.05, 0.95))
def test_yoshimura_valid(nx, ny, w, h, frac):
    flat = yoshimura(nx, ny, w=w, h=h)
    _check_flat(flat, True)
    fold = min(frac * yoshimura_max_fold(w, h), 360.0 / nx)
    _check_isometric(flat, yoshimura(nx, ny, w=w, h=h, fold=fold))


@SETTINGS
@given(small, small, st.floats(35.0, 70.0), st.floats(-6.0, 6.0), st.floats(1.0, 175.0))
def test_miura_arc_valid(nx, ny, alpha, delta, fold):
    flat = miura_arc(nx, ny, a=1.0, h=0.8, alpha=alpha, delta=delta)
    _check_flat(flat, True)
    _check_isometric(flat, miura_arc(nx, ny, a=1.0, h=0.8, alpha=alpha, delta=delta, fold=fold))


@SETTINGS
@given(
    st.lists(length, min_size=2, max_size=5),
    st.lists(length, min_size=2, max_size=5),
    st.floats(5.0, 85.0),
)
def test_miura_nonuniform_valid(a, b, alpha):
    flat = miura_nonuniform(a, b, alpha=alpha)
    _check_flat(flat, True)
    _check_isometric(flat, miura_nonuniform(a, b, alpha=alpha, fold=45.0))


@SETTINGS
@given(small, small, st.floats(10.0, 80.0), st.floats(0.01, 0.99))
def test_eggbox_valid(nx, ny, alpha, frac):
    lo = 90.0 - alpha
    cp = eggbox(nx, ny, alpha=alpha, fold=lo + frac * alpha)
    assert not cp.developable
    np.testing.assert_allclose(cp.state_fold_angles(), cp.fold_angles, atol=1e-7)


@SETTINGS
@given(
    st.integers(1, 3),
    st.integers(1, 3),
    st.floats(1.0, 44.0),
    st.floats(0.1, 0.9),
)
def test_square_twist_valid(nx, ny, twist, frac):
    t = math.radians(twist)
    a = frac * 2.0 / (math.cos(t) + math.sin(t))
    _check_flat(square_twist(nx, ny, pitch=2.0, a=a, twist=twist), True)


@settings(max_examples=10, deadline=None)
@given(st.integers(1, 4), st.integers(1, 4), length)
def test_grid_families_valid(nx, ny, s):
    _check_flat(waterbomb(nx, ny, s=s), True)
    _check_flat(diagonal(nx, ny, a=s, b=1.0), True)
    _check_flat(kresling(n=nx + 2, stories=ny, a=s), True)
    _check_flat(hypar(n=nx + 1, size=s), False)
    _check_flat(pleats(n=nx + 1, w=s), False)
    _check_flat(curved_pleats(n=nx + 1, w=s / 4, sweep=60.0 * ny), False)
    _check_flat(resch(nx + 3, ny + 2, t=s), False)
    _check_flat(russo_pleat(pleats=nx, strips=ny + 1, width=0.3, angle=10.0 * ny), True)


OUT_OF_RANGE = [
    (miura, {"alpha": 90.0}, "alpha"),
    (miura, {"a": -1.0}, "a"),
    (miura, {"fold": 91.0}, "fold"),
    (yoshimura, {"w": 0.0}, "w"),
    (yoshimura, {"h": float("nan")}, "h"),
    (miura_arc, {"delta": 200.0}, "delta"),
    (miura_arc, {"alpha": 80.0, "delta": 30.0}, "sector angle"),
    (miura_nonuniform, {"a": [1.0, -2.0]}, r"a\[1\]"),
    (miura_nonuniform, {"b": [1.0]}, "b"),
    (eggbox, {"alpha": 60.0, "fold": 20.0}, "fold"),
    (pleats, {"n": 1}, "n"),
    (pleats, {"fold": 180.0}, "fold"),
    (curved_pleats, {"sweep": 360.0}, "sweep"),
    (square_twist, {"twist": 45.0}, "twist"),
    (square_twist, {"a": 5.0}, "a"),
    (waterbomb, {"nx": 0}, "nx"),
    (resch, {"t": 0.0}, "t"),
    (kresling, {"n": 2}, "n"),
    (kresling, {"shift": 1.0}, "shift"),
    (diagonal, {"b": -1.0}, "b"),
    (hypar, {"n": 1}, "n"),
    (russo_pleat, {"width": 1.5}, "width"),
    (russo_pleat, {"angle": 90.0}, "angle"),
]


@pytest.mark.parametrize("fn,kwargs,name", OUT_OF_RANGE)
def test_out_of_range_raises_pattern_error(fn, kwargs, name):
    with pytest.raises(PatternError, match=name):
        fn(**kwargs)


@settings(max_examples=25, deadline=None)
@given(st.floats(allow_nan=True, allow_infinity=True).filter(lambda x: not 0 < x < 90))
def test_miura_alpha_outside_range_always_rejected(alpha):
    with pytest.raises(PatternError, match="alpha"):
        miura(1, 1, alpha=alpha)
