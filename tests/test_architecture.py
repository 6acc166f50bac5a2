"""The import graph of barhinge: no cycles, every import points down the declared layers, and
``import barhinge`` stays cheap. docs/architecture.md describes the same layers.

How the graph is read (``ast``, nothing is imported): every ``import`` and ``from ... import``
statement in a module counts, wherever it stands -- at module level, inside a function, or
under ``if TYPE_CHECKING:`` -- because a lazy import still ties the two modules together.
``from barhinge.a import b`` is an edge to ``barhinge.a.b`` when that is a module, to
``barhinge.a`` otherwise. A package's ``__init__`` is the node of the package; importing a
module of a package is not counted as importing the package's ``__init__`` (Python runs it,
but it is a re-export list, and the import-time test below checks what it costs).
Dynamic imports (``importlib.import_module``) are not seen: the lazy re-export tables of
``barhinge/__init__.py`` and ``barhinge/solver/__init__.py`` use them on purpose.
"""

from __future__ import annotations

import ast
import fnmatch
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "barhinge"

#: The layers, bottom first. A module may import modules of its own layer or of a layer
#: below, never above. A module named exactly belongs to that layer; otherwise the first
#: layer with a matching wildcard (fnmatch on the dotted name) does. Keep in step with
#: docs/architecture.md.
LAYERS: list[tuple[str, list[str]]] = [
    (
        "ground",
        [
            "barhinge.errors",
            "barhinge._typing",
            "barhinge._check",
            "barhinge._version",
            "barhinge._json",
            "barhinge._protocols",
            "barhinge._deprecated",
            "barhinge._publish",
            "barhinge._study_args",
            "barhinge._disk_cache",
        ],
    ),
    ("linalg", ["barhinge.linalg", "barhinge.linalg.*"]),
    ("results", ["barhinge.results"]),
    ("pattern", ["barhinge.pattern", "barhinge.pattern.*"]),
    ("families", ["barhinge.families", "barhinge.families.*"]),
    ("actuators", ["barhinge.actuators", "barhinge.actuators.*"]),
    ("kinematics", ["barhinge.kinematics", "barhinge.kinematics.*"]),
    ("kernels", ["barhinge.kernels", "barhinge.kernels.*", "barhinge.assembly"]),
    ("model", ["barhinge.model", "barhinge.model.*"]),
    ("scene", ["barhinge.solver_options", "barhinge.loads", "barhinge.scene"]),
    ("solver", ["barhinge.solver", "barhinge.solver.*"]),
    ("analysis", ["barhinge.analysis", "barhinge.analysis.*"]),
    # fields on the mesh of a state and their VTU/XDMF files (meshio): drawn by the
    # pictures, shown by the viewer, written by output/
    ("fields", ["barhinge.fields"]),
    ("plot", ["barhinge.plot", "barhinge.plot.*"]),
    # the interactive HTML viewer of a result folder (it reads the fields' files)
    ("view", ["barhinge.view", "barhinge.view.*"]),
    # everything a run writes: the writer (run.py: files, pictures, the viewer), the step
    # table, the summary, the result folder, the mode files and the pictures
    ("output", ["barhinge.output", "barhinge.output.*"]),
    ("apps", ["barhinge.verify", "barhinge.sweep"]),
    ("cli", ["barhinge.cli", "barhinge.__main__"]),
    ("api", ["barhinge"]),
]

#: (importer, imported, reason): imports allowed although they point up. Keep it empty.
EXCEPTIONS: list[tuple[str, str, str]] = []

#: never loaded by ``import barhinge`` (rendering, plotting, clusters, sparse solvers)
HEAVY = ["scipy.sparse.linalg", "pyvista", "matplotlib", "dask", "meshio", "skfem"]


def module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def modules() -> dict[str, Path]:
    """Dotted name -> file of every module of the package."""
    return {module_name(p): p for p in sorted(PACKAGE.rglob("*.py"))}


def _imported(node: ast.AST, here: str, is_package: bool, known: set[str]) -> Iterator[str]:
    """The barhinge modules one import statement names."""
    if isinstance(node, ast.Import):
        for alias in node.names:
            yield alias.name
    elif isinstance(node, ast.ImportFrom):
        if node.level:  # relative: resolve against the importing module's package
            base = here.split(".")
            base = base if is_package else base[:-1]
            base = base[: len(base) - (node.level - 1)]
            mod = ".".join(base + ([node.module] if node.module else []))
        else:
            mod = node.module or ""
        for alias in node.names:
            sub = f"{mod}.{alias.name}"
            yield sub if sub in known else mod


def import_graph() -> dict[str, set[str]]:
    """Module -> the barhinge modules it imports (module-level and function-level)."""
    mods = modules()
    known = set(mods)
    graph: dict[str, set[str]] = {}
    for name, path in mods.items():
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        out: set[str] = set()
        for node in ast.walk(tree):
            if not isinstance(node, ast.Import | ast.ImportFrom):
                continue
            for target in _imported(node, name, path.name == "__init__.py", known):
                # the module itself, or the nearest enclosing barhinge module/package
                while target and target not in known:
                    target = target.rpartition(".")[0]
                if target and target != name:
                    out.add(target)
        graph[name] = out
    return graph


def layer_of(module: str) -> int:
    for i, (_, patterns) in enumerate(LAYERS):
        if module in patterns:
            return i
    for i, (_, patterns) in enumerate(LAYERS):
        if any(fnmatch.fnmatchcase(module, p) for p in patterns):
            return i
    raise LookupError(f"{module} is in no layer of LAYERS (tests/test_architecture.py)")


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components with more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    out: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def upward_imports(graph: dict[str, set[str]]) -> list[tuple[str, str]]:
    allowed = {(a, b) for a, b, _ in EXCEPTIONS}
    return sorted(
        (a, b)
        for a, targets in graph.items()
        for b in targets
        if layer_of(b) > layer_of(a) and (a, b) not in allowed
    )


def test_the_graph_is_read():
    graph = import_graph()
    assert "barhinge.linalg.backends" in graph["barhinge.kinematics.path"]
    assert "barhinge.kinematics.path" in graph["barhinge.solver.branch"]
    assert sum(len(t) for t in graph.values()) > 150


def test_every_module_has_a_layer():
    for name in modules():
        layer_of(name)


def test_no_import_cycles():
    assert cycles(import_graph()) == []


def test_imports_point_down_the_layers():
    graph = import_graph()
    up = upward_imports(graph)
    assert up == [], "\n".join(
        f"{a} ({LAYERS[layer_of(a)][0]}) imports {b} ({LAYERS[layer_of(b)][0]})" for a, b in up
    )


def test_exceptions_are_still_needed():
    graph = import_graph()
    for a, b, reason in EXCEPTIONS:
        assert b in graph[a], f"exception {a} -> {b} ({reason}) is no longer used: remove it"


def test_import_barhinge_stays_cheap():
    """``import barhinge`` loads no rendering, plotting, cluster or sparse-solver library,
    and none of the solver, kinematics or model modules."""
    code = (
        "import sys, barhinge; "
        "print('\\n'.join(m for m in sys.modules if m.split('.')[0] in "
        f"{sorted({h.split('.')[0] for h in HEAVY} | {'scipy', 'barhinge'})!r}))"
    )
    loaded = set(
        subprocess.run(
            [sys.executable, "-c", code], check=True, capture_output=True, text=True, cwd=ROOT
        ).stdout.split()
    )
    assert not [h for h in HEAVY if h in loaded]
    assert not [
        m
        for m in loaded
        if m.startswith(("barhinge.solver", "barhinge.kinematics", "barhinge.model"))
    ]


@pytest.mark.parametrize("module", ["barhinge.scene", "barhinge.kinematics"])
def test_lower_layers_do_not_load_the_solver(module):
    """A scene and rigid kinematics load without the Newton driver."""
    code = f"import sys, {module}; print('barhinge.solver.newton' in sys.modules)"
    out = subprocess.run(
        [sys.executable, "-c", code], check=True, capture_output=True, text=True, cwd=ROOT
    ).stdout.strip()
    assert out == "False"
