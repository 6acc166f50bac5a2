"""Make the pictures of docs/results.md (run from the repository root):

    python docs/img/make_results_figures.py

Prints the numbers quoted in docs/results.md.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

import barhinge as bh
from barhinge.analysis.poisson import bending_poisson, grid_pairs, periodic_poisson
from barhinge.analysis.stiffness import linear_response, stiffness_modes
from barhinge.plot import charts, render
from barhinge.scene import default_scene, restraint_321

IMG = Path(__file__).resolve().parent


def default_scene_pictures() -> None:
    scene = default_scene()
    path = bh.solve(scene)
    X = path.X[-1]
    render.render_state(
        X,
        IMG / "default_scene.png",
        model=scene.model,
        title="barhinge fold (default scene): final state",
    )
    render.render_state(
        X, IMG / "default_scene_energy.png", model=scene.model, scalars="energy_density"
    )
    charts.summary_figure(path, IMG / "default_scene_charts.png")
    render.animate(
        path, IMG / "default_scene.gif", model=scene.model, max_frames=16, window_size=(480, 360)
    )
    modes = stiffness_modes(scene.model, X, fixed=scene.fixed, k=4)
    print("default scene: lowest eigenvalues", modes.eigenvalues, "soft", modes.n_soft)
    render.render_mode(
        X,
        modes.shapes[0],
        IMG / "default_scene_mode0.png",
        model=scene.model,
        title=f"lowest mode, eigenvalue {modes.eigenvalues[0]:.3g}",
    )


def poisson_pictures() -> None:
    alpha = 60.0
    theta = np.linspace(5.0, 85.0, 33)
    X = np.array([bh.families.miura(3, 3, alpha=alpha, fold=t).vertices3d for t in theta])
    px, py = grid_pairs(bh.families.miura(3, 3, alpha=alpha, fold=5.0))
    res = periodic_poisson(X, py, px, parameter=np.radians(theta))
    fine = np.linspace(5.0, 85.0, 200)
    ref = -(np.cos(np.radians(fine)) ** 2) * np.tan(np.radians(alpha)) ** 2
    charts.plot_poisson(
        theta,
        res.nu,
        path=IMG / "miura_poisson.png",
        label="periodic cell, measured along the fold path",
        reference=(fine, ref, "Schenk & Guest (2013): -cos²θ tan²γ"),
    )
    print("max |nu - closed form| =", np.abs(res.nu - np.interp(theta, fine, ref)).max())


def saddle_picture() -> None:
    theta, alpha = 45.0, 60.0
    cp = bh.families.miura(6, 6, alpha=alpha, fold=theta)
    model = bh.BarHingeModel.from_pattern(
        cp, scheme="N4B5", stiffness_ratio=1e3, material=bh.Material(E=1e6, nu=1 / 3, t=0.01)
    )
    nv = cp.n_vertices
    ni, nj = cp.meta["barhinge:grid"]
    J = np.arange(nv) // ni
    top = np.isclose(cp.vertices[:, 2], cp.vertices[:, 2].max())
    F = np.zeros((model.n_nodes, 3))
    for end, sign in ((J == 0, -1.0), (J == nj - 1, 1.0)):
        F[:nv][end & top, 1] += sign / (end & top).sum()
        F[:nv][end & ~top, 1] -= sign / (end & ~top).sum()
    U, _ = linear_response(model, F, restraint_321(model))
    U = U - U[:nv].mean(0)
    Xb = model.X0 + 1.2 / np.abs(U[:, 2]).max() * U
    inner = (J > 1) & (J < nj - 2)
    r = bending_poisson(model.X0 + 1e-3 / np.abs(U).max() * U, np.flatnonzero(top & inner))
    print(
        f"bent Miura: K < 0: {r.K < 0}, -k_x/k_y = {r.nu_yx:.4f}, "
        f"cos^2 tan^2 = {np.cos(np.radians(theta)) ** 2 * np.tan(np.radians(alpha)) ** 2:.4f}"
    )
    render.render_state(
        Xb,
        IMG / "miura_saddle.png",
        model=model,
        scalars=U[:, 2],
        cmap="coolwarm",
        title="Miura bent by end moments: a saddle",
        label="vertical displacement (scaled)",
    )


if __name__ == "__main__":
    poisson_pictures()
    saddle_picture()
    default_scene_pictures()
