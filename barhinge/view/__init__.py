"""The fold-path viewer: one self-contained HTML file (WebGL2 and a 2-D canvas, no library,
nothing fetched) with the folded sheet, a slider over the states, colour modes, the crease
pattern linked to it and the charts of the run. See docs/viewer.md.

:func:`write_viewer` writes the file; :func:`viewer_html` returns the text (the Jupyter
display of a :class:`~barhinge.FoldPath` puts it in an iframe).
"""

from __future__ import annotations

import html as _html
from pathlib import Path
from typing import Any

from barhinge.view.data import ViewData, load_view_data, view_data
from barhinge.view.html import viewer_html as _viewer_html
from barhinge.view.html import write_html

__all__ = ["ViewData", "iframe_html", "load_view_data", "view_data", "viewer_html", "write_viewer"]


def viewer_html(source: Any, precision: str = "auto", **kwargs: Any) -> str:
    """The viewer of ``source`` (see :func:`write_viewer`) as one HTML string."""
    return _viewer_html(load_view_data(source, **kwargs), precision)


def write_viewer(
    source: Any, html_path: str | Path, precision: str = "auto", **kwargs: Any
) -> Path:
    """Write the viewer of a fold path to one self-contained HTML file.

    Parameters
    ----------
    source : path, FoldPath or ViewData
        A result folder of ``barhinge fold``, a ``fold_path.npz`` (with its ``.fold``
        beside it), a FOLD file with ``file_frames``, or a :class:`~barhinge.FoldPath`
        with ``model=``, ``scene=`` or ``pattern=``.
    html_path : path
        The file to write (its folder must exist).
    precision : {"auto", "float32", "uint16"}
        Positions as float32, or as 16-bit integers on a grid over the path's bounding box
        (each coordinate within ``extent / 131070`` of its value; the file's positions are
        half the size). ``"auto"``: 16-bit above
        :data:`~barhinge.view.html.QUANTISE_ABOVE` node-states.
    **kwargs
        ``model``, ``scene``, ``pattern``, ``fixed``, ``loads``, ``title`` for a FoldPath;
        ``pattern`` and ``states`` for a result folder (the crease pattern of its
        ``fold_path.fold`` and the :class:`~barhinge.fields.StateData` of its VTU
        files, which are then not read back).

    Returns
    -------
    Path of the written file.

    Raises
    ------
    ConfigError
        The source is missing or not a fold path, or the path and its pattern disagree.
    """
    return write_html(load_view_data(source, **kwargs), html_path, precision)


def iframe_html(source: Any, height: int = 760, **kwargs: Any) -> str:
    """The viewer inside an ``<iframe srcdoc=...>`` (for Jupyter's rich display)."""
    doc = _html.escape(viewer_html(source, **kwargs), quote=True)
    return (
        f'<iframe srcdoc="{doc}" style="width:100%;height:{height}px;border:0" '
        'sandbox="allow-scripts"></iframe>'
    )
