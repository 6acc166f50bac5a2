"""The HTML viewer (barhinge.view): the data it carries against the solver's own numbers, and
the file itself opened in headless Chromium with every network request blocked."""

from __future__ import annotations

import io
import shutil
import time
from pathlib import Path

import numpy as np
import pytest

import barhinge as bh
from barhinge.cli import main
from barhinge.fields import state_data
from barhinge.scene import default_scene
from barhinge.view import load_view_data, viewer_html, write_viewer
from barhinge.view.data import _node_area
from barhinge.view.html import quantise_positions

CHROMIUM = shutil.which("chromium")
DRIVER = shutil.which("chromedriver")


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """A short default-scene run written by ``barhinge fold``."""
    scene = default_scene()
    path = bh.solve(scene)
    from barhinge.output.run import write_run

    out = tmp_path_factory.mktemp("run") / "run"
    write_run(path, scene, out)
    return scene, path, out


def test_lumped_energy_is_the_stored_energy(run):
    """Node energy densities times node areas add up to the solver's stored energy."""
    scene, path, out = run
    d = load_view_data(out)
    area = _node_area(d.X[0], d.triangles)
    total = d.energy_density @ area
    np.testing.assert_allclose(total, path.energy, rtol=1e-9, atol=1e-14)
    # the same from the model directly
    dm = load_view_data(path, scene=scene)
    np.testing.assert_allclose(dm.energy_density, d.energy_density, rtol=1e-6, atol=1e-12)
    # crease moments: an actuator's is the solver's multiplier; any other crease's is its
    # fold spring's, k (rho - rho0) for the linear law
    np.testing.assert_array_equal(dm.moment[:, path.actuator_edges], path.actuator_moments)
    model = scene.model
    assert model.fold_law == "linear"
    h = np.flatnonzero((np.asarray(model.hinge_kind) == "fold") & (model.hinge_edge >= 0))
    h = h[~np.isin(model.hinge_edge[h], path.actuator_edges)]
    rho = model.hinge_angles(path.X[-1])[h]
    expect = model.hinge_k[h] * (rho - model.rest_angle[h])
    np.testing.assert_allclose(dm.moment[-1, model.hinge_edge[h]], expect, rtol=1e-9, atol=1e-15)


def test_run_writer_view_from_its_states_is_the_view_read_back(run):
    """The run writer hands the viewer the fields it wrote instead of reading its VTU files
    back: the view is the same."""
    from barhinge.fields import path_state_data

    scene, path, out = run
    states = path_state_data(path, model=scene.model, pattern=scene.model.pattern)
    given = load_view_data(out, pattern=scene.model.pattern, states=states)
    read = load_view_data(out)
    np.testing.assert_array_equal(given.energy_density, read.energy_density)
    np.testing.assert_array_equal(given.triangles, read.triangles)
    np.testing.assert_array_equal(given.bars, read.bars)
    np.testing.assert_array_equal(given.bar_L0, read.bar_L0)


def test_file_is_small_and_self_contained(run):
    _, _, out = run
    html = viewer_html(out)
    assert len(html.encode()) < 5e6
    for url in ("http://", "https://", "src=", "href="):
        assert url not in html.replace("http://www.w3.org", "")


def test_cli_writes_the_viewer_and_bad_paths_exit_2(run, tmp_path, capsys):
    _, _, out = run
    with pytest.raises(SystemExit) as e:
        main(["view", str(tmp_path / "missing")])
    assert e.value.code == 2
    assert "does not exist" in capsys.readouterr().err
    main(["view", str(out), "--output", str(tmp_path / "v.html")])
    assert (tmp_path / "v.html").stat().st_size > 10_000


def test_foldpath_rich_display(run):
    _, path, _ = run
    assert path._repr_html_().startswith("<iframe srcdoc=")


def test_quantised_positions_within_half_a_step():
    """16-bit positions: every coordinate within half a grid step of its value, the step is
    the bounding box of the path / 65535, and the corners of the box are exact."""
    rng = np.random.default_rng(3)
    X = rng.normal(size=(4, 500, 3)) * [10.0, 1.0, 1e-3] + [5.0, -2.0, 0.0]
    q, lo, step = quantise_positions(X)
    assert q.dtype == np.uint16
    np.testing.assert_allclose(step, (X.max(axis=(0, 1)) - X.min(axis=(0, 1))) / 65535)
    err = np.abs(lo + q * step - X)
    assert (err <= 0.5 * step * (1 + 1e-9)).all()
    assert q.min() == 0 and q.max() == 65535
    # a flat axis (a sheet in its plane) stays exact
    X[..., 2] = 0.25
    q, lo, step = quantise_positions(X)
    assert step[2] == 1.0 and np.all(lo[2] + q[..., 2] * step[2] == 0.25)


# --------------------------------------------------------------------------- the browser
@pytest.fixture(scope="module")
def browser():
    if not (CHROMIUM and DRIVER):
        pytest.skip("chromium / chromedriver not installed (.ci/run installs them)")
    pytest.importorskip("selenium.webdriver")
    drv = open_browser()
    yield drv
    drv.quit()


def open_browser():
    """Headless Chromium (Debian's chromium + chromium-driver) with the network off."""
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    opt = webdriver.ChromeOptions()
    for a in ("--headless=new", "--no-sandbox", "--enable-unsafe-swiftshader",
              "--use-angle=swiftshader", "--window-size=1280,1000", "--force-device-scale-factor=1",
              "--proxy-server=127.0.0.1:9", "--host-resolver-rules=MAP * ~NOTFOUND"):  # fmt: skip
        opt.add_argument(a)
    opt.binary_location = CHROMIUM
    opt.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    drv = webdriver.Chrome(service=Service(DRIVER), options=opt)
    drv.execute_cdp_cmd("Network.enable", {})
    drv.execute_cdp_cmd(
        "Network.emulateNetworkConditions",
        {"offline": True, "latency": 0, "downloadThroughput": 0, "uploadThroughput": 0},
    )
    return drv


def _canvas(drv, element_id: str) -> np.ndarray:
    from PIL import Image

    png = drv.find_element("id", element_id).screenshot_as_png
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), dtype=np.int16)


def _open(drv, html: Path):
    drv.get(html.as_uri())
    assert drv.execute_script("return window.barhingeViewer && window.barhingeViewer.ready")
    return drv.execute_script("return window.barhingeViewer")


def shots(drv, html: Path, folder: Path | None = None) -> dict[str, np.ndarray]:
    """The test's pictures (also saved as docs/img/viewer.png by scripts/viewer_screenshots.py)."""
    _open(drv, html)
    out = {}
    drv.execute_script("barhingeViewer.setMode('fold'); barhingeViewer.setState(0)")
    out["state0"] = _canvas(drv, "gl")
    drv.execute_script(
        "barhingeViewer.setState(barhingeViewer_last())".replace(
            "barhingeViewer_last()", str(int(drv.find_element("id", "state").get_attribute("max")))
        )
    )
    out["last"] = _canvas(drv, "gl")
    if folder is not None:
        drv.save_screenshot(str(folder / "viewer.png"))
    drv.execute_script("barhingeViewer.setMode('strain')")
    out["strain"] = _canvas(drv, "gl")
    drv.execute_script("barhingeViewer.setMode('fold')")
    return out


def test_viewer_in_chromium(run, browser, tmp_path):
    from selenium.webdriver.common.action_chains import ActionChains

    scene, path, out = run
    html = write_viewer(out, tmp_path / "viewer.html")
    pics = shots(browser, html)
    # no console errors, nothing fetched
    logs = [m for m in browser.get_log("browser") if m["level"] == "SEVERE"]
    assert logs == []
    assert browser.execute_script("return performance.getEntriesByType('resource').length") == 0

    # the slider moves the sheet: pixels change, and only where the sheet is in either state
    a, b = pics["state0"], pics["last"]
    white = np.array([255, 255, 255])
    bg_a, bg_b = (np.abs(a - white).sum(2) < 6), (np.abs(b - white).sum(2) < 6)
    changed = np.abs(a - b).sum(2) > 24
    assert changed.mean() > 0.01
    assert not (changed & bg_a & bg_b).any()  # background in both: unchanged
    # the colour mode changes colours of the sheet, not its outline
    c = pics["strain"]
    recoloured = np.abs(b - c).sum(2) > 24
    assert recoloured.mean() > 0.01
    assert np.array_equal(np.abs(c - white).sum(2) < 6, bg_b)

    # JS fields against Python's: bar strain, Gaussian curvature (angle defect / mixed area)
    s = path.n_states - 1
    d = state_data(path.X[s], model=scene.model, X_ref=path.X[0])
    js_k = np.array(browser.execute_script(f"return barhingeViewer.field('gaussian', {s})"),
                    dtype=float)  # fmt: skip
    py_k = d.point_data["defect_density"]
    ok = np.isfinite(py_k)
    np.testing.assert_array_equal(np.isfinite(js_k), ok)
    np.testing.assert_allclose(js_k[ok], py_k[ok], rtol=1e-3, atol=1e-3 * np.abs(py_k[ok]).max())

    # hover a crease of the 2-D pattern: its id, assignment, fold angle and moment
    e = int(path.actuator_edges[0])
    x, y = browser.execute_script(f"return barhingeViewer.creasePoint({e})")
    cp = browser.find_element("id", "cp")
    w, h = cp.size["width"], cp.size["height"]
    ActionChains(browser).move_to_element_with_offset(cp, x - w / 2, y - h / 2).perform()
    tip = browser.find_element("id", "tip").text
    assert f"crease {e} (actuator)" in tip
    assert f"assignment {scene.model.pattern.assignment[e]}" in tip
    assert f"fold angle {np.rint(path.fold_angles_deg[s, e] * 100) / 100:.2f}" in tip
    assert "moment" in tip and "moment \u2013" not in tip


def test_uint16_positions_in_chromium(run, browser, tmp_path):
    """A file with 16-bit positions: the browser's positions are the solver's within the
    quantisation bound (half a grid step per axis, plus float32 rounding), and the file is
    smaller than with float32 positions."""
    _, path, out = run
    small = write_viewer(out, tmp_path / "q.html", precision="uint16")
    full = write_viewer(out, tmp_path / "f.html", precision="float32")
    assert small.stat().st_size < full.stat().st_size
    _open(browser, small)
    assert [m for m in browser.get_log("browser") if m["level"] == "SEVERE"] == []
    _, lo, step = quantise_positions(path.X)
    for s in (0, path.n_states - 1):
        js = np.array(browser.execute_script(f"return barhingeViewer.positions({s})"), float)
        err = np.abs(js.reshape(-1, 3) - path.X[s])
        bound = 0.5 * step + 2.0**-23 * (np.abs(path.X[s]) + np.abs(lo)) * 2
        assert (err <= bound).all(), float((err / bound).max())
    eps = browser.execute_script("return barhingeViewer.eps")
    assert eps == pytest.approx(0.5 * float(np.linalg.norm(step)))


def test_jupyter_shows_the_viewer(browser, tmp_path):
    """A notebook run by a real kernel (nbclient): a FoldPath as the last expression of a
    cell displays the viewer as text/html; that iframe, loaded in Chromium, runs the viewer
    (no console error, pixels drawn)."""
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    pytest.importorskip("ipykernel")
    code = (
        "import numpy as np\n"
        "import barhinge as bh\n"
        "from barhinge.results import FoldPath\n"
        "cps = [bh.families.miura(nx=2, ny=2, fold=t) for t in (10.0, 50.0)]\n"
        "path = FoldPath(X=np.stack([c.vertices3d for c in cps]),\n"
        "                fold_angles_deg=np.stack([c.fold_angles for c in cps]), kind='rigid')\n"
        "path"
    )
    nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(code)])
    nbclient.NotebookClient(nb, timeout=120, kernel_name="python3").execute()
    outputs = nb.cells[0].outputs
    html = next(o["data"]["text/html"] for o in outputs if "text/html" in o.get("data", {}))
    assert html.startswith("<iframe srcdoc=")
    page = tmp_path / "notebook_output.html"
    page.write_text(f"<!DOCTYPE html><html><body>{html}</body></html>", encoding="utf-8")
    browser.get(page.as_uri())
    try:
        # the frame's document may still be loading after the page's load event (and the
        # frame handle may then point at its first, blank document): look again until ready
        deadline = time.monotonic() + 30
        while True:
            browser.switch_to.default_content()
            browser.switch_to.frame(browser.find_element("tag name", "iframe"))
            js = "return !!(window.barhingeViewer && barhingeViewer.ready && barhingeViewer.drawn)"
            if browser.execute_script(js) or time.monotonic() > deadline:
                break
            time.sleep(0.2)
        assert browser.execute_script(js), browser.get_log("browser")
        assert browser.execute_script("return barhingeViewer.state") == 1
        img = _canvas(browser, "gl")
        assert (np.abs(img - 255).sum(axis=2) > 24).mean() > 0.01  # the sheet is drawn
    finally:
        browser.switch_to.default_content()
    assert [m for m in browser.get_log("browser") if m["level"] == "SEVERE"] == []
