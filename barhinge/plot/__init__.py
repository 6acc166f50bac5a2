"""Pictures: 3-D renders (pyvista, off-screen; ``render``), charts (matplotlib; ``charts``),
crease-pattern drawings (``pattern``) and DOF pictures (``dof``).

Nothing here is imported by ``import barhinge``; rendering libraries load on first use.
"""

from __future__ import annotations

import logging
import os
from pathlib import Path
from typing import Any

__all__ = ["fold_outputs_hook", "results_rows", "results_summary", "write_pictures"]

log = logging.getLogger(__name__)


def write_pictures(
    fold_path: Any,
    model: Any | None,
    out_dir: str | Path,
    *,
    pattern: Any | None = None,
    name: str = "result",
    gif: bool = True,
    extra_arrays: tuple[str, ...] = ("energy_density",),
    fixed: Any | None = None,
    loads: Any | None = None,
) -> dict[str, Path]:
    """Write the standard pictures of a fold path into ``out_dir``.

    ``<name>.png`` (final state, creases coloured by fold angle), ``<name>_<array>.png`` for
    each of ``extra_arrays`` (bar-and-hinge paths only), ``<name>_charts.png`` (actuator
    angles, energy split, actuator moments) and ``<name>.gif`` (the fold path).

    ``fixed`` and ``loads`` ((n_nodes, 3) arrays of the scene) are drawn on the state
    pictures: supports as black dots, loads as purple arrows.

    Returns a dict from a picture kind to its path.
    """
    from barhinge.plot import charts, render

    cp = pattern if pattern is not None else getattr(model, "pattern", None)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    kw: dict[str, Any] = {"model": model, "pattern": cp if model is None else None}
    fa = fold_path.fold_angles_deg[-1] if model is None else None
    done: dict[str, Path] = {}
    last = fold_path.n_states - 1
    scene = fold_path.meta.get("scene") or name
    title = f"{scene}: state {last} of {last}" + ("" if fold_path.converged else " (stopped)")
    marks = {"fixed": fixed, "loads": loads}
    done["png"] = render.render_state(
        fold_path.X[-1], out / f"{name}.png", fold_angles_deg=fa, title=title, **marks, **kw
    )
    if model is not None:
        for arr in extra_arrays:
            done[arr] = render.render_state(
                fold_path.X[-1], out / f"{name}_{arr}.png", scalars=arr, title=title,
                **marks, **kw,
            )  # fmt: skip
    done["charts"] = out / f"{name}_charts.png"
    charts.summary_figure(fold_path, done["charts"])
    if gif and fold_path.n_states > 1:
        done["gif"] = render.animate(fold_path, out / f"{name}.gif", max_frames=30, **kw)
    return done


def fold_outputs_hook(fold_path: Any, scene: Any, out_dir: Path) -> list[Path]:
    """Hook for :data:`barhinge.solve.outputs.OUTPUT_HOOKS`: result files
    (:func:`barhinge.io.write_results`, stem ``fold_path``) and pictures of a solved scene.

    Writes ``fold_path.xdmf``/``.h5``, ``fold_path_bars.xdmf``, ``fold_path_NNNN.vtu`` (every
    state), ``fold_path.fold`` (FOLD frames), ``fold_path_steps.csv``,
    ``fold_path_summary.json`` (final state, stiffness, curvature, strains) and
    ``fold_path.png``, ``fold_path_energy_density.png``, ``fold_path_charts.png``,
    ``fold_path.gif`` (skipped when the environment sets ``BARHINGE_PICTURES=0``).
    """
    from barhinge.io import write_results

    model = scene.model
    fixed = getattr(scene, "fixed", None)
    loads = getattr(scene, "loads", None)
    files = write_results(
        fold_path, model, out_dir, name="fold_path", npz=False, fixed=fixed, loads=loads
    )
    if os.environ.get("BARHINGE_PICTURES", "").strip() == "0":
        log.info("BARHINGE_PICTURES=0: no pictures")
        return list(files.values())
    try:
        pics = write_pictures(fold_path, model, out_dir, name="fold_path", fixed=fixed, loads=loads)
    except Exception as exc:  # noqa: BLE001 - pictures are optional; never lose the results
        log.warning("pictures not written: %s", exc)
        pics = {}
    return [*files.values(), *pics.values()]


def results_summary(out_dir: str | Path, name: str = "fold_path") -> dict[str, Any]:
    """The ``summary`` record of ``<name>_summary.json`` in ``out_dir`` ({} if absent)."""
    import json

    f = Path(out_dir) / f"{name}_summary.json"
    if not f.is_file():
        return {}
    return json.loads(f.read_text()).get("summary", {})


def results_rows(out_dir: str | Path, name: str = "fold_path") -> list[tuple[str, str]]:
    """(quantity, value) rows for the ``barhinge fold`` table from ``<name>_summary.json``
    (empty if the file is absent)."""
    import numpy as np

    s = results_summary(out_dir, name)
    rows: list[tuple[str, str]] = []

    def add(label: str, key: str, fmt: str = "{:.4g}") -> None:
        v = s.get(key)
        if v is not None:
            rows.append((label, fmt.format(v)))

    act = s.get("actuator_fold_deg") or []
    if len(act) > 4:
        a = np.abs(act)
        rows.append(
            (
                f"final |actuator fold| (deg), {len(act)} actuators",
                f"{a.min():.2f} .. {a.max():.2f}",
            )
        )
    elif act:
        rows.append(("final actuator fold (deg)", ", ".join(f"{v:.2f}" for v in act)))
    add("max |fold angle| (deg)", "max_abs_fold_deg", "{:.2f}")
    add("Gaussian curvature K (global form)", "K_global")
    add("mean curvature H (global form)", "H_global")
    add("max |angle defect| (deg)", "max_abs_angle_defect_deg", "{:.3g}")
    add("max |bar strain|", "max_abs_bar_strain", "{:.3g}")
    if s.get("lowest_eigenvalues"):
        rows.append(
            ("lowest tangent eigenvalue (actuators released)", f"{s['lowest_eigenvalues'][0]:.4g}")
        )
    add("soft modes (of those computed)", "n_soft_modes", "{}")
    add("effective stiffness (scene loads)", "effective_stiffness")
    return rows
