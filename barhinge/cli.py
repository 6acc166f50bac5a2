"""Command-line interface: ``barhinge fold | info | dof | patterns | study | render | view |
cache | verify``.

The CLI owns the terminal: rich tables and progress bars. :func:`main` is its one error
boundary: usage mistakes, library errors and unreadable/unwritable files become one line on
stderr and exit code 2 (bad input) or 3 (did not converge); anything else is a bug (exit 70);
``--debug`` shows the traceback. Ctrl-C exits with 130, SIGTERM with 143 (``fold`` and
``study`` write what finished first).
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import signal
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Annotated, Any, Literal

import typer
from rich.console import Console

from barhinge.errors import BarhingeError, ConvergenceError

app = typer.Typer(
    name="barhinge",
    help="Bar-and-hinge structural analysis of origami tessellations.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)
console = Console()
err_console = Console(stderr=True)
_state = {"debug": False}


#: exit code of a run stopped by SIGTERM (128 + 15, the shell's convention)
EXIT_TERMINATED = 143


class _Terminated(KeyboardInterrupt):
    """SIGTERM, raised where the signal arrives so that it unwinds like Ctrl-C."""


@contextlib.contextmanager
def _sigterm_as_interrupt() -> Iterator[None]:
    """Within the block SIGTERM raises :class:`_Terminated` (a KeyboardInterrupt), so a
    ``kill PID`` writes partial results as Ctrl-C does; the previous handler is restored."""

    def on_term(signum: int, frame: object) -> None:
        raise _Terminated

    try:
        old = signal.signal(signal.SIGTERM, on_term)
    except ValueError:  # not the main thread (an embedding application): leave it alone
        yield
        return
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, old)


def _terminated(exc: BaseException) -> bool:
    """Whether ``exc`` (or what it was raised from) is a SIGTERM."""
    link: BaseException | None = exc
    while link is not None:
        if isinstance(link, _Terminated):
            return True
        link = link.__cause__ or link.__context__
    return False


@app.callback()
def _root(
    debug: Annotated[bool, typer.Option("--debug", help="Show tracebacks on errors.")] = False,
) -> None:
    _state["debug"] = debug


def print_json(data: object) -> None:
    """Print machine-readable output (for ``--json``)."""
    from barhinge._json import default

    sys.stdout.write(json.dumps(data, indent=2, default=default) + "\n")


# --- commands: info (foundation) ---


@app.command()
def info(
    file: Annotated[Path, typer.Argument(help="Crease pattern (.fold or .svg).")],
    as_json: Annotated[bool, typer.Option("--json", help="Machine-readable output.")] = False,
    developable: Annotated[
        bool,
        typer.Option(
            "--developable/--non-developable",
            help="Require sector angles to sum to 360 deg at interior vertices.",
        ),
    ] = True,
    merge_tol: Annotated[
        float | None,
        typer.Option(help="Merge vertices closer than this length before checking."),
    ] = None,
) -> None:
    """Counts, validation findings and bounding box of a crease pattern file.

    Exit code 2 when the pattern has validation errors (they are listed).
    """
    from rich.markup import escape
    from rich.table import Table

    from barhinge.pattern.info import pattern_info
    from barhinge.pattern.io import read
    from barhinge.pattern.validate import findings

    cp = read(file, validate=False)
    if not developable:
        cp = cp.replaced(developable=False, validate=False)
    if merge_tol is not None:
        cp = cp.replaced(merge_tol=merge_tol, validate=False)
    found = findings(cp)
    data = {"file": str(file), **pattern_info(cp, found)}
    if as_json:
        print_json(data)
    else:
        t = Table(title=f"{file.name}", show_header=False)
        t.add_row("vertices", f"{data['n_vertices']} ({data['n_interior_vertices']} interior, "
                  f"{data['n_boundary_vertices']} on the boundary)")  # fmt: skip
        asg = " ".join(f"{a}={c}" for a, c in data["edges_by_assignment"].items() if c)
        t.add_row("edges", f"{data['n_edges']} ({asg})")
        t.add_row("faces", str(data["n_faces"]))
        t.add_row("holes", str(data["n_holes"]))
        hist = " ".join(f"{d}:{c}" for d, c in data["degree_histogram"].items())
        t.add_row("vertex degrees", hist)
        lo, hi = data["bounding_box"]["min"], data["bounding_box"]["max"]
        fmt = lambda p: "(" + ", ".join(f"{x:.6g}" for x in p) + ")"  # noqa: E731
        t.add_row("bounding box", f"{fmt(lo)} .. {fmt(hi)}")
        t.add_row(
            "state",
            ("flat" if data["flat"] else "folded (3-D)") + f", {data['dimension']}-D coordinates",
        )
        console.print(t)
        style = {"error": "bold red", "warning": "yellow", "info": "cyan"}
        for f in found:
            console.print(f"[{style[f.severity]}]{f.severity}[/] {f.code}: {escape(f.message)}",
                          highlight=False, soft_wrap=True)  # fmt: skip
        if not found:
            console.print("[green]valid[/]: no findings")
    if data["n_errors"]:
        raise typer.Exit(2)


# --- commands: patterns (pattern library) ---


@app.command("patterns")
def patterns_cmd(
    name: Annotated[
        str | None, typer.Argument(help="Family to generate; omit to list the families.")
    ] = None,
    param: Annotated[
        list[str] | None,
        typer.Option(
            "--param",
            "-p",
            help="Generator parameter NAME=VALUE (repeatable; lists as 1,2,3 or JSON).",
        ),
    ] = None,
    out: Annotated[
        Path | None, typer.Option("--out", "-o", help="Write the pattern to this FOLD file.")
    ] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Machine-readable output.")] = False,
) -> None:
    """List the parametric pattern families, or generate one (``--out FILE.fold``)."""
    from rich.table import Table

    from barhinge.families.spec import catalogue, family_kwargs, generate
    from barhinge.pattern.info import generated_info

    if name is None:
        data = catalogue()
        if as_json:
            print_json(data)
            return
        t = Table(title="pattern families (barhinge patterns NAME --param k=v --out F.fold)")
        t.add_column("family", style="bold")
        t.add_column("parameters (defaults)")
        t.add_column("fold=")
        t.add_column("description")
        for fam, d in data.items():
            ps = ", ".join(f"{k}={v}" for k, v in d["parameters"].items())
            t.add_row(fam, ps, "exact" if d["exact_fold"] else "", d["summary"])
        console.print(t)
        return
    cp = generate(name, family_kwargs(name, param or []))
    summary = {**generated_info(name, cp), "out": str(out) if out else None}
    if out is not None:
        from barhinge.pattern.fold import write_fold

        write_fold(cp, out)
    if as_json:
        print_json(summary)
        return
    asg = " ".join(f"{a}={c}" for a, c in summary["edges_by_assignment"].items())
    console.print(
        f"{name}: {cp.n_vertices} vertices, {cp.n_edges} edges ({asg}), {cp.n_faces} faces"
        + (f" -> {out}" if out else "  (use --out FILE.fold to write it)"),
        highlight=False,
    )


# --- commands: dof (kinematics) ---


#: picture formats of ``barhinge dof --png`` (matplotlib picks the format from the suffix)
_PICTURE_SUFFIXES = (".png", ".svg", ".pdf")


@app.command()
def dof(
    pattern: Annotated[
        str, typer.Argument(help="Pattern file (.fold/.svg) or family spec, e.g. miura:nx=4,ny=4")
    ],
    as_json: Annotated[bool, typer.Option("--json", help="Machine-readable output.")] = False,
    png: Annotated[
        Path | None,
        typer.Option("--png", help="Write the local-DOF picture (.png, .svg or .pdf)."),
    ] = None,
    triangulated: Annotated[
        bool, typer.Option("--triangulated", help="Let panels fold along diagonals.")
    ] = False,
    prefer: Annotated[
        str | None,
        typer.Option(help="Actuator preference: boundary, interior or spread."),
    ] = None,
) -> None:
    """Rigid-origami DOF: global (count and rank), redundancy, local DOF and actuators."""
    from barhinge.kinematics.dof import dof as compute_dof

    if png is not None and png.suffix.lower() not in _PICTURE_SUFFIXES:
        from barhinge.errors import ConfigError

        raise ConfigError(
            f"--png {png}: expected a picture file ending in "
            f"{', '.join(_PICTURE_SUFFIXES[:-1])} or {_PICTURE_SUFFIXES[-1]}"
        )
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    from barhinge.families.spec import read_or_generate

    cp = read_or_generate(pattern)
    bar = Progress(
        TextColumn("[bold]dof[/] {task.description}"),
        BarColumn(),
        TimeElapsedColumn(),
        console=err_console,
        disable=as_json,
        transient=True,
    )
    with bar:
        task = bar.add_task("", total=None)

        def show(stage: str, done: int, total: int) -> None:
            bar.update(task, description=stage, completed=done, total=total)

        rep = compute_dof(cp, triangulated=triangulated, prefer=prefer, progress=show)
    if png is not None:
        from barhinge.plot.dof import draw_dof

        draw_dof(cp, rep, png)
    if as_json:
        data = {"pattern": pattern, **rep.summary()}
        if png is not None:
            data["png"] = str(png)
        print_json(data)
        return
    from rich.table import Table

    t = Table(title=f"rigid DOF of {pattern}" + (" (triangulated)" if triangulated else ""))
    t.add_column("")
    t.add_column("this state")
    reps = [rep] + ([rep.folded] if rep.folded is not None else [])
    if rep.folded is not None:
        t.add_column("folded state nearby")
    t.add_row("flat", *[str(r.flat) for r in reps])
    t.add_row("variables / equations", *[f"{r.n_variables} / {r.n_equations}" for r in reps])
    t.add_row("counted DOF (Tachi 2010)", *[str(r.counted_dof) for r in reps])
    t.add_row("DOF from rank", *[f"{r.global_dof} (rank {r.rank}, {r.method})" for r in reps])
    t.add_row("redundant constraints", *[str(r.redundant) for r in reps])

    def doubt(r) -> str:
        if r.certain:
            return f"{r.gap_ratio:.1e} certain"
        return f"{r.gap_ratio:.1e} UNCERTAIN: DOF between {r.dof_range[0]} and {r.dof_range[1]}"

    sig = [f"{r.sigma_below:.1e} / {r.tolerance:.1e} / {r.sigma_gap:.1e}" for r in reps]
    t.add_row("σ counted zero / cut / σ non-zero", *sig)
    t.add_row("gap ratio", *[doubt(r) for r in reps])

    def hist(a) -> str:
        import numpy as np

        a = a[a >= 0]
        v, c = np.unique(a, return_counts=True)
        return ", ".join(f"{int(x)}: {int(n)}" for x, n in zip(v, c, strict=True)) or "-"

    t.add_row("local DOF (value: vertices)", *[hist(r.local) for r in reps])
    t.add_row("region DOF (value: vertices)", *[hist(r.region) for r in reps])
    acts = [" ".join(map(str, r.actuators.tolist())) or "-" for r in reps]
    t.add_row("suggested actuators (edges)", *acts)
    console.print(t)
    if rep.note:
        console.print(f"note: {rep.note}", highlight=False)
    if png is not None:
        console.print(f"wrote {png}")


# --- commands: fold (solver) ---


@app.command("fold")
def fold_cmd(
    scene_file: Annotated[
        Path | None, typer.Argument(help="Scene TOML; omitted: the built-in Miura scene.")
    ] = None,
    out: Annotated[Path, typer.Option("--out", help="Output folder.")] = Path("fold-out"),
    as_json: Annotated[bool, typer.Option("--json", help="Print the summary as JSON.")] = False,
    form_only: Annotated[
        bool,
        typer.Option(
            "--form-only",
            help="Only the folded form is wanted: use rigid kinematics when the scene has "
            "actuators only (exact, fastest), else the bar-and-hinge solver.",
        ),
    ] = False,
    overwrite: Annotated[
        bool,
        typer.Option(
            "--overwrite",
            help="Replace --out even when it is a non-empty folder that is not a barhinge "
            "result folder (a previous result folder is always replaced whole).",
        ),
    ] = False,
    pictures: Annotated[
        str | None,
        typer.Option(
            "--pictures",
            help="none: no pictures (default: viewer.html shows the run); png: the final state "
            "and the charts; all: and the energy-density picture and the GIF of the path.",
        ),
    ] = None,
    viewer: Annotated[
        bool,
        typer.Option("--viewer/--no-viewer", help="Write the interactive viewer.html."),
    ] = True,
    accuracy: Annotated[
        str | None,
        typer.Option(
            "--accuracy",
            help="Run the lightest model (rigid form, N4B5, N5B8, panels cut into m x m "
            "cells) whose estimated error meets this accuracy, e.g. 2%; the choice and its "
            "estimated error go to the summary (exit code 3 when no model meets it).",
        ),
    ] = None,
    accuracy_for: Annotated[
        str,
        typer.Option(
            "--accuracy-for",
            help="Outputs the accuracy is for, comma-separated: stiffness, displacement, "
            "form (default: form for a scene driven by actuators alone, else stiffness).",
        ),
    ] = "",
    accuracy_max_dofs: Annotated[
        int | None,
        typer.Option(
            "--accuracy-max-dofs",
            min=1,
            help="With --accuracy: the most DOFs a refined level may have (default 1,500,000; "
            "levels m = 2, 4, 8, ... are tried while they fit, and a larger budget lets "
            "slowly converging scenes meet tighter accuracies, at more time and memory).",
        ),
    ] = None,
) -> None:
    """Fold a scene: solve it step by step, write the fold path, one summary, one step
    table and the interactive viewer (docs/outputs.md).

    The output folder is replaced atomically at the end; Ctrl-C writes the converged steps
    and exits with code 130.
    """
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    from barhinge.output.folder import check_output_folder
    from barhinge.output.run import picture_level, write_run
    from barhinge.output.summary import iterate_text
    from barhinge.results import Interrupted
    from barhinge.scene import default_scene, load_scene
    from barhinge.solver.form import form_only_model, rigid_form
    from barhinge.solver.newton import IterationStatus, solve

    level = picture_level(pictures)  # a bad value stops before the solve
    scene = default_scene() if scene_file is None else load_scene(scene_file)
    check_output_folder(out, overwrite=overwrite)  # before the solve, not after
    opts: dict[str, Any] = {"overwrite": overwrite, "pictures": level, "viewer": viewer}
    choice = None
    wanted, amplitude = scene.imperfection, None
    if wanted is not None:  # the amplitude of the scene as given, whatever model is chosen
        from barhinge.analysis.imperfection import amplitude_length

        amplitude = amplitude_length(scene)
        scene = scene.with_(imperfection=None)
    if accuracy is not None:
        from barhinge.analysis.accuracy import scene_for_accuracy

        outs = tuple(o.strip() for o in accuracy_for.split(",") if o.strip())

        def tried(name: str, n_dof: int, seconds: float) -> None:
            err_console.print(f"  estimated with {name}: {n_dof:,} DOFs, {seconds:.1f} s",
                              highlight=False, markup=False)  # fmt: skip

        scene, choice = scene_for_accuracy(
            scene, accuracy, outs or None, on_level=tried, max_dofs=accuracy_max_dofs
        )
        c = choice.chosen
        err_console.print(f"model for {100 * choice.accuracy:g} % in {', '.join(choice.outputs)}: "
                          f"{c.name} (estimated error {100 * c.error:.2g} %)",
                          highlight=False, markup=False)  # fmt: skip
        form_only = form_only or c.name == "rigid"
    if wanted is not None:
        from barhinge.analysis.imperfection import seed_imperfection
        from barhinge.output.summary import imperfection_text

        scene = seed_imperfection(scene.with_(imperfection=wanted), amplitude=amplitude)
        err_console.print("imperfection: " + imperfection_text(scene.model.meta["imperfection"]),
                          highlight=False, markup=False)  # fmt: skip
    if form_only and form_only_model(scene)[0] == "rigid":
        try:
            rigid = rigid_form(scene)
        except BarhingeError as exc:
            err_console.print(f"rigid kinematics cannot fold it ({exc}); using the bar-and-hinge "
                              "model", highlight=False, markup=False, soft_wrap=True)  # fmt: skip
        else:
            if choice is not None:
                rigid.meta["model_choice"] = choice.summary()
            run = write_run(rigid, scene, out, command="fold --form-only", fields=False,
                            **opts)  # fmt: skip
            _print_run(run, f"fold --form-only: {scene.name} (rigid kinematics)", as_json)
            return
    bar = Progress(
        TextColumn(f"[bold]{scene.name}[/]"),
        BarColumn(),
        TextColumn("step {task.completed}/{task.total}"),
        TimeElapsedColumn(),
        TextColumn("{task.fields[detail]}", markup=False),
        console=err_console,
        disable=as_json,
    )
    term = contextlib.ExitStack()  # SIGTERM (kill PID) stops the run as Ctrl-C does
    term.enter_context(_sigterm_as_interrupt())
    try:
        with bar:
            task = bar.add_task("fold", total=scene.steps, detail="")

            def iterate(status: IterationStatus) -> None:
                text = f"solving step {status.step}: {iterate_text(status)}"
                bar.update(task, detail=text)

            try:
                path = solve(
                    scene,
                    progress=lambda d, total, v: bar.update(task, completed=d, detail=""),
                    on_iteration=iterate,
                )
            except (ConvergenceError, Interrupted) as exc:
                part = exc.last_state
                if part is not None:
                    if _terminated(exc):  # the solver saw a KeyboardInterrupt: say which
                        part = dataclasses.replace(
                            part, message=part.message.replace("(Ctrl-C)", "(SIGTERM)")
                        )
                    write_run(part, scene, out, **opts)
                    _print_events(part.meta.get("events", []), err_console)
                    err_console.print(f"partial results ({part.n_states} states) in {out}",
                                      highlight=False, markup=False)  # fmt: skip
                raise
        if choice is not None:
            path.meta["model_choice"] = choice.summary()
        run = write_run(path, scene, out, **opts)
    except Interrupted as exc:
        stop = _terminated(exc)
        part = exc.last_state
        msg = part.message if part is not None else "interrupted (Ctrl-C) before state 0"
        if stop:
            msg = msg.replace("(Ctrl-C)", "(SIGTERM)")
        err_console.print(msg, highlight=False, markup=False)
        sys.exit(EXIT_TERMINATED if stop else 130)
    except KeyboardInterrupt as exc:
        what = "terminated (SIGTERM)" if _terminated(exc) else "interrupted"
        err_console.print(f"{what}; {out} unchanged", highlight=False, markup=False)
        sys.exit(EXIT_TERMINATED if _terminated(exc) else 130)
    finally:
        term.close()
    _print_run(run, f"fold: {scene.name}", as_json)


def _print_run(run, title: str, as_json: bool) -> None:
    """The summary of a written run: JSON (``--json``) or a table, then its events."""
    if as_json:
        print_json({**run.summary, "files": [str(f) for f in run.files]})
        return
    from rich.table import Table

    t = Table(title=title)
    t.add_column("quantity")
    t.add_column("value", justify="right")
    for k, v in run.rows:
        t.add_row(k, v)
    t.add_row("output", str(run.out))
    console.print(t)
    _print_events(run.summary["events"], console)


def _print_events(events, to) -> None:
    """Stability and work-balance events, one line each."""
    for ev in events:
        to.print(f"event: {ev}", highlight=False, markup=False)


# --- commands: render (results) ---


@app.command()
def render(
    result: Annotated[Path, typer.Argument(help="Saved fold path (.npz from barhinge fold).")],
    out: Annotated[
        Path | None, typer.Option("--out", help="Output folder (default: beside RESULT).")
    ] = None,
    pattern: Annotated[
        Path | None, typer.Option(help="Crease pattern file (default: the .fold beside RESULT).")
    ] = None,
    scalars: Annotated[
        str, typer.Option(help="Array to colour by: fold_angle_deg, angle_defect, ...")
    ] = "fold_angle_deg",
    step: Annotated[int, typer.Option(help="State to render (default: the last).")] = -1,
    gif: Annotated[bool, typer.Option("--gif/--no-gif", help="Also animate the path.")] = True,
    backend: Annotated[str, typer.Option(help="auto, pyvista or matplotlib.")] = "auto",
    as_json: Annotated[bool, typer.Option("--json", help="Machine-readable output.")] = False,
) -> None:
    """Re-render the pictures of a saved fold path (PNG of one state, charts, GIF)."""
    from barhinge.output.pictures import rerender

    written = rerender(result, out=out, pattern=pattern, scalars=scalars, step=step, gif=gif,
                       backend=backend)  # fmt: skip
    if as_json:
        print_json({k: str(v) for k, v in written.items()})
    else:
        for k, v in written.items():
            console.print(f"[green]{k:>6}[/] {v}", highlight=False)


# --- commands: view (interactive HTML) ---


@app.command()
def view(
    path: Annotated[
        Path, typer.Argument(help="Result folder, fold_path.npz or FOLD file with frames.")
    ],
    output: Annotated[
        Path | None,
        typer.Option("--output", "-o", help="HTML file (default: viewer.html beside PATH)."),
    ] = None,
) -> None:
    """Write the fold path as one interactive HTML file that works offline."""
    from barhinge.output.folder import MANIFEST, add_to_manifest
    from barhinge.view import write_viewer

    default = path / "viewer.html" if path.is_dir() else path.with_name(f"{path.stem}.html")
    out = write_viewer(path, output if output is not None else default)
    if output is None and path.is_dir() and (path / MANIFEST).is_file():
        add_to_manifest(path, [out])  # a result folder lists the viewer as its own
    console.print(f"[green]viewer[/] {out}", highlight=False)


# --- commands: cache (calibration answers kept between runs) ---


@app.command()
def cache(
    clear: Annotated[bool, typer.Option("--clear", help="Remove every kept answer.")] = False,
    as_json: Annotated[bool, typer.Option("--json", help="Machine-readable output.")] = False,
) -> None:
    """Where the calibration's answers are kept between runs, and how much they hold.

    BARHINGE_CACHE_DIR moves the folder; BARHINGE_CACHE=off turns the cache off.
    """
    from barhinge._disk_cache import cache_info, clear_cache

    found = clear_cache() if clear else cache_info()
    data = {
        "folder": None if found.folder is None else str(found.folder),
        "entries": found.entries,
        "bytes": found.bytes,
        "cleared": clear,
    }
    if as_json:
        print_json(data)
    elif found.folder is None:
        console.print("calibration cache: off (BARHINGE_CACHE=off)", highlight=False)
    else:
        what = "removed" if clear else "holds"
        console.print(
            f"calibration cache {found.folder}: {what} {found.entries} entries "
            f"({found.bytes / 1024:.1f} KiB)",
            highlight=False,
            soft_wrap=True,
        )


# --- commands: study (sweeps) ---


@app.command()
def study(
    study_file: Annotated[Path, typer.Argument(help="Study TOML (function, grid, points).")],
    scheduler: Annotated[
        str | None, typer.Option("--scheduler", help="Dask scheduler address, tcp://HOST:PORT.")
    ] = None,
    workers: Annotated[
        int | None,
        typer.Option("--workers", min=1, help="Worker processes of the local cluster."),
    ] = None,
    serial: Annotated[bool, typer.Option("--serial", help="Run in this process.")] = False,
    out: Annotated[Path | None, typer.Option("--out", help="Output folder.")] = None,
    batch_size: Annotated[
        int | None, typer.Option("--batch-size", min=1, help="Points per Dask task.")
    ] = None,
    retry_failed: Annotated[
        bool, typer.Option("--retry-failed", help="Rerun points that failed before.")
    ] = False,
    as_json: Annotated[bool, typer.Option("--json", help="Print the counts as JSON.")] = False,
) -> None:
    """Run (or resume) a parameter study; finished points are skipped on a rerun."""
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    from barhinge.sweep import SweepReport, load_study, run_study

    spec = load_study(study_file)
    mode: Literal["serial", "local", "dask"] = (
        "serial" if serial else ("dask" if scheduler else "local")
    )
    progress = Progress(
        TextColumn("[bold]{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TextColumn("ok {task.fields[done]}  failed {task.fields[failed]}"),
        TimeElapsedColumn(),
        TextColumn("ETA"),
        TimeRemainingColumn(),
        console=err_console,
        disable=as_json,
    )
    task = progress.add_task(spec.name, total=None, done=0, failed=0)

    def on_start(rep: SweepReport) -> None:
        progress.update(task, total=rep.pending, completed=0)

    def on_record(rec: dict, rep: SweepReport) -> None:
        progress.update(task, completed=rep.finished, done=rep.done, failed=rep.failed)

    try:
        with _sigterm_as_interrupt(), progress:
            rep = run_study(
                spec,
                out=out,
                mode=mode,
                scheduler=scheduler,
                workers=workers,
                batch_size=batch_size,
                retry_failed=retry_failed,
                on_start=on_start,
                on_record=on_record,
            )
    except KeyboardInterrupt as exc:
        what = "terminated (SIGTERM)" if _terminated(exc) else "interrupted"
        err_console.print(f"{what}; finished points are saved, rerun to resume")
        sys.exit(EXIT_TERMINATED if _terminated(exc) else 130)
    counts = {
        "out": str(rep.out),
        "total": rep.total,
        "skipped": rep.skipped,
        "done": rep.done,
        "failed": rep.failed,
        "elapsed_s": round(rep.elapsed_s, 3),
    }
    if as_json:
        print_json(counts)
        return
    failed_all = sum(r.get("status") == "failed" for r in rep.records.values())
    console.print(
        f"{spec.name}: {rep.total} points, {rep.skipped} already done, {rep.done} ok and "
        f"{rep.failed} failed now ({failed_all} failed in all), {rep.elapsed_s:.1f} s -> "
        f"{rep.out / 'summary.csv'}",
        highlight=False,
    )


# --- commands: verify ---


@app.command("verify")
def verify_cmd(
    as_json: Annotated[bool, typer.Option("--json", help="Machine-readable output.")] = False,
    case: Annotated[
        list[str] | None, typer.Option("--case", help="Run only this case (repeatable).")
    ] = None,
    quick: Annotated[bool, typer.Option("--quick", help="Only the fastest cases.")] = False,
    list_cases: Annotated[bool, typer.Option("--list", help="List the cases and exit.")] = False,
) -> None:
    """Run the reference cases (closed forms from the literature); exit code 1 on a failure."""
    from rich.table import Table

    from barhinge import verify

    if list_cases:  # the cases --case and --quick select, as a run would
        data: dict[str, dict[str, Any]] = {
            c.name: {
                "citation": c.citation,
                "description": c.description,
                "quantities": [q.name for q in c.quantities],
                "quick": c.quick,
            }
            for c in verify.select(names=case or None, quick=quick)
        }
        if as_json:
            print_json(data)
        else:
            for name, d in data.items():
                console.print(f"[bold]{name}[/] ({', '.join(d['quantities'])}): {d['citation']}",
                              highlight=False, soft_wrap=True)  # fmt: skip
        return
    with err_console.status("verifying", spinner="dots") as status:

        def on_case(c: verify.Case, rows: list) -> None:
            if not as_json:
                status.update(f"verifying: {c.name} done")

        checks = verify.run(names=case or None, quick=quick, on_case=on_case)
    info = verify.summary(checks)
    if as_json:
        print_json({**info, "checks": [c.as_dict() for c in checks]})
    else:
        t = Table(title="barhinge verify: reference cases")
        for col, just in (
            ("case", "left"),
            ("quantity", "left"),
            ("", "center"),
            ("reference", "right"),
            ("computed", "right"),
            ("rel. error", "right"),
            ("tolerance", "right"),
            ("time (s)", "right"),
        ):
            num = col not in ("case", "quantity")
            width = 4 if not col else 7 if num else (12 if col == "case" else 10)
            t.add_column(col, justify=just, no_wrap=num, min_width=width)  # type: ignore[arg-type]
        last = None
        for c in checks:
            t.add_row(
                c.case if c.case != last else "",
                c.quantity,
                "[green]pass[/]" if c.passed else "[bold red]FAIL[/]",
                f"{c.reference:.7g}",
                f"{c.computed:.7g}",
                f"{c.error:.1e}",
                f"{c.tolerance:.0e}",
                f"{c.time_s:.2f}" if c.case != last else "",
            )
            last = c.case
        console.print(t)
        seen: dict[str, str] = {}
        for c in checks:
            seen.setdefault(c.case, c.citation)
        for name, cite in seen.items():
            console.print(f"[dim]{name}:[/] {cite}", highlight=False, soft_wrap=True)
        for c in checks:
            if c.message:
                console.print(f"[red]{c.case}/{c.quantity}:[/] {c.message}", highlight=False)
        console.print(
            f"{info['n_passed']}/{info['n_checks']} checks passed in {info['n_cases']} cases "
            f"({info['time_s']:.1f} s)",
            highlight=False,
        )
    if not info["passed"]:
        raise SystemExit(1)


#: Exit codes of ``barhinge`` (README "Conventions"; docs/index.md "Errors").
EXIT_OK, EXIT_BAD_INPUT, EXIT_NOT_CONVERGED, EXIT_INTERNAL = 0, 2, 3, 70  # 70: EX_SOFTWARE

_REPORT = (
    "this is a bug in barhinge: please report it with the command line, its input files and "
    "the traceback that `barhinge --debug COMMAND ...` prints"
)


def _one_line(text: object) -> str:
    """``text`` on one line (line breaks become spaces)."""
    return " ".join(part.strip() for part in str(text).splitlines() if part.strip())


def _say(line: str) -> None:
    """One line on stderr, printed as is (no rich markup: ``[model]`` stays ``[model]``)."""
    sys.stderr.write(line + "\n")
    sys.stderr.flush()


def _is_usage_error(exc: BaseException) -> bool:
    """A command-line usage error, whatever its class: click's own, or the copies that
    typer >= 0.29 bundles (``typer._click``); both carry ``exit_code`` and
    ``format_message()``."""
    return isinstance(getattr(exc, "exit_code", None), int) and callable(
        getattr(exc, "format_message", None)
    )


def _option_values(param: object, argv: list[str]) -> list[str]:
    """The words ``argv`` gives option ``param`` (``--step abc`` or ``--step=abc``)."""
    names = [*getattr(param, "opts", []), *getattr(param, "secondary_opts", [])]
    if not names or getattr(param, "is_flag", False):
        return []
    found = []
    for i, word in enumerate(argv):
        if word == "--":
            break
        if word in names and i + 1 < len(argv):
            found.append(argv[i + 1])
        for n in names:
            if n.startswith("--") and word.startswith(n + "="):
                found.append(word[len(n) + 1 :])
    return found


def _usage_text(exc: BaseException, argv: list[str] | None = None) -> str:
    msg = _one_line(exc.format_message())  # type: ignore[attr-defined]
    if msg.startswith("Invalid value for") and argv:  # name the value given, not only the option
        values = [v for v in _option_values(getattr(exc, "param", None), argv) if v not in msg]
        if values:
            msg += f" (got {', '.join(repr(v) for v in dict.fromkeys(values))})"
    ctx = getattr(exc, "ctx", None)
    path = getattr(ctx, "command_path", None)
    return f"{msg} (see '{path} --help')" if path else msg


def _os_error_text(exc: OSError) -> str:
    """An OS error naming its file(s): "out/x: Not a directory"."""
    if exc.filename is None:
        return _one_line(exc)
    text = f"{exc.filename}: {exc.strerror or type(exc).__name__}"
    if exc.filename2 is not None:
        text += f" (and {exc.filename2})"
    return _one_line(text)


def main(argv: list[str] | None = None) -> None:
    """Entry point, the CLI's one error boundary (``argv``: the arguments; default
    ``sys.argv[1:]``).

    Exits 0 when done; 2 with one line ``error: ...`` on stderr for bad input (usage errors,
    ``BarhingeError``, unreadable or unwritable files); 3 when a solve did not converge
    (partial results are written first); 70 with one line ``internal error: ...`` for
    anything else, which is a bug. ``--debug`` re-raises, showing the traceback.
    """
    _state["debug"] = False  # set by the --debug callback; reset for in-process calls
    words = list(sys.argv[1:] if argv is None else argv)
    try:
        code = app(args=argv, prog_name="barhinge", standalone_mode=False)
    except SystemExit:  # typer.Exit / sys.exit inside a command: its code stands
        raise
    except KeyboardInterrupt as exc:
        _say("terminated (SIGTERM)" if _terminated(exc) else "interrupted")
        sys.exit(EXIT_TERMINATED if _terminated(exc) else 130)
    except BarhingeError as exc:
        if _state["debug"]:
            raise
        _say(f"error: {_one_line(exc)}")
        sys.exit(EXIT_NOT_CONVERGED if isinstance(exc, ConvergenceError) else EXIT_BAD_INPUT)
    except OSError as exc:  # missing, unreadable or unwritable files and folders
        if _state["debug"]:
            raise
        _say(f"error: {_os_error_text(exc)}")
        sys.exit(EXIT_BAD_INPUT)
    except Exception as exc:
        if type(exc).__name__ == "NoArgsIsHelpError":  # bare ``barhinge``: the help
            text = exc.format_message()  # type: ignore[attr-defined]
            if text.strip():  # (typer's rich help prints itself and leaves this empty)
                sys.stdout.write(text.rstrip("\n") + "\n")
            sys.exit(EXIT_BAD_INPUT)
        if _is_usage_error(exc):
            _say(f"error: {_usage_text(exc, words)}")
            sys.exit(EXIT_BAD_INPUT)
        if type(exc).__name__ == "Abort":  # click's or typer's (EOF at a prompt)
            _say("aborted")
            sys.exit(1)
        if _state["debug"]:
            raise
        what = f"{type(exc).__name__}: {_one_line(exc)}" if str(exc) else type(exc).__name__
        _say(f"internal error: {what}; {_REPORT}")
        sys.exit(EXIT_INTERNAL)
    if isinstance(code, int) and code != 0:
        sys.exit(code)
    if argv is None and next((w for w in words if not w.startswith("-")), "") in _FAST_EXIT:
        _exit_now()


#: commands whose process ends without the interpreter's teardown once they succeeded
_FAST_EXIT = frozenset({"fold", "view"})


def _exit_now() -> None:
    """End a finished CLI process at once (exit code 0): every file is written and closed,
    and the teardown of the loaded modules (scipy, MKL, HDF5: 0.1-0.2 s) would only add to
    the wall time of a small fold. Only for a process started as the CLI (``argv`` None),
    never for an in-process call."""
    import logging
    import os

    sys.stdout.flush()
    sys.stderr.flush()
    logging.shutdown()
    os._exit(0)


if __name__ == "__main__":
    main()
