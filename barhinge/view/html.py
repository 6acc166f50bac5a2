"""One self-contained HTML file from a :class:`~barhinge.view.data.ViewData`: the data as
JSON with base64 typed arrays (float32 positions), the viewer's script and style inline.

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

from barhinge.view.data import ViewData

__all__ = ["viewer_html", "viewer_payload"]

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


def viewer_payload(d: ViewData) -> dict[str, Any]:
    """The JSON the viewer script reads (arrays as base64 little-endian)."""
    x_key, charts = _charts(d)
    n = d.X.shape[1]
    out: dict[str, Any] = {
        "title": d.title,
        "n_states": d.n_states,
        "n_nodes": n,
        "X": _b64(d.X, np.float32),
        "triangles": _b64(d.triangles, np.uint32),
        "bars": _b64(d.bars, np.uint32),
        "bar_L0": _b64(d.bar_L0, np.float32),
        "creases": _b64(d.creases, np.uint32),
        "assignment": [str(a) for a in d.assignment],
        "flat": _b64(d.flat, np.float32),
        # fold angles in hundredths of a degree (int16): half the size of float32, exact
        # to the two decimals the viewer shows
        "fold_cdeg": _b64(np.rint(np.clip(np.nan_to_num(d.fold_deg), -327, 327) * 100), np.int16),
        "moment": None if d.moment is None else _b64(d.moment, np.float32),
        "energy_density": None if d.energy_density is None else _b64(d.energy_density, np.float32),
        "fixed": None if d.fixed is None or not d.fixed.any() else _b64(d.fixed, np.uint8),
        "loads": None if d.loads is None else _b64(d.loads, np.float32),
        "actuators": [int(e) for e in d.actuators],
        "series": {k: _b64(np.asarray(v, float), np.float64) for k, v in d.series.items()},
        "x_key": x_key,
        "charts": charts,
        "summary": {k: _clean(v) for k, v in d.summary.items()},
    }
    return out


def _asset(name: str) -> str:
    return resources.files("barhinge.view").joinpath(name).read_text(encoding="utf-8")


def viewer_html(d: ViewData) -> str:
    """The whole HTML document of the viewer."""
    data = json.dumps(viewer_payload(d), separators=(",", ":")).replace("</", "<\\/")
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
<script>{_asset("viewer.js")}</script>
</body></html>
"""


def write_html(d: ViewData, html_path: str | Path) -> Path:
    """Write :func:`viewer_html` to ``html_path`` (UTF-8) and return the path."""
    p = Path(html_path)
    p.write_text(viewer_html(d), encoding="utf-8")
    return p
