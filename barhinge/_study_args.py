"""The command line of a study script (``studies/``): the options it takes, checked before
anything runs.

The study scripts read their few options from ``sys.argv`` at module level (their figures are
module-level results). Without a check, a mistyped option or ``--help`` would start the
study's full run (hours for some). :func:`check_study_argv` answers ``--help`` with the
script's docstring and refuses anything else it does not know, in one line.
"""

from __future__ import annotations

import sys
from collections.abc import Sequence

__all__ = ["check_study_argv"]


def check_study_argv(
    doc: str | None,
    flags: Sequence[str] = (),
    valued: Sequence[str] = (),
    argv: Sequence[str] | None = None,
) -> None:
    """Check a study script's arguments before it runs.

    Parameters
    ----------
    doc : str or None
        The script's docstring, printed for ``-h`` / ``--help``.
    flags : sequence of str
        Options without a value (``"--quick"``).
    valued : sequence of str
        Options written ``--name=VALUE`` (given as ``"--name"``).
    argv : sequence of str, optional
        The arguments (default ``sys.argv[1:]``).

    Raises
    ------
    SystemExit
        Code 0 after printing the help; code 2 with a one-line message naming an unknown
        option, a value given to a flag or a valued option without its value.
    """
    args = list(sys.argv[1:] if argv is None else argv)
    if "-h" in args or "--help" in args:
        print(doc or "(no description)")
        raise SystemExit(0)
    known = sorted([*flags, *(f"{v}=VALUE" for v in valued)])
    for a in args:
        name, eq, value = a.partition("=")
        if (name in valued and eq and value) or a in flags:
            continue
        if name in valued:
            _refuse(f"option {name} needs a value ({name}=VALUE)")
        if name in flags:
            _refuse(f"option {name} takes no value (got {a!r})")
        _refuse(f"unknown argument {a!r}; expected any of {', '.join(known) or 'none'}")


def _refuse(message: str) -> None:
    print(f"error: {message}", file=sys.stderr)
    raise SystemExit(2)
