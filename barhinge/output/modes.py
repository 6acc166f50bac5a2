"""VTU files of mode shapes (buckling or stiffness modes), one file per mode (meshio).

Each file holds the state's triangles (the model's triangulation) with the point data
``mode`` (n_nodes, 3; unit largest amplitude) and ``mode_magnitude``, and the field data
``factor`` (the buckling load factor or eigenvalue). Open them in ParaView / PyVista and warp
by ``mode``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from barhinge.errors import ConfigError
from barhinge.model.triangulate import triangulate

__all__ = ["write_mode_vtus"]


def write_mode_vtus(
    folder: str | Path,
    model: Any,
    X: np.ndarray,
    modes: np.ndarray,
    factors: np.ndarray,
    stem: str = "buckling_mode",
) -> list[Path]:
    """Write ``folder/{stem}_{i}.vtu`` for every mode ``i`` (1-based).

    Parameters
    ----------
    folder : an existing folder.
    model : BarHingeModel
    X : (n_nodes, 3) float
        The state the modes belong to.
    modes : (n_modes, n_nodes, 3) float
    factors : (n_modes,) float
    """
    import meshio

    folder = Path(folder)
    if not folder.is_dir():
        raise ConfigError(f"mode files: {folder} is not a folder")
    modes = np.asarray(modes, float)
    X = np.asarray(X, float)
    if modes.ndim != 3 or modes.shape[1:] != X.shape:
        raise ConfigError(f"modes must have shape (n, {len(X)}, 3), got {modes.shape}")
    factors = np.asarray(factors, float).ravel()
    if len(factors) != len(modes):
        raise ConfigError(f"len(factors) = {len(factors)}, but len(modes) = {len(modes)}")
    tri = triangulate(model.pattern, model.scheme).triangles
    out = []
    for i, (phi, lam) in enumerate(zip(modes, factors, strict=True), start=1):
        mesh = meshio.Mesh(
            X,
            [("triangle", np.asarray(tri, np.int64))],
            point_data={"mode": phi, "mode_magnitude": np.linalg.norm(phi, axis=1)},
            field_data={"factor": np.array([lam])},
        )
        path = folder / f"{stem}_{i}.vtu"
        mesh.write(path)
        out.append(path)
    return out
