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

#: public name -> the module that defines it
_EXPORTS = {
    "RunOutput": "barhinge.output.run",
    "write_results": "barhinge.output.run",
    "write_run": "barhinge.output.run",
    "MANIFEST": "barhinge.output.folder",
    "add_to_manifest": "barhinge.output.folder",
    "atomic_file": "barhinge.output.folder",
    "check_output_folder": "barhinge.output.folder",
    "read_manifest": "barhinge.output.folder",
    "result_folder": "barhinge.output.folder",
    "run_summary": "barhinge.output.summary",
    "step_table": "barhinge.output.table",
    "state_data": "barhinge.fields",
    "state_mesh": "barhinge.fields",
    "write_pictures": "barhinge.output.pictures",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str) -> Any:
    if name in _EXPORTS:
        return getattr(importlib.import_module(_EXPORTS[name]), name)
    raise AttributeError(f"module 'barhinge.output' has no attribute {name!r}")
