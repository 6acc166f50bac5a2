"""Command-line interface: ``barhinge fold | info | dof | patterns | study | render | verify``.

The CLI owns the terminal: rich tables and progress bars. Library errors become one line on
stderr and exit code 2 (bad input) or 3 (did not converge); ``--debug`` shows the traceback.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Annotated

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


@app.callback()
def _root(
    debug: Annotated[bool, typer.Option("--debug", help="Show tracebacks on errors.")] = False,
) -> None:
    _state["debug"] = debug


def print_json(data: object) -> None:
    """Print machine-readable output (for ``--json``)."""
    sys.stdout.write(json.dumps(data, indent=2, default=_json_default) + "\n")


def _json_default(o: object) -> object:
    import numpy as np

    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, Path):
        return str(o)
    raise TypeError(f"not JSON serialisable: {type(o).__name__}")


# --- commands: info (foundation) ---

# --- commands: patterns (pattern library) ---

# --- commands: dof (kinematics) ---

# --- commands: fold (solver) ---

# --- commands: render (results) ---

# --- commands: study (sweeps) ---

# --- commands: verify ---


def main() -> None:
    """Entry point: run the app, turning barhinge errors into one line and an exit code."""
    try:
        app(standalone_mode=False)
    except SystemExit as exc:  # typer/click exits (help, usage)
        raise
    except BarhingeError as exc:
        if _state["debug"]:
            raise
        err_console.print(f"[bold red]error:[/] {exc}", highlight=False, soft_wrap=True)
        sys.exit(3 if isinstance(exc, ConvergenceError) else 2)
    except Exception as exc:  # click usage errors carry their own exit code
        import click

        if isinstance(exc, click.exceptions.ClickException):
            exc.show()
            sys.exit(exc.exit_code)
        if isinstance(exc, click.exceptions.Abort):
            sys.exit(1)
        raise


if __name__ == "__main__":
    main()
