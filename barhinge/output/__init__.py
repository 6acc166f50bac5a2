"""Everything barhinge writes about a fold path, in one place.

* ``run`` -- the one writer: the result folder of ``barhinge fold`` (:func:`write_run`) and
  the same files into any folder (:func:`write_results`);
* ``folder`` -- the atomic result folder and its manifest ``barhinge-run.json``;
* ``summary`` -- ``summary.json`` and the lines ``barhinge fold`` prints;
* ``table`` -- the step table ``states.csv``;
* ``modes`` -- one VTU per buckling or stiffness mode;
* ``pictures`` -- the standard pictures (drawn by :mod:`barhinge.plot`).

The fields on the mesh of a state and their VTU / XDMF files are :mod:`barhinge.fields`
(below the pictures and the viewer, which draw them); ``state_data`` and ``state_mesh`` are
also named here.

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
    "state_data": "barhinge.fields",
    "state_mesh": "barhinge.fields",
    "write_pictures": "pictures",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str) -> Any:
    if name in _EXPORTS:
        module = _EXPORTS[name]
        full = module if module.startswith("barhinge.") else f"barhinge.output.{module}"
        return getattr(importlib.import_module(full), name)
    raise AttributeError(f"module 'barhinge.output' has no attribute {name!r}")
