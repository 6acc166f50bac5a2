"""Everything barhinge writes about a fold path, in one place.

* ``run`` -- the one writer: the result folder of ``barhinge fold`` (:func:`write_run`) and
  the same files into any folder (:func:`write_results`);
* ``folder`` -- the atomic result folder and its manifest ``barhinge-run.json``;
* ``summary`` -- ``summary.json`` and the lines ``barhinge fold`` prints;
* ``table`` -- the step table ``states.csv``;
* ``fields`` -- fields on the mesh of a state, VTU and XDMF files (meshio);
* ``pictures`` -- the standard pictures (drawn by :mod:`barhinge.plot`).

docs/outputs.md lists every file with its columns and units. The names below load their
module on first use.
"""

from __future__ import annotations

import importlib
from typing import Any

_EXPORTS = {
    "RunOutput": "run",
    "write_results": "run",
    "write_run": "run",
    "MANIFEST": "folder",
    "add_to_manifest": "folder",
    "atomic_file": "folder",
    "check_output_folder": "folder",
    "read_manifest": "folder",
    "result_folder": "folder",
    "run_summary": "summary",
    "step_table": "table",
    "state_data": "fields",
    "state_mesh": "fields",
    "write_pictures": "pictures",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str) -> Any:
    if name in _EXPORTS:
        return getattr(importlib.import_module(f"barhinge.output.{_EXPORTS[name]}"), name)
    raise AttributeError(f"module 'barhinge.output' has no attribute {name!r}")
