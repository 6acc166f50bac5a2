"""One self-contained HTML file from a :class:`~barhinge.view.data.ViewData`: the mesh and
the numbers of the run as JSON with base64 typed arrays, what changes from state to state
(positions, fold angles, moments, energies) as one base64 block per state and array (decoded
by the viewer only when that state is shown), the viewer's script and style inline.

Positions are float32, or for large paths (:data:`QUANTISE_ABOVE` node-states) 16-bit
integers on a grid over the bounding box of the path (:func:`quantise_positions`): each
coordinate within half a grid step, ``extent / 131070``, of its value.

Nothing is fetched: a Content-Security-Policy in the file forbids every network request,
so the file opens the same from ``file://``, a mail attachment or a web server.
"""

from __future__ import annotations

import base64
import html
import json
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from barhinge.errors import ConfigError
from barhinge.view.data import ViewData

__all__ = [
    "QUANTISE_ABOVE",
    "quantise_positions",
    "state_blocks",
    "viewer_html",
    "viewer_payload",
]

#: node-states (nodes x states) above which ``precision="auto"`` stores 16-bit positions
QUANTISE_ABOVE = 200_000
_Q = 65535

_CSP = (
    "default-src 'none'; script-src 'unsafe-inline'; style-src 'unsafe-inline'; "
    "img-src data:; connect-src 'none'"
)


def _b64(a: np.ndarray, dtype: Any) -> str:
    return base64.b64encode(
        np.ascontiguousarray(a, dtype=np.dtype(dtype).newbyteorder("<")).tobytes()
    ).decode()


def _clean(v: Any) -> Any:
    if isinstance(v, np.generic):
        v = v.item()
    if isinstance(v, float) and not np.isfinite(v):
        return None
    return v


def _charts(d: ViewData) -> tuple[str, list[dict[str, Any]]]:
    """The x-axis (the control, as in the static charts) and the chart groups."""
    keys = list(d.series)
    angles = [k for k in keys if k.startswith("actuator") and k.endswith("angle (deg)")]
    moments = [k for k in keys if k.startswith("actuator") and k.endswith("moment")]
    x = d.x_label if d.x_label in d.series else "state"
    charts = []
    energy = [k for k in keys if k.startswith("energy")]
    if energy:
        charts.append({"title": "stored energy", "keys": energy})
    if angles:
        charts.append({"title": "actuator fold angles (deg)", "keys": angles})
    if moments:
        charts.append({"title": "actuator moments", "keys": moments})
    if "load factor" in d.series and x != "load factor":
        charts.append({"title": "load factor", "keys": ["load factor"]})
    if not charts:
        charts.append({"title": "state", "keys": ["state"]})
    return x, charts


def quantise_positions(X: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """16-bit positions on a grid over the bounding box of all states.

    Parameters
    ----------
    X : (n_states, n_nodes, 3) float

    Returns
    -------
    q : (n_states, n_nodes, 3) uint16
        ``X ~ lo + q * step``, with ``|X - (lo + q * step)| <= step / 2`` per coordinate.
    lo, step : (3,) float
        Lower corner of the box and grid step per axis (``(hi - lo) / 65535``; 1 where the
        box is flat in that axis).
    """
    X = np.asarray(X, float)
    lo = X.min(axis=(0, 1))
    ext = X.max(axis=(0, 1)) - lo
    step = np.where(ext > 0, ext / _Q, 1.0)
    q = np.clip(np.rint((X - lo) / step), 0, _Q).astype(np.uint16)
    return q, lo, step


def _quantised(d: ViewData, precision: str) -> bool:
    if precision not in ("auto", "float32", "uint16"):
        raise ConfigError(f"precision = {precision!r}; expected 'auto', 'float32' or 'uint16'")
    if precision == "auto":
        return d.X.shape[0] * d.X.shape[1] > QUANTISE_ABOVE
    return precision == "uint16"


def state_blocks(d: ViewData, precision: str = "auto") -> dict[str, list[str]]:
    """The per-state arrays, one base64 block per state: ``X`` (positions: float32, or
    uint16 with ``precision="uint16"`` or, under ``"auto"``, for large paths), ``F`` (fold
    angles in hundredths of a degree, int16: exact to the two decimals the viewer shows),
    ``M`` (crease moments, float32) and ``E`` (node energy densities, float32) where known."""
    if _quantised(d, precision):
        X = quantise_positions(d.X)[0]
        xs = [_b64(x, np.uint16) for x in X]
    else:
        xs = [_b64(x, np.float32) for x in d.X]
    fold = np.rint(np.clip(np.nan_to_num(d.fold_deg), -327, 327) * 100)
    out = {"X": xs, "F": [_b64(f, np.int16) for f in fold]}
    if d.moment is not None:
        out["M"] = [_b64(m, np.float32) for m in d.moment]
    if d.energy_density is not None:
        out["E"] = [_b64(e, np.float32) for e in d.energy_density]
    return out


def viewer_payload(d: ViewData, precision: str = "auto") -> dict[str, Any]:
    """The JSON the viewer script reads (arrays as base64 little-endian); the per-state
    arrays are in :func:`state_blocks`."""
    x_key, charts = _charts(d)
    n = d.X.shape[1]
    X = np.asarray(d.X, float)
    if _quantised(d, precision):
        _, lo, step = quantise_positions(X)
        positions = {"dtype": "uint16", "lo": lo.tolist(), "step": step.tolist()}
    else:
        positions = {"dtype": "float32"}
    out: dict[str, Any] = {
        "title": d.title,
        "n_states": d.n_states,
        "n_nodes": n,
        "positions": positions,
        "box": [X.min(axis=(0, 1)).tolist(), X.max(axis=(0, 1)).tolist()],
        "fold_absmax": float(np.abs(np.nan_to_num(d.fold_deg)).max(initial=0.0)),
        "blocks": [],
        "triangles": _b64(d.triangles, np.uint32),
        "bars": _b64(d.bars, np.uint32),
        "bar_L0": _b64(d.bar_L0, np.float32),
        "creases": _b64(d.creases, np.uint32),
        "assignment": [str(a) for a in d.assignment],
        "flat": _b64(d.flat, np.float32),
        "fixed": None if d.fixed is None or not d.fixed.any() else _b64(d.fixed, np.uint8),
        "loads": None if d.loads is None else _b64(d.loads, np.float32),
        "actuators": [int(e) for e in d.actuators],
        "series": {k: _b64(np.asarray(v, float), np.float64) for k, v in d.series.items()},
        "x_key": x_key,
        "charts": charts,
        "summary": {k: _clean(v) for k, v in d.summary.items()},
    }
    out["blocks"] = (
        ["X", "F"]
        + (["M"] if d.moment is not None else [])
        + (["E"] if d.energy_density is not None else [])
    )
    return out


def _asset(name: str) -> str:
    return resources.files("barhinge.view").joinpath(name).read_text(encoding="utf-8")


def viewer_html(d: ViewData, precision: str = "auto") -> str:
    """The whole HTML document of the viewer (``precision``: ``"auto"``, ``"float32"`` or
    ``"uint16"`` positions, see :func:`state_blocks`)."""
    data = json.dumps(viewer_payload(d, precision), separators=(",", ":")).replace("</", "<\\/")
    blocks = "\n".join(
        f'<script type="application/octet-stream" id="bh-{k}{s}">{b}</script>'
        for k, per_state in state_blocks(d, precision).items()
        for s, b in enumerate(per_state)
    )
    title = html.escape(d.title)
    n_charts = len(_charts(d)[1])
    canvases = "".join('<canvas class="chart"></canvas>' for _ in range(n_charts))
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<meta http-equiv="Content-Security-Policy" content="{_CSP}">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>{title} - barhinge viewer</title>
<style>{_asset("viewer.css")}</style></head>
<body>
<header><h1>{title}</h1><span id="msg"></span></header>
<main>
<section id="view3d"><canvas id="gl"></canvas><canvas id="bar"></canvas>
<p class="hint">drag: orbit &middot; right-drag or shift-drag: pan &middot; wheel: zoom &middot;
green: actuators &middot; black dots: supports &middot; purple: loads</p>
<nav><button id="play">&#9654; play</button>
<input id="state" type="range" min="0" max="0" step="1" value="0">
<span id="statelabel"></span>
<label>colour by <select id="mode"></select></label></nav>
<div id="charts">{canvases}</div></section>
<aside>
<h2>Crease pattern</h2>
<canvas id="cp"></canvas>
<p class="hint">red dashed: mountain &middot; blue: valley &middot; hover a crease for its data</p>
<h2>Run</h2><table id="summary"></table>
</aside>
</main>
<div id="tip"></div>
<script type="application/json" id="bh-data">{data}</script>
{blocks}
<script>{_asset("viewer.js")}</script>
</body></html>
"""


def write_html(d: ViewData, html_path: str | Path, precision: str = "auto") -> Path:
    """Write :func:`viewer_html` to ``html_path`` (UTF-8) and return the path."""
    p = Path(html_path)
    p.write_text(viewer_html(d, precision), encoding="utf-8")
    return p
