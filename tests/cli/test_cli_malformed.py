"""The CLI's input contract, one parametrised table of malformed invocations (issue 16).

Every row runs ``barhinge.cli.main(argv)`` in this process (a few dangerous rows, whose
values reached a factorisation and crashed the interpreter, run in a subprocess) and checks
the documented contract (README "Conventions"):

- exit code 2 for bad input, 3 when the solve did not converge;
- nothing on stderr looks like a traceback;
- exactly one line starting ``error:`` on stderr, naming the offending key, file or value
  (``needle``, a substring of that line).

The malformed inputs are small files written once per session into a temporary folder.
Rows that still need the value checks of ``scene.py`` / ``sweep.py`` / the pattern readers
(issue 16, parts B and E) are strict xfails, so they flip to failures when those land.
"""

from __future__ import annotations

import json
import shlex
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from barhinge.cli import main

REPO = Path(__file__).resolve().parents[2]

SCENE_FIX = "validated in scene.py (issue 16 part B)"
STUDY_FIX = "validated in sweep.py (issue 16 part B/F)"
PATTERN_FIX = "validated in the pattern readers / generators (issue 16 parts B/E)"


@dataclass(frozen=True)
class Row:
    id: str
    argv: str  # shell words; {d} is the folder of malformed inputs, {o} a fresh output path
    needle: str  # substring of the error line (naming the key, file or value)
    code: int = 2
    xfail: str | None = None
    subprocess: bool = False  # may crash the interpreter until fixed: run it apart
    report: bool = False  # ``info``: a findings report on stdout, not an ``error:`` line


# ------------------------------------------------------------------------ the inputs

_MIURA = {"nx": 2, "ny": 2, "a": 1.0, "b": 1.0, "alpha": 60.0, "fold": 5.0}
_EDGES = [8, 9, 10, 11]  # miura_line_creases of the 2 x 2 sheet
_TARGETS = [-81.7868, 81.7868, -81.7868, 81.7868]


def _base_scene() -> dict[str, dict[str, str]]:
    """The tiny valid scene as {section: {key: TOML value text}} ("" = top level)."""
    return {
        "": {"name": '"tiny"'},
        "pattern": {
            "family": '"miura"',
            "params": "{ " + ", ".join(f"{k} = {v}" for k, v in _MIURA.items()) + " }",
        },
        "model": {
            "scheme": '"N5B8"',
            "material": "{ E = 1.0e6, nu = 0.3, t = 0.01 }",
            "fold_stiffness": "1.0e-3",
        },
        "actuators": {"edges": str(_EDGES), "targets_deg": str(_TARGETS)},
        "solve": {"steps": "2"},
    }


def _toml(sections: dict[str, dict[str, str] | str | None]) -> str:
    top = sections.get("", {}) or {}
    lines = [f"{k} = {v}" for k, v in top.items()]
    for name, body in sections.items():
        if name == "" or body is None:
            continue
        if isinstance(body, str):  # raw text, e.g. "pattern = 3" or "[[supports]] ..."
            lines.append(body)
            continue
        lines.append(f"[{name}]")
        lines += [f"{k} = {v}" for k, v in body.items()]
    return "\n".join(lines) + "\n"


def _scene(**edits: object) -> str:
    """The tiny scene with edits: ``section__key=value`` sets (None deletes) a key,
    ``section=None`` deletes a table, ``section="raw text"`` replaces it, and
    ``extra="raw text"`` is appended."""
    s: dict = _base_scene()
    extra = edits.pop("extra", "")
    for key, value in edits.items():
        if "__" in key:
            sec, k = key.split("__")
            sec = "" if sec == "top" else sec
            if value is None:
                s[sec].pop(k, None)
            else:
                s.setdefault(sec, {})[k] = value
        else:
            s[key] = value
    return _toml(s) + str(extra)


def _material(**kw: str) -> str:
    m = {"E": "1.0e6", "nu": "0.3", "t": "0.01", **kw}
    return "{ " + ", ".join(f"{k} = {v}" for k, v in m.items() if v is not None) + " }"


def _params(**kw: str) -> str:
    m = {k: str(v) for k, v in _MIURA.items()} | kw
    return "{ " + ", ".join(f"{k} = {v}" for k, v in m.items()) + " }"


SVG_HEAD = '<svg xmlns="http://www.w3.org/2000/svg" width="10" height="10">'
SVG_OK = (
    SVG_HEAD
    + '<line x1="0" y1="0" x2="10" y2="0" stroke="#000000"/>'
    + '<line x1="10" y1="0" x2="10" y2="10" stroke="#000000"/>'
    + '<line x1="10" y1="10" x2="0" y2="10" stroke="#000000"/>'
    + '<line x1="0" y1="10" x2="0" y2="0" stroke="#000000"/>'
    + '<line x1="0" y1="0" x2="10" y2="10" stroke="#ff0000"/></svg>'
)

BINARY = bytes(range(256)) * 8


def _pattern_files(valid_fold: str) -> dict[str, str | bytes]:
    """Malformed crease patterns: name -> content."""
    sq = [[0, 0], [1, 0], [1, 1], [0, 1]]
    ring = [[0, 1], [1, 2], [2, 3], [3, 0]]

    def fold(**kw: object) -> str:
        d = {"file_spec": 1.1, "vertices_coords": sq, "edges_vertices": ring}
        d |= {"edges_assignment": ["B"] * 4}
        d |= kw
        return json.dumps({k: v for k, v in d.items() if v is not None})

    return {
        "empty.fold": "",
        "blank.fold": "  \n\n",
        "truncated.fold": valid_fold[: len(valid_fold) // 2],
        "binary.fold": BINARY,
        "list.fold": "[1, 2, 3]",
        "string.fold": '"a fold file"',
        "number.fold": "42",
        "null_coords.fold": fold(vertices_coords=None),
        "no_edges.fold": fold(edges_vertices=None, edges_assignment=None),
        "str_coords.fold": fold(vertices_coords=[["a", "b"], [1, 0], [1, 1], [0, 1]]),
        "nan_coords.fold": fold(vertices_coords=[[float("nan"), 0], [1, 0], [1, 1], [0, 1]]),
        "flat_coords.fold": fold(vertices_coords=[0, 1, 2, 3]),
        "edge_out_of_range.fold": fold(edges_vertices=[[0, 1], [1, 2], [2, 3], [3, 99]]),
        "edge_negative.fold": fold(edges_vertices=[[0, 1], [1, 2], [2, 3], [3, -1]]),
        "edge_three.fold": fold(edges_vertices=[[0, 1, 2], [1, 2], [2, 3], [3, 0]]),
        "bad_assignment.fold": fold(edges_assignment=["B", "B", "Q", "B"]),
        "short_assignment.fold": fold(edges_assignment=["B", "B"]),
        "bad_fold_angle.fold": fold(edges_foldAngle=["x", 0, 0, 0]),
        "face_out_of_range.fold": fold(faces_vertices=[[0, 1, 99]]),
        "coords_dict.fold": fold(vertices_coords={"a": 1}),
        "bad_json.fold": '{"vertices_coords": [[0, 0], [1, 0]],, }',
        "pattern.txt": valid_fold,
        "pattern": valid_fold,
        "empty.svg": "",
        "truncated.svg": SVG_OK[: len(SVG_OK) // 2],
        "binary.svg": BINARY,
        "html.svg": "<html><body><p>not a drawing</p></body></html>",
        "no_lines.svg": SVG_HEAD + "</svg>",
        "collapsed.svg": SVG_HEAD + '<line x1="1" y1="1" x2="1" y2="1" stroke="#000"/></svg>',
        "bad_coord.svg": SVG_OK.replace(
            'x1="0" y1="0" x2="10" y2="0"', 'x1="abc" y1="0" x2="10" y2="0"'
        ),
        "nan_coord.svg": SVG_OK.replace('x2="10" y2="0"', 'x2="nan" y2="0"'),
        "bad_path.svg": SVG_HEAD + '<path d="M 0 0 L zz" stroke="#000"/></svg>',
        "text.svg": "just some text, no xml at all",
    }


def _npz_bytes(**arrays: object) -> bytes:
    import io

    buf = io.BytesIO()
    np.savez(buf, **arrays)
    return buf.getvalue()


@pytest.fixture(scope="session")
def d(tmp_path_factory) -> Path:
    """The folder of malformed inputs (and a few valid ones to point bad options at)."""
    from barhinge.families import miura
    from barhinge.kinematics.path import rigid_fold
    from barhinge.pattern.fold import write_fold

    root = tmp_path_factory.mktemp("malformed")
    cp = miura(2, 2, a=1.0, b=1.0, alpha=60.0, fold=5.0)
    write_fold(cp, root / "valid.fold")
    valid_fold = (root / "valid.fold").read_text()
    (root / "valid.svg").write_text(SVG_OK)
    for name, content in _pattern_files(valid_fold).items():
        f = root / "p" / name
        f.parent.mkdir(exist_ok=True)
        (f.write_bytes if isinstance(content, bytes) else f.write_text)(content)
    (root / "p" / "dir.fold").mkdir()
    # a file to put paths under, and a folder where a file is expected
    (root / "a_file").write_text("not a folder\n")
    (root / "a_dir.fold").mkdir()
    (root / "a_dir.toml").mkdir()
    (root / "a_dir.npz").mkdir()
    (root / "a_dir.png").mkdir()
    # scenes
    sc = root / "s"
    sc.mkdir()
    (sc / "ok.toml").write_text(_scene())
    for name, text in SCENES.items():
        (sc / f"{name}.toml").write_text(text)
    (sc / "binary.toml").write_bytes(BINARY)
    (sc / "no_convergence.toml").write_text(
        _scene(solve__steps="1", solve__options="{ max_iter = 1, max_cutbacks = 0 }")
    )
    (sc / "truncated.toml").write_text(_scene()[:-40])
    for name in _pattern_files(""):
        (sc / f"file_{name}.toml").write_text(
            _scene(pattern=f'[pattern]\nfile = "{root / "p" / name}"')
        )
    # fold paths
    r = root / "r"
    r.mkdir()
    a = np.array(_EDGES)
    path = rigid_fold(cp, actuators=a, targets_deg=np.array(_TARGETS) / 4, steps=2)
    path.save(r / "fold_path.npz")
    write_fold(cp, r / "fold_path.fold")
    good = (r / "fold_path.npz").read_bytes()
    npz = {
        "empty.npz": b"",
        "truncated.npz": good[: len(good) // 2],
        "binary.npz": BINARY,
        "text.npz": "fold path\n",
        "foreign.npz": _npz_bytes(a=np.arange(3), b=np.ones((2, 2))),
        "bad_json.npz": _npz_bytes(__json__=np.array("{not json")),
        "json_list.npz": _npz_bytes(__json__=np.array("[1, 2]")),
        "wrong_fields.npz": _npz_bytes(__json__=np.array('{"bogus": 1}')),
        "missing_X.npz": _npz_bytes(__json__=np.array("{}"), fold_angles_deg=np.zeros((2, 3))),
        "plain.npy": b"",
    }
    for name, content in npz.items():
        f = r / name
        (f.write_bytes if isinstance(content, bytes) else f.write_text)(content)
    import io

    buf = io.BytesIO()
    np.save(buf, np.arange(4))
    (r / "plain.npy").write_bytes(buf.getvalue())
    (r / "array.npz").write_bytes(buf.getvalue())  # a .npy named .npz
    # a fold path with no pattern beside it
    (r / "alone").mkdir()
    (r / "alone" / "path.npz").write_bytes(good)
    # studies
    st = root / "st"
    st.mkdir()
    (st / "points.py").write_text("def point(x=1):\n    return {'y': x}\n")
    for name, text in STUDIES.items():
        (st / f"{name}.toml").write_text(text)
    (st / "ok.toml").write_text(_study())
    (st / "binary.toml").write_bytes(BINARY)
    return root


# ------------------------------------------------------------------------ scenes

SCENES: dict[str, str] = {
    "empty": "",
    "only_comment": "# nothing here\n",
    "invalid_syntax": _scene() + "steps = = 3\n",
    "duplicate_key": _scene(extra="[solve]\nsteps = 3\n"),
    "top_bogus": _scene(top__bogus="1"),
    "top_list": "[[pattern]]\nfamily = 'miura'\n",
    "no_pattern": _scene(pattern=None),
    "pattern_number": _scene(pattern=None, top__pattern="3"),
    "pattern_empty": _scene(pattern={}),
    "pattern_both": _scene(pattern__file='"x.fold"'),
    "pattern_bogus": _scene(pattern__bogus="1"),
    "family_unknown": _scene(pattern__family='"nosuchfamily"'),
    "family_number": _scene(pattern__family="7"),
    "params_bogus": _scene(pattern__params=_params(bogus="1")),
    "params_number": _scene(pattern__params="3"),
    "params_nx_str": _scene(pattern__params=_params(nx='"many"')),
    "params_nx_zero": _scene(pattern__params=_params(nx="0")),
    "params_nx_negative": _scene(pattern__params=_params(nx="-2")),
    "params_nx_float": _scene(pattern__params=_params(nx="1.5")),
    "params_alpha_big": _scene(pattern__params=_params(alpha="200.0")),
    "params_alpha_zero": _scene(pattern__params=_params(alpha="0.0")),
    "params_a_negative": _scene(pattern__params=_params(a="-1.0")),
    "params_a_nan": _scene(pattern__params=_params(a="nan")),
    "params_fold_str": _scene(pattern__params=_params(fold='"x"')),
    "file_missing": _scene(pattern='[pattern]\nfile = "no_such_pattern.fold"'),
    "file_number": _scene(pattern="[pattern]\nfile = 3"),
    "file_frame_str": _scene(pattern='[pattern]\nfile = "../valid.fold"\nframe = "x"'),
    "file_frame_big": _scene(pattern='[pattern]\nfile = "../valid.fold"\nframe = 99'),
    "model_bogus": _scene(model__bogus="1"),
    "model_number": _scene(model=None, top__model="3"),
    "scheme_unknown": _scene(model__scheme='"N9B9"'),
    "scheme_number": _scene(model__scheme="5"),
    "material_bogus": _scene(model__material=_material(bogus="1")),
    "material_number": _scene(model__material="3"),
    "E_negative": _scene(model__material=_material(E="-1.0")),
    "E_zero": _scene(model__material=_material(E="0.0")),
    "E_str": _scene(model__material=_material(E='"steel"')),
    "nu_big": _scene(model__material=_material(nu="0.6")),
    "nu_negative": _scene(model__material=_material(nu="-1.5")),
    "nu_str": _scene(model__material=_material(nu='"x"')),
    "t_zero": _scene(model__material=_material(t="0.0")),
    "t_negative": _scene(model__material=_material(t="-0.01")),
    "t_list": _scene(model__material=_material(t="[0.01]")),
    "fold_stiffness_negative": _scene(model__fold_stiffness="-1.0"),
    "fold_stiffness_str": _scene(model__fold_stiffness='"soft"'),
    "fold_stiffness_list": _scene(model__fold_stiffness="[1, 2]"),
    "actuators_bogus": _scene(actuators__bogus="1"),
    "actuators_number": _scene(actuators=None, top__actuators="3"),
    "edges_missing": _scene(actuators__edges=None),
    "edges_word": _scene(actuators__edges='"nosuch"'),
    "edges_out_of_range": _scene(actuators__edges="[8, 9, 10, 999]"),
    "edges_negative": _scene(actuators__edges="[8, 9, 10, -1]"),
    "edges_str": _scene(actuators__edges='[8, 9, 10, "a"]'),
    "edges_float": _scene(actuators__edges="[8, 9, 10, 11.7]"),
    "edges_number": _scene(actuators__edges="3"),
    "edges_boundary": _scene(actuators__edges="[8, 9, 10, 0]"),
    "edges_empty_targets": _scene(actuators__targets_deg="[]"),
    "targets_short": _scene(actuators__targets_deg="[1.0, 2.0]"),
    "targets_str": _scene(actuators__targets_deg='["a", 1.0, 1.0, 1.0]'),
    "targets_nan": _scene(actuators__targets_deg="[nan, 1.0, 1.0, 1.0]"),
    "targets_inf": _scene(actuators__targets_deg="[inf, 1.0, 1.0, 1.0]"),
    "targets_over_180": _scene(actuators__targets_deg="[270.0, 1.0, 1.0, 1.0]"),
    "table_ragged": _scene(actuators__targets_deg=None, actuators__table_deg="[[1.0], [1.0, 2.0]]"),
    "table_wrong_width": _scene(actuators__targets_deg=None, actuators__table_deg="[[1.0, 2.0]]"),
    "table_over_180": _scene(
        actuators__targets_deg=None, actuators__table_deg="[[0, 0, 0, 0], [400, 0, 0, 0]]"
    ),
    "steps_zero": _scene(solve__steps="0"),
    "steps_negative": _scene(solve__steps="-3"),
    "steps_str": _scene(solve__steps='"ten"'),
    "steps_bool": _scene(solve__steps="true"),
    "steps_float": _scene(solve__steps="2.7"),
    "steps_list": _scene(solve__steps="[2]"),
    "solve_bogus": _scene(solve__bogus="1"),
    "solve_number": _scene(solve=None, top__solve="3"),
    "control_unknown": _scene(solve__control='"wiggle"'),
    "control_load": _scene(solve__control='"load"'),
    "control_displacement": _scene(solve__control='"displacement"'),
    "options_bogus": _scene(solve__options="{ bogus = 1 }"),
    "options_number": _scene(solve__options="3"),
    "options_max_iter_zero": _scene(solve__options="{ max_iter = 0 }"),
    "options_tol_negative": _scene(solve__options="{ tol_force = -1.0 }"),
    "options_tol_str": _scene(solve__options='{ tol_force = "tight" }'),
    "options_solver_unknown": _scene(solve__options='{ linear_solver = "magic" }'),
    "options_predictor_unknown": _scene(solve__options='{ predictor = "psychic" }'),
    "supports_number": _scene(top__supports="3"),
    "supports_bogus": _scene(extra='[[supports]]\nwhere = "left"\nbogus = 1\n'),
    "supports_where": _scene(extra='[[supports]]\nwhere = "upstairs"\n'),
    "supports_dofs": _scene(extra='[[supports]]\nwhere = "left"\ndofs = "abc"\n'),
    "supports_vertex_range": _scene(extra="[[supports]]\nvertices = [999]\n"),
    "supports_vertex_str": _scene(extra='[[supports]]\nvertices = ["a"]\n'),
    "supports_nothing": _scene(extra='[[supports]]\ndofs = "x"\n'),
    "supports_nodes_range": _scene(extra="[[supports]]\nnodes = [-5]\n"),
    "supports_edges_range": _scene(extra="[[supports]]\nedges = [999]\n"),
    "loads_bogus": _scene(extra='[[loads]]\nwhere = "top"\nbogus = 1\n'),
    "loads_force_short": _scene(extra='[[loads]]\nwhere = "top"\nforce = [1.0, 2.0]\n'),
    "loads_force_str": _scene(extra='[[loads]]\nwhere = "top"\nforce = ["a", "b", "c"]\n'),
    "self_weight_no_density": _scene(extra="[[loads]]\nself_weight = { g = [0, 0, -9.81] }\n"),
    "self_weight_density_str": _scene(extra='[[loads]]\nself_weight = { area_density = "x" }\n'),
    "self_weight_g_short": _scene(
        extra="[[loads]]\nself_weight = { area_density = 1.0, g = [0, -9.8] }\n"
    ),
    "self_weight_bogus": _scene(extra="[[loads]]\nself_weight = { area_density = 1.0, h = 1 }\n"),
    "prescribed_no_displacement": _scene(extra='[[prescribed]]\nwhere = "left"\n'),
    "prescribed_short": _scene(extra='[[prescribed]]\nwhere = "left"\ndisplacement = [1.0]\n'),
    "prescribed_and_supported": _scene(
        extra='[[supports]]\nwhere = "left"\n[[prescribed]]\nwhere = "left"\n'
        "displacement = [0.1, 0, 0]\n"
    ),
}

# values that reached the factorisation once (segfaults in PARDISO): run in a subprocess
CRASHING = {
    "E_inf": _scene(model__material=_material(E="inf")),
    "E_nan": _scene(model__material=_material(E="nan")),
    "fold_stiffness_nan": _scene(model__fold_stiffness="nan"),
    "fold_stiffness_inf": _scene(model__fold_stiffness="inf"),
}
SCENES |= CRASHING

# rows still wrong today (strict xfail: they flip when fixed)
_SCENE_XFAIL: set[str] = set()

# scene name -> substring of the error line
_SCENE_NEEDLE = {
    "empty": "pattern",
    "only_comment": "pattern",
    "invalid_syntax": "invalid_syntax.toml",
    "duplicate_key": "duplicate_key.toml",
    "top_bogus": "bogus",
    "top_list": "pattern",
    "no_pattern": "pattern",
    "pattern_number": "pattern",
    "pattern_empty": "pattern",
    "pattern_both": "exactly one",
    "pattern_bogus": "bogus",
    "family_unknown": "nosuchfamily",
    "family_number": "family",
    "params_bogus": "bogus",
    "params_number": "params",
    "params_nx_str": "nx",
    "params_nx_zero": "nx",
    "params_nx_negative": "nx",
    "params_nx_float": "nx",
    "params_alpha_big": "alpha",
    "params_alpha_zero": "alpha",
    "params_a_negative": "a",
    "params_a_nan": "a",
    "params_fold_str": "fold",
    "file_missing": "no_such_pattern.fold",
    "file_number": "file",
    "file_frame_str": "frame",
    "file_frame_big": "frame",
    "model_bogus": "bogus",
    "model_number": "model",
    "scheme_unknown": "N9B9",
    "scheme_number": "scheme",
    "material_bogus": "bogus",
    "material_number": "material",
    "E_negative": "E",
    "E_zero": "E",
    "E_str": "E",
    "nu_big": "nu",
    "nu_negative": "nu",
    "nu_str": "nu",
    "t_zero": "t",
    "t_negative": "t",
    "t_list": "t",
    "fold_stiffness_negative": "fold_stiffness",
    "fold_stiffness_str": "fold_stiffness",
    "fold_stiffness_list": "fold_stiffness",
    "actuators_bogus": "bogus",
    "actuators_number": "actuators",
    "edges_missing": "edges",
    "edges_word": "nosuch",
    "edges_out_of_range": "999",
    "edges_negative": "-1",
    "edges_str": "edges",
    "edges_float": "11.7",
    "edges_number": "edges",
    "edges_boundary": "edge 0",
    "edges_empty_targets": "targets_deg",
    "targets_short": "targets_deg",
    "targets_str": "targets_deg",
    "targets_nan": "targets_deg",
    "targets_inf": "targets_deg[0] = inf",
    "targets_over_180": "270",
    "table_ragged": "table_deg",
    "table_wrong_width": "table_deg",
    "table_over_180": "400",
    "steps_zero": "steps",
    "steps_negative": "steps",
    "steps_str": "steps",
    "steps_bool": "steps",
    "steps_float": "steps",
    "steps_list": "steps",
    "solve_bogus": "bogus",
    "solve_number": "solve",
    "control_unknown": "wiggle",
    "control_load": "load",
    "control_displacement": "displacement",
    "options_bogus": "bogus",
    "options_number": "options",
    "options_max_iter_zero": "max_iter",
    "options_tol_negative": "tol_force",
    "options_tol_str": "tol_force",
    "options_solver_unknown": "magic",
    "options_predictor_unknown": "psychic",
    "supports_number": "supports",
    "supports_bogus": "bogus",
    "supports_where": "upstairs",
    "supports_dofs": "abc",
    "supports_vertex_range": "vertices",
    "supports_vertex_str": "vertices",
    "supports_nothing": "supports.0",
    "supports_nodes_range": "nodes",
    "supports_edges_range": "edges",
    "loads_bogus": "bogus",
    "loads_force_short": "force",
    "loads_force_str": "force",
    "self_weight_no_density": "area_density",
    "self_weight_density_str": "area_density",
    "self_weight_g_short": "g",
    "self_weight_bogus": "h",
    "prescribed_no_displacement": "displacement",
    "prescribed_short": "displacement",
    "prescribed_and_supported": "both supported and prescribed",
    "E_inf": "E",
    "E_nan": "E",
    "fold_stiffness_nan": "fold_stiffness",
    "fold_stiffness_inf": "fold_stiffness",
}


# ------------------------------------------------------------------------ studies


def _study(study: str = 'function = "points:point"\npaths = ["."]\n', rest: str = "") -> str:
    return "[study]\n" + study + "\n" + rest


STUDIES: dict[str, str] = {
    "empty": "",
    "invalid_syntax": "[study\nfunction = 1\n",
    "unknown_table": _study(rest="[bogus]\nx = 1\n"),
    "unknown_key": _study('function = "points:point"\nbogus = 1\n'),
    "no_function": _study('name = "x"\n'),
    "function_no_colon": _study('function = "points"\npaths = ["."]\n'),
    "function_number": _study("function = 3\n"),
    "function_module": _study('function = "no_such_module_xyz:f"\n'),
    "function_name": _study('function = "points:nosuch"\npaths = ["."]\n'),
    "grid_number": "grid = 3\n" + _study(),
    "grid_scalar": _study(rest="[grid]\nx = 3\n"),
    "points_number": "points = 3\n" + _study(),
    "batch_size_str": _study('function = "points:point"\npaths = ["."]\nbatch_size = "x"\n'),
    "batch_size_zero": _study('function = "points:point"\npaths = ["."]\nbatch_size = 0\n'),
    "paths_number": _study('function = "points:point"\npaths = 3\n'),
    "study_number": "study = 3\n",
    # keys the point function does not take: every point would fail; stopped before running
    "grid_key_not_a_parameter": _study(rest="[grid]\nx = [1, 2]\nbogus = [1]\n"),
    "fixed_key_not_a_parameter": _study(rest="[fixed]\nsteps = 3\n"),
    "grid_date": _study(rest="[grid]\nx = [2020-01-02]\n"),
}

_STUDY_NEEDLE = {
    "empty": "function",
    "invalid_syntax": "invalid_syntax.toml",
    "unknown_table": "bogus",
    "unknown_key": "bogus",
    "no_function": "function",
    "function_no_colon": "points",
    "function_number": "function",
    "function_module": "no_such_module_xyz",
    "function_name": "nosuch",
    "grid_number": "grid",
    "grid_scalar": "x",
    "points_number": "points",
    "batch_size_str": "batch_size",
    "batch_size_zero": "batch_size",
    "paths_number": "paths",
    "study_number": "study",
    "grid_key_not_a_parameter": "[grid] key 'bogus'",
    "fixed_key_not_a_parameter": "[fixed] key 'steps'",
    "grid_date": "x[0] = datetime.date",
}


# ------------------------------------------------------------------------ the table

COMMANDS = ("fold", "info", "dof", "patterns", "render", "study", "verify")
_ARGS = {  # a valid first argument of each command, for option errors after it
    "fold": "{d}/s/ok.toml",
    "info": "{d}/valid.fold",
    "dof": "{d}/valid.fold",
    "patterns": "miura",
    "render": "{d}/r/fold_path.npz",
    "study": "{d}/st/unknown_key.toml",
    "verify": "",
}


def _rows() -> list[Row]:
    rows: list[Row] = []
    add = rows.append
    # --- usage: unknown commands and root options
    for cmd in ("nosuch", "fodl", "FOLD", "infos", "help", "render2", "-", "_"):
        add(Row(f"cmd-{cmd}", cmd, cmd))
    add(Row("root-option", "--nosuch", "--nosuch"))
    add(Row("root-short-option", "-q fold", "-q"))
    add(Row("root-debug-value", "--debug=yes fold", "--debug"))
    add(Row("debug-then-unknown", "--debug nosuch", "nosuch"))
    # --- usage: every command, unknown and malformed options
    for cmd in COMMANDS:
        a = _ARGS[cmd]
        add(Row(f"{cmd}-unknown-option", f"{cmd} {a} --nosuch", "--nosuch"))
        add(Row(f"{cmd}-unknown-short", f"{cmd} {a} -Z", "-Z"))
        add(Row(f"{cmd}-misspelt-json", f"{cmd} {a} --jsn", "--jsn"))
        add(Row(f"{cmd}-json-value", f"{cmd} {a} --json=yes", "--json"))
        add(Row(f"{cmd}-debug-after", f"{cmd} {a} --debug", "--debug"))
    # missing arguments and option values
    for cmd in ("info", "dof", "render", "study"):
        add(Row(f"{cmd}-no-argument", cmd, "Missing argument"))
    for argv, needle in [
        ("fold {d}/s/ok.toml --out", "--out"),
        ("info {d}/valid.fold --merge-tol", "--merge-tol"),
        ("dof {d}/valid.fold --png", "--png"),
        ("dof {d}/valid.fold --prefer", "--prefer"),
        ("patterns miura -p", "-p"),
        ("patterns miura --out", "--out"),
        ("render {d}/r/fold_path.npz --step", "--step"),
        ("render {d}/r/fold_path.npz --pattern", "--pattern"),
        ("render {d}/r/fold_path.npz --scalars", "--scalars"),
        ("study {d}/st/unknown_key.toml --workers", "--workers"),
        ("study {d}/st/unknown_key.toml --scheduler", "--scheduler"),
        ("study {d}/st/unknown_key.toml --batch-size", "--batch-size"),
        ("verify --case", "--case"),
    ]:
        add(Row(f"no-value-{argv.split()[0]}-{argv.split()[-1]}", argv, needle))
    # bad option values
    for argv, needle in [
        (
            "render {d}/r/fold_path.npz --step abc",
            "unable to parse string as an integer (got 'abc')",
        ),
        ("render {d}/r/fold_path.npz --step 1.5", "'1.5'"),
        ("render {d}/r/fold_path.npz --step ''", "--step"),
        ("render {d}/r/fold_path.npz --step 1e3", "'1e3'"),
        ("render {d}/r/fold_path.npz --step 99", "--step 99"),
        ("render {d}/r/fold_path.npz --step -99", "--step -99"),
        ("study {d}/st/unknown_key.toml --workers abc", "'abc'"),
        ("study {d}/st/unknown_key.toml --workers 2.5", "'2.5'"),
        ("study {d}/st/unknown_key.toml --batch-size x", "(got 'x')"),
        ("info {d}/valid.fold --merge-tol abc", "'abc'"),
        ("info {d}/valid.fold --merge-tol 1,2", "'1,2'"),
        ("info {d}/valid.fold --merge-tol -1", "merge_tol"),
        ("info {d}/valid.fold --merge-tol nan", "merge_tol"),
        ("info {d}/valid.fold --merge-tol inf", "merge_tol"),
        ("fold {d}/s/ok.toml --form-only=maybe", "--form-only"),
        ("render {d}/r/fold_path.npz --gif=no", "--gif"),
        ("render {d}/r/fold_path.npz --step=abc", "(got 'abc')"),
        ("dof {d}/valid.fold --png {d}/out.fold", ".png, .svg or .pdf"),
        ("dof {d}/valid.fold --png {d}/out", ".png, .svg or .pdf"),
        ("dof {d}/valid.fold --png {d}/out.txt", "--png"),
        ("verify --list --case nosuchcase", "nosuchcase"),
    ]:
        add(Row(f"bad-value-{argv.split()[0]}-{argv.split()[-1]}", argv, needle))
    # extra arguments
    for argv in (
        "fold {d}/s/ok.toml {d}/s/ok.toml",
        "info {d}/valid.fold {d}/valid.fold",
        "dof {d}/valid.fold miura",
        "patterns miura yoshimura",
        "render {d}/r/fold_path.npz {d}/r/fold_path.npz",
        "study {d}/st/empty.toml extra",
        "verify extra",
    ):
        add(Row(f"extra-argument-{argv.split()[0]}", argv, "unexpected extra argument"))
    # --- pattern files: info, dof, as a scene's [pattern] file, as render --pattern
    for name in [*_pattern_files(""), "dir.fold", "missing.fold", "missing.svg"]:
        f = f"{{d}}/p/{name}"
        xf = PATTERN_FIX if name in _PATTERN_XFAIL else None
        rep = name in _PATTERN_REPORT
        add(Row(f"info-{name}", f"info {f}", _pattern_needle(name), xfail=xf, report=rep))
        add(Row(f"dof-{name}", f"dof {f}", _pattern_needle(name), xfail=xf))
        add(
            Row(
                f"render-pattern-{name}",
                f"render {{d}}/r/fold_path.npz --pattern {f} --out {{o}} --no-gif",
                _pattern_needle(name),
            )
        )
        if name in _pattern_files(""):
            add(
                Row(
                    f"fold-pattern-file-{name}",
                    f"fold {{d}}/s/file_{name}.toml --out {{o}}",
                    _pattern_needle(name),
                    xfail=xf,
                )
            )
    add(Row("info-dir", "info {d}/a_dir.fold", "a_dir.fold: is a folder"))
    add(Row("dof-dir", "dof {d}/a_dir.fold", "a_dir.fold: is a folder"))
    # --- a crease pattern given as a scene, a scene given as a crease pattern: the error
    # says which is which and how a scene reads a pattern
    add(Row("fold-a-fold-file", "fold {d}/valid.fold --out {o}", 'file = "valid.fold"'))
    add(
        Row(
            "fold-an-svg-file",
            f"fold {REPO}/tests/data/crease-patterns/origami-simulator/miura-ori.svg --out {{o}}",
            "miura-ori.svg is an SVG file, not a scene TOML",
        )
    )
    add(Row("dof-a-scene", "dof {d}/s/ok.toml", "ok.toml is a scene TOML, not a crease pattern"))
    # --- scenes
    # (--out under a file: a scene accepted by mistake fails fast, before writing results)
    for name in SCENES:
        add(
            Row(
                f"fold-scene-{name}",
                f"fold {{d}}/s/{name}.toml --out {{d}}/a_file/never",
                _SCENE_NEEDLE[name],
                xfail=SCENE_FIX if name in _SCENE_XFAIL else None,
                subprocess=name in CRASHING,
            )
        )
    for argv, needle in [
        ("fold {d}/s/missing.toml --out {o}", "missing.toml"),
        ("fold {d}/a_dir.toml --out {o}", "a_dir.toml"),
        ("fold {d}/s/binary.toml --out {o}", "binary.toml"),
        ("fold {d}/s/truncated.toml --out {o}", "truncated.toml"),
        ("fold {d}/valid.fold --out {o}", "valid.fold"),
        ("fold {d}/r/fold_path.npz --out {o}", "fold_path.npz"),
    ]:
        xf = SCENE_FIX if argv.split()[1].rsplit("/", 1)[-1] in _SCENE_FILE_XFAIL else None
        add(Row(f"fold-file-{argv.split()[1].rsplit('/', 1)[-1]}", argv, needle, xfail=xf))
    # --- no convergence: exit 3, partial results written
    add(
        Row(
            "fold-no-convergence",
            "fold {d}/s/no_convergence.toml --out {o}",
            "did not converge",
            code=3,
        )
    )
    # --- output paths
    for i, (argv, needle) in enumerate(
        [
            ("fold {d}/s/ok.toml --out {d}/a_file", "a_file"),
            ("fold {d}/s/ok.toml --out {d}/a_file/sub", "a_file"),
            ("fold {d}/s/ok.toml --out /proc/barhinge-out", "/proc/barhinge-out"),
            ("fold {d}/s/ok.toml --form-only --out {d}/a_file", "a_file"),
            ("fold {d}/s/ok.toml --form-only --out {d}/a_file/sub", "a_file"),
            ("fold {d}/s/ok.toml --form-only --out /proc/barhinge-out", "/proc/barhinge-out"),
            ("patterns miura --out {d}/a_dir.fold", "a_dir.fold"),
            ("patterns miura --out {d}/a_file/x.fold", "a_file"),
            ("patterns miura --out /proc/barhinge.fold", "/proc/barhinge.fold"),
            ("patterns miura --out {d}/nosuchdir/x.fold", "nosuchdir"),
            ("dof {d}/valid.fold --png {d}/a_file/x.png", "a_file"),
            ("dof {d}/valid.fold --png {d}/a_dir.png", "a_dir.png"),
            ("render {d}/r/fold_path.npz --out {d}/a_file --no-gif", "a_file"),
            ("render {d}/r/fold_path.npz --out {d}/a_file/sub --no-gif", "a_file"),
            ("render {d}/r/fold_path.npz --out /proc/barhinge-out --no-gif", "/proc/barhinge-out"),
            ("study {d}/st/ok.toml --serial --out {d}/a_file", "a_file"),
            ("study {d}/st/ok.toml --serial --out {d}/a_file/sub", "a_file"),
            ("study {d}/st/ok.toml --serial --out /proc/barhinge-study", "/proc/barhinge-study"),
        ]
    ):
        add(Row(f"out-{i}-{argv.split()[0]}", argv, needle))
    # --- render: saved fold paths that are not
    for name in (
        "empty.npz",
        "truncated.npz",
        "binary.npz",
        "text.npz",
        "foreign.npz",
        "bad_json.npz",
        "json_list.npz",
        "wrong_fields.npz",
        "missing_X.npz",
        "plain.npy",
        "array.npz",
    ):
        add(Row(f"render-{name}", f"render {{d}}/r/{name} --out {{o}} --no-gif", name))
    add(Row("render-missing", "render {d}/r/nosuch.npz --out {o}", "nosuch.npz"))
    add(Row("render-dir", "render {d}/a_dir.npz --out {o}", "a_dir.npz"))
    add(Row("render-no-pattern", "render {d}/r/alone/path.npz --out {o}", "path.npz"))
    add(
        Row(
            "render-pattern-dir",
            "render {d}/r/fold_path.npz --pattern {d}/a_dir.fold --out {o}",
            "a_dir.fold",
        )
    )
    add(
        Row(
            "render-scalars",
            "render {d}/r/fold_path.npz --scalars bogus --backend matplotlib --no-gif --out {o}",
            "bogus",
        )
    )
    add(
        Row(
            "render-backend",
            "render {d}/r/fold_path.npz --backend bogus --no-gif --out {o}",
            "bogus",
        )
    )
    # --- patterns: families and parameters
    add(Row("patterns-unknown-family", "patterns nosuchfamily", "nosuchfamily"))
    add(Row("patterns-unknown-family-out", "patterns nosuch --out {o}.fold", "nosuch"))
    for fam in ("miura", "yoshimura", "waterbomb", "resch", "kresling", "pleats"):
        add(Row(f"patterns-{fam}-bogus", f"patterns {fam} -p bogus=1", "bogus"))
        add(Row(f"patterns-{fam}-no-equals", f"patterns {fam} -p target", "target"))
        add(Row(f"patterns-{fam}-no-name", f"patterns {fam} -p =3", "=3"))
        add(
            Row(
                f"patterns-{fam}-target-str",
                f"patterns {fam} -p target=steep",
                "target",
                xfail=PATTERN_FIX if fam in _PARAM_XFAIL else None,
            )
        )
        add(
            Row(
                f"patterns-{fam}-target-list",
                f"patterns {fam} -p target=[1,2]",
                "target",
                xfail=PATTERN_FIX if fam in _PARAM_XFAIL else None,
            )
        )
    for argv, needle in [
        ("patterns miura -p nx=0", "nx"),
        ("patterns miura -p nx=-2", "nx"),
        ("patterns miura -p nx=1.5", "nx"),
        ("patterns miura -p nx=abc", "nx"),
        ("patterns miura -p nx=null", "nx"),
        ("patterns miura -p alpha=0", "alpha"),
        ("patterns miura -p alpha=200", "alpha"),
        ("patterns miura -p alpha=NaN", "alpha"),
        ("patterns miura -p a=-1", "a"),
        ("patterns miura -p a=0", "a"),
        ("patterns yoshimura -p nx=0", "nx"),
        ("patterns yoshimura -p h=-1", "h"),
        ("patterns pleats -p n=0", "n"),
        ("patterns kresling -p n=2", "n"),
        ("patterns waterbomb -p s=0", "s"),
    ]:
        add(
            Row(
                f"patterns-value-{argv.split()[1]}-{argv.split()[-1]}",
                argv,
                needle,
                xfail=PATTERN_FIX if argv in _PARAM_VALUE_XFAIL else None,
            )
        )
    # --- dof: family specs
    for spec, needle in [
        ("nosuchfamily", "nosuchfamily"),
        ("nosuch.fold", "nosuch.fold"),
        ("miura:nx", "nx"),
        ("miura:bogus=1", "bogus"),
        ("miura:nx=abc", "nx"),
        ("miura:nx=0", "nx"),
        ("miura:alpha=200", "alpha"),
        ("miura:,=", "="),
    ]:
        add(
            Row(
                f"dof-spec-{spec}",
                f"dof {spec}",
                needle,
                xfail=PATTERN_FIX if spec in _DOF_XFAIL else None,
            )
        )
    add(Row("dof-prefer", "dof {d}/valid.fold --prefer nowhere", "nowhere"))
    # --- study files
    for name in STUDIES:
        add(
            Row(
                f"study-{name}",
                f"study {{d}}/st/{name}.toml --serial --out {{o}}",
                _STUDY_NEEDLE[name],
                xfail=STUDY_FIX if name in _STUDY_XFAIL else None,
            )
        )
    add(Row("study-missing", "study {d}/st/missing.toml --serial", "missing.toml"))
    add(
        Row(
            "study-dir",
            "study {d}/a_dir.toml --serial",
            "a_dir.toml",
            xfail=STUDY_FIX if "dir" in _STUDY_XFAIL else None,
        )
    )
    add(
        Row(
            "study-binary",
            "study {d}/st/binary.toml --serial",
            "binary.toml",
            xfail=STUDY_FIX if "binary" in _STUDY_XFAIL else None,
        )
    )
    add(
        Row(
            "study-workers-zero",
            "study {d}/st/ok.toml --workers 0 --out {o}",
            "workers",
            xfail=STUDY_FIX if "workers_zero" in _STUDY_XFAIL else None,
        )
    )
    add(
        Row(
            "study-batch-zero",
            "study {d}/st/ok.toml --serial --batch-size 0 --out {o}",
            "batch",
            xfail=STUDY_FIX if "batch_zero" in _STUDY_XFAIL else None,
        )
    )
    # --- verify
    add(Row("verify-unknown-case", "verify --case nosuchcase", "nosuchcase"))
    add(Row("verify-empty-case", "verify --case ''", "case"))
    return rows


# outcomes of today's code, filled in below
_PATTERN_XFAIL: set[str] = set()
_PATTERN_REPORT: set[str] = set()
_SCENE_FILE_XFAIL: set[str] = set()
_PARAM_XFAIL: set[str] = set()
_PARAM_VALUE_XFAIL: set[str] = set()
_DOF_XFAIL: set[str] = set()
_STUDY_XFAIL: set[str] = set()


def _pattern_needle(name: str) -> str:
    return name


ROWS = _rows()


def _params_of(rows: list[Row]) -> list:
    out = []
    for r in rows:
        marks = [pytest.mark.xfail(strict=True, reason=r.xfail)] if r.xfail else []
        out.append(pytest.param(r, id=r.id, marks=marks))
    return out


def _run(argv: list[str], capsys) -> tuple[int, str, str]:
    try:
        main(argv)
        code = 0
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
    cap = capsys.readouterr()
    return code, cap.out, cap.err


def _argv(row: Row, d: Path, out: Path) -> list[str]:
    return [w.format(d=d, o=out) for w in shlex.split(row.argv)]


@pytest.fixture(scope="session")
def apart(d: Path) -> dict[str, subprocess.Popen]:
    """The rows that may crash the interpreter, started together, each in a subprocess."""
    import os

    env = {**os.environ, "PYTHONPATH": str(REPO)}
    code = "import sys; from barhinge.cli import main; main(sys.argv[1:])"
    return {
        r.id: subprocess.Popen(
            [sys.executable, "-c", code, *_argv(r, d, d / "apart" / r.id)],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            cwd=REPO,
            env=env,
        )
        for r in ROWS
        if r.subprocess
    }


def _run_apart(p: subprocess.Popen) -> tuple[int, str, str]:
    out, err = p.communicate(timeout=300)
    return p.returncode, out, err


def test_the_table_is_big_enough():
    assert len(ROWS) >= 250
    assert len({r.id for r in ROWS}) == len(ROWS), "row ids must be unique"
    assert {r.argv.split()[0] for r in ROWS if r.argv} >= set(COMMANDS)


@pytest.mark.parametrize("row", _params_of(ROWS))
def test_malformed_invocation(row: Row, d: Path, tmp_path: Path, capsys, request, monkeypatch):
    monkeypatch.setenv("BARHINGE_PICTURES", "0")  # results without pictures (fast)
    argv = _argv(row, d, tmp_path / "out")
    if row.subprocess:
        code, out, err = _run_apart(request.getfixturevalue("apart")[row.id])
    else:
        code, out, err = _run(argv, capsys)
    shown = f"argv={argv}\nexit={code}\nstdout={out[-800:]}\nstderr={err[-1500:]}"
    assert "Traceback" not in err and "Traceback" not in out, shown
    assert code == row.code, shown
    errors = [ln for ln in err.splitlines() if ln.startswith("error:")]
    if row.report:  # info's findings report: on stdout, exit 2
        assert row.needle in out or row.needle in err, shown
        return
    assert len(errors) == 1, shown
    assert row.needle in errors[0], shown
    assert "internal error" not in err, shown


# ------------------------------------------------------------------------ the boundary itself


def test_bare_command_shows_the_help_with_exit_2(capsys):
    code, out, err = _run([], capsys)
    assert code == 2 and "Usage" in out + err and "Traceback" not in err


def test_help_exits_0(capsys):
    code, out, err = _run(["fold", "--help"], capsys)
    assert code == 0 and "--out" in out and not err


def _boom(*args, **kwargs):
    raise ZeroDivisionError("a bug [model] here")


def test_an_unexpected_exception_is_one_line_naming_a_bug_and_debug(capsys, monkeypatch, d):
    monkeypatch.setattr("barhinge.scene.load_scene", _boom)
    code, out, err = _run(["fold", str(d / "s" / "ok.toml")], capsys)
    lines = err.splitlines()
    assert code == 70 and len(lines) == 1, err
    assert lines[0].startswith("internal error: ZeroDivisionError: a bug [model] here")
    assert "bug in barhinge" in lines[0] and "--debug" in lines[0] and "Traceback" not in err


def test_debug_shows_the_traceback_and_does_not_stick(capsys, monkeypatch, d):
    monkeypatch.setattr("barhinge.scene.load_scene", _boom)
    with pytest.raises(ZeroDivisionError):
        main(["--debug", "fold", str(d / "s" / "ok.toml")])
    code, _, err = _run(["fold", str(d / "s" / "ok.toml")], capsys)  # no --debug this time
    assert code == 70 and err.startswith("internal error:")


def test_messages_keep_their_brackets(capsys, d):
    # square brackets in a message are printed as they are (rich would read "[0]" or
    # "[model]" as markup and drop them)
    code, _, err = _run(["fold", str(d / "s" / "targets_inf.toml")], capsys)
    assert code == 2 and "actuators.targets_deg[0] = inf" in err


def test_no_convergence_writes_partial_results(capsys, monkeypatch, d, tmp_path):
    monkeypatch.setenv("BARHINGE_PICTURES", "0")
    code, _, err = _run(
        ["fold", str(d / "s" / "no_convergence.toml"), "--out", str(tmp_path)], capsys
    )
    assert code == 3 and "partial results" in err and (tmp_path / "fold_path.npz").is_file()


def test_verify_list_honours_case(capsys):
    # --list used to list every case whatever --case said
    main(["verify", "--list", "--case", "miura_rigid", "--json"])
    assert list(json.loads(capsys.readouterr().out)) == ["miura_rigid"]
