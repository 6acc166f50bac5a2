"""The one parser of family specs: ``"miura:nx=4,ny=4,alpha=60"`` -> a crease pattern.

A spec is a family name, optionally followed by ``:`` and ``key=value`` pairs separated by
commas (``barhinge dof miura:nx=4,ny=4``); ``barhinge patterns NAME -p key=value`` gives the
same pairs one by one. A value is JSON (numbers, ``[1, 2]``, ``true``, ``null``), a comma
list of numbers (``-p`` only; in a spec use brackets) or else a plain string.
"""

from __future__ import annotations

import json
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from barhinge.errors import PatternError
from barhinge.pattern.crease import CreasePattern

__all__ = [
    "catalogue",
    "family_kwargs",
    "generate",
    "parse_spec",
    "parse_value",
    "pattern_from_spec",
    "read_or_generate",
]


def parse_value(text: str) -> Any:
    """A parameter value: JSON, a comma list of numbers, or the text itself."""
    text = text.strip()
    try:
        return json.loads(text)
    except ValueError:
        pass
    if "," in text:
        try:
            return [float(x) for x in text.split(",")]
        except ValueError:
            pass
    return text


def _split_top(text: str) -> list[str]:
    """``text`` split at the commas outside brackets."""
    parts, depth, cur = [], 0, ""
    for ch in text:
        depth += ch in "[{"
        depth -= ch in "]}"
        if ch == "," and depth == 0:
            parts.append(cur)
            cur = ""
        else:
            cur += ch
    return [p for p in [*parts, cur] if p.strip()]


def family_kwargs(name: str, items: Iterable[str]) -> dict[str, Any]:
    """Keyword arguments of family ``name`` from ``key=value`` words.

    Raises
    ------
    PatternError
        An unknown family, a word without ``=`` or an unknown parameter (named).
    """
    from barhinge.families import family_parameters

    known = family_parameters(name)
    out: dict[str, Any] = {}
    for item in items:
        key, sep, value = item.partition("=")
        key = key.strip()
        if not sep or not key:
            raise PatternError(f"parameter {item!r} of {name}: expected NAME=VALUE")
        if key not in known:
            raise PatternError(
                f"{name}: unknown parameter {key!r}; expected one of {', '.join(known)}"
            )
        out[key] = parse_value(value)
    return out


def parse_spec(spec: str) -> tuple[str, dict[str, Any]]:
    """(family, keyword arguments) of ``"name[:key=value,...]"``."""
    name, _, args = spec.partition(":")
    return name.strip(), family_kwargs(name.strip(), _split_top(args))


def pattern_from_spec(spec: str) -> CreasePattern:
    """The crease pattern of a family spec (``"miura:nx=4,ny=4"``).

    Raises
    ------
    PatternError
        An unknown family or parameter, or a value the generator refuses.
    """
    name, kwargs = parse_spec(spec)
    return generate(name, kwargs)


def generate(name: str, kwargs: dict[str, Any]) -> CreasePattern:
    """``FAMILIES[name](**kwargs)``; a value of the wrong type becomes a PatternError."""
    from barhinge.families import FAMILIES, family_parameters

    family_parameters(name)  # PatternError naming the families for an unknown one
    try:
        return FAMILIES[name](**kwargs)
    except TypeError as exc:  # e.g. a list given where a number is expected
        raise PatternError(f"{name}: bad parameter value ({exc})") from None


def read_or_generate(text: str) -> CreasePattern:
    """A pattern from a file path (``.fold``/``.svg``) or a family spec."""
    if Path(text).exists():
        from barhinge.pattern.io import read

        return read(text)
    from barhinge.families import FAMILIES

    name = text.partition(":")[0].strip()
    if name not in FAMILIES:
        raise PatternError(
            f"{text!r} is neither a file nor a pattern family; families: "
            f"{', '.join(sorted(FAMILIES))}"
        )
    return pattern_from_spec(text)


def catalogue() -> dict[str, dict[str, Any]]:
    """Every family: its parameters with their defaults (``"(required)"`` without one),
    whether ``fold=`` gives an exact folded state, and the first line of its docstring."""
    import inspect

    from barhinge.families import FAMILIES, FOLDABLE_FAMILIES, family_parameters, family_summary

    def shown(v: object) -> object:
        return "(required)" if v is inspect.Parameter.empty else v

    return {
        fam: {
            "parameters": {k: shown(v) for k, v in family_parameters(fam).items()},
            "exact_fold": fam in FOLDABLE_FAMILIES,
            "summary": family_summary(fam),
        }
        for fam in FAMILIES
    }
