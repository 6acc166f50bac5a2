"""The viewer's pictures in docs/img: the default scene solved, its viewer opened in headless
Chromium offline (the same steps as tests/test_viewer.py), screenshots saved.

    python scripts/viewer_screenshots.py          # writes docs/img/viewer.png
"""

from __future__ import annotations

import importlib.util
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    import barhinge as bh
    from barhinge.output.run import write_run
    from barhinge.scene import default_scene
    from barhinge.view import write_viewer

    spec = importlib.util.spec_from_file_location("test_viewer", ROOT / "tests/test_viewer.py")
    tv = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(tv)
    scene = default_scene()
    path = bh.solve(scene)
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "run"
        write_run(path, scene, out)
        html = write_viewer(out, Path(tmp) / "viewer.html")
        drv = tv.open_browser()
        try:
            tv.shots(drv, html, ROOT / "docs/img")
        finally:
            drv.quit()
    print(f"wrote {ROOT / 'docs/img/viewer.png'}", file=sys.stderr)


if __name__ == "__main__":
    main()
