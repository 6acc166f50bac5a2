"""The standard pictures of a fold path (PNG of the final state, charts, GIF), drawn by
:mod:`barhinge.plot`; rendering libraries load on first use."""

from __future__ import annotations

from pathlib import Path
from typing import Any

__all__ = ["write_pictures"]


def write_pictures(
    fold_path: Any,
    model: Any | None,
    out_dir: str | Path,
    *,
    pattern: Any | None = None,
    name: str = "result",
    gif: bool = True,
    extra_arrays: tuple[str, ...] = ("energy_density",),
) -> dict[str, Path]:
    """Write the standard pictures of a fold path into ``out_dir``.

    ``<name>.png`` (final state, creases coloured by fold angle), ``<name>_<array>.png`` for
    each of ``extra_arrays`` (bar-and-hinge paths only), ``<name>_charts.png`` (actuator
    angles, energy split, actuator moments) and ``<name>.gif`` (the fold path).

    Returns a dict from a picture kind to its path.
    """
    from barhinge.plot import charts, render

    cp = pattern if pattern is not None else getattr(model, "pattern", None)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    kw: dict[str, Any] = {"model": model, "pattern": cp if model is None else None}
    fa = fold_path.fold_angles_deg[-1] if model is None else None
    done: dict[str, Path] = {}
    done["png"] = render.render_state(
        fold_path.X[-1], out / f"{name}.png", fold_angles_deg=fa, **kw
    )
    if model is not None:
        for arr in extra_arrays:
            done[arr] = render.render_state(
                fold_path.X[-1], out / f"{name}_{arr}.png", scalars=arr, **kw
            )
    done["charts"] = out / f"{name}_charts.png"
    charts.summary_figure(fold_path, done["charts"])
    if gif and fold_path.n_states > 1:
        done["gif"] = render.animate(fold_path, out / f"{name}.gif", max_frames=30, **kw)
    return done
