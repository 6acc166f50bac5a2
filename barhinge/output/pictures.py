"""The standard pictures of a fold path (PNG of the final state, charts, GIF), drawn by
:mod:`barhinge.plot`; rendering libraries load on first use."""

from __future__ import annotations

from pathlib import Path
from typing import Any

__all__ = ["load_saved_path", "pattern_beside", "rerender", "write_pictures"]


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
    marks: dict[str, Any] = {"fixed": fixed, "loads": loads}
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


def pattern_beside(result: Path, pattern: Path | None):
    """The crease pattern of a saved path: ``--pattern``, else a FOLD file beside it."""
    from barhinge.errors import ConfigError

    if pattern is not None:
        from barhinge.pattern.io import read

        return read(pattern)
    stem = result.name.removesuffix(".npz")
    for cand in (result.with_name(f"{stem}_pattern.fold"), result.with_name(f"{stem}.fold")):
        if cand.is_file():
            from barhinge.pattern.fold import read_fold

            return read_fold(cand, validate=False)
    raise ConfigError(
        f"no crease pattern for {result.name}: expected {stem}_pattern.fold or {stem}.fold "
        "beside it, or give --pattern FILE"
    )


def load_saved_path(result: Path):
    """``FoldPath.load(result)``; a file that is not a saved fold path (empty, truncated,
    another .npz or no .npz at all) becomes one ConfigError naming it."""
    import pickle
    import zipfile

    from barhinge.errors import ConfigError
    from barhinge.results import FoldPath

    try:
        return FoldPath.load(result)
    except (
        EOFError,  # empty file
        zipfile.BadZipFile,  # truncated .npz
        pickle.UnpicklingError,
        KeyError,  # another .npz: no __json__ or a missing array
        ValueError,  # not .npy/.npz, bad JSON, arrays of the wrong shape
        TypeError,  # a .npy (no archive), unknown fields
        AttributeError,
        IndexError,
    ) as exc:
        why = (
            f"{type(exc).__name__}: {' '.join(str(exc).split())}"
            if str(exc)
            else type(exc).__name__
        )
        raise ConfigError(
            f"{result} is not a fold path saved by barhinge fold (.npz with __json__): {why}"
        ) from None


def rerender(
    result: Path,
    *,
    out: Path | None = None,
    pattern: Path | None = None,
    scalars: str = "fold_angle_deg",
    step: int = -1,
    gif: bool = True,
    backend: str = "auto",
) -> dict[str, Path]:
    """Re-render the pictures of a saved fold path (``barhinge render``): the PNG of one
    state coloured by ``scalars``, the charts and (``gif``) the animation, each written
    atomically into ``out`` (default: beside ``result``) and added to its manifest when
    ``out`` is a result folder. Returns a dict from a picture kind to its path.

    Raises
    ------
    ConfigError
        ``result`` is not a saved path, the pattern does not match it, ``step`` is out of
        range or ``out`` is a file.
    """
    from barhinge.errors import ConfigError
    from barhinge.output.folder import add_to_manifest, atomic_file
    from barhinge.plot import charts
    from barhinge.plot import render as rnd
    from barhinge.results import FoldPath

    if not result.is_file():
        what = "is a folder, not a file" if result.is_dir() else "does not exist"
        raise ConfigError(f"result file {result} {what}")
    fp = load_saved_path(result)
    cp = pattern_beside(result, pattern)
    if fp.X.shape[1] < cp.n_vertices:
        raise ConfigError(
            f"the path has {fp.X.shape[1]} nodes, but the pattern has {cp.n_vertices} vertices"
        )
    if fp.fold_angles_deg.shape[1] != cp.n_edges:
        raise ConfigError(
            f"the path has fold angles of {fp.fold_angles_deg.shape[1]} edges, but the pattern "
            f"{pattern or 'beside it'} has {cp.n_edges} edges: not the pattern of {result.name}"
        )
    n = fp.n_states
    if not -n <= step < n:
        raise ConfigError(f"--step {step} is outside the path's {n} states")
    folder = out if out is not None else result.parent
    if folder.exists() and not folder.is_dir():
        raise ConfigError(f"--out {folder} is a file, not a folder")
    folder.mkdir(parents=True, exist_ok=True)
    stem = result.name.removesuffix(".npz")
    s = step % n
    X = fp.X[:, : cp.n_vertices]
    written = {
        "png": folder / f"{stem}_{scalars}_{s:04d}.png",
        "charts": folder / f"{stem}_charts.png",
    }
    # each picture is written beside its name and renamed into place (never half a file)
    with atomic_file(written["png"]) as tmp:
        rnd.render_state(X[s], tmp, pattern=cp, scalars=scalars,
                         fold_angles_deg=fp.fold_angles_deg[s], title=f"state {s} of {n - 1}",
                         backend=backend)  # fmt: skip
    with atomic_file(written["charts"]) as tmp:
        charts.summary_figure(fp, tmp)
    if gif and n > 1:
        fp_v = FoldPath(X=X, fold_angles_deg=fp.fold_angles_deg, kind=fp.kind)
        written["gif"] = folder / f"{stem}.gif"
        with atomic_file(written["gif"]) as tmp:
            rnd.animate(fp_v, tmp, pattern=cp, scalars=scalars, backend=backend)
    add_to_manifest(folder, list(written.values()))  # a result folder lists them as its own
    return written
