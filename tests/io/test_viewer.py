"""The HTML viewer (pyevolver.io.viewer): its data, its clipped colour
ranges, the datafile's facet colours, and a headless browser that opens it
and finds the mesh drawn (Debian's chromium and chromium-driver, installed
by .ci/run; skipped only where no browser is installed outside CI)."""
import io
import json
import os
import re
import shutil

import numpy as np
import pytest

from pyevolver import Session
from pyevolver.errors import CommandError
from pyevolver.io.fields import clipped_range, facet_colors
from pyevolver.io.viewer import viewer_data, write_viewer

CUBE = os.path.join(os.path.dirname(__file__), "..", "..", "datafiles", "cube.fe")


def _cube():
    return Session.load(CUBE, out=io.StringIO())


def test_clipped_range_leaves_out_a_few_extreme_values():
    v = np.r_[np.linspace(0.0, 1.0, 54), [-500.0] * 6]       # 10% at a fixed boundary
    a, b = clipped_range(v)
    assert -3.1 <= a <= 0.0 and 0.97 <= b <= 1.0, (a, b)
    smooth = np.linspace(-1.0, 1.0, 101)
    a, b = clipped_range(smooth)
    assert a == pytest.approx(-0.96) and b == pytest.approx(0.96)
    assert clipped_range(np.ones(5))[0] < 1.0 < clipped_range(np.ones(5))[1]
    assert clipped_range(np.array([np.nan])) == (0.0, 1.0)


def test_viewer_data_is_centred_in_the_unit_ball_and_has_every_facet():
    s = _cube()
    s.run("g 3")
    d = viewer_data(s.surface)
    X = np.array(d["X"]).reshape(-1, 3)
    assert X.shape == (s.surface.nv, 3)
    assert np.max(np.linalg.norm(X, axis=1)) == pytest.approx(1.0, abs=1e-4)
    assert np.allclose((X.min(axis=0) + X.max(axis=0)) / 2, 0, atol=1e-4)
    assert len(d["F"]) == 3 * s.surface.nf
    assert "vertex mean_curvature" in d["fields"] and "facet area" in d["fields"]
    assert all(len(f["values"]) == s.surface.nf for f in d["fields"].values())
    assert "colors" not in d                          # cube.fe sets no facet colours


def test_facet_colours_of_the_datafile():
    s = _cube()
    s.run("set facet color red where id <= 4")
    col = facet_colors(s.surface)
    assert col is not None and col.shape == (s.surface.nf, 3)
    red = np.array([1.0, 0.0, 0.0])
    ids = np.asarray(s.surface.ids("facet"))
    assert np.allclose(col[ids <= 4], red) and not np.allclose(col[ids > 4], red)
    assert "colors" in viewer_data(s.surface)


def test_write_viewer_is_one_self_contained_file(tmp_path):
    s = _cube()
    path = write_viewer(s.surface, str(tmp_path / "cube.html"), title="cube <1>")
    text = open(path, encoding="utf-8").read()
    assert "cube &lt;1&gt;" in text
    assert not re.search(r"<script[^>]+src=|<link[^>]+href=|https?://", text)
    data = json.loads(re.search(r"const DATA = (\{.*?\});\n", text).group(1))
    assert len(data["F"]) == 3 * s.surface.nf


def test_no_facets_no_viewer(tmp_path):
    string = tmp_path / "s.fe"
    string.write_text("STRING\nSPACE_DIMENSION 2\nvertices\n1 0 0\n2 1 0\nedges\n1 1 2\n")
    s = Session.load(str(string), out=io.StringIO())
    with pytest.raises(CommandError, match="no facets"):
        write_viewer(s.surface, str(tmp_path / "x.html"))
    assert not (tmp_path / "x.html").exists()


# -- a real browser ------------------------------------------------------------------------

def _browser():
    chrome = shutil.which("chromium") or shutil.which("chromium-browser")
    driver = shutil.which("chromedriver")
    try:
        import selenium  # noqa: F401
    except ImportError:
        chrome = None
    if not chrome or not driver:
        if os.environ.get("CI", "").lower() == "true":
            pytest.fail("chromium, chromium-driver and selenium are needed: .ci/run installs "
                        "them (apt-get install chromium chromium-driver; the test extra)")
        pytest.skip("no headless browser (chromium, chromedriver, selenium) installed")
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service
    opts = webdriver.ChromeOptions()
    opts.binary_location = chrome
    for a in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
              "--window-size=800,640"):
        opts.add_argument(a)
    return webdriver.Chrome(service=Service(driver), options=opts)


_PIXELS = """
const cv = document.getElementById('view'), W = cv.width, H = cv.height;
const d = cv.getContext('2d').getImageData(0, 0, W - 90, H).data;
let drawn = 0; const colours = new Set();
for (let i = 0; i < d.length; i += 4) {
  if (d[i] < 250 || d[i + 1] < 250 || d[i + 2] < 250) { drawn++; colours.add(d[i] << 16 | d[i + 1] << 8 | d[i + 2]); }
}
return [drawn, (W - 90) * H, colours.size, window.pyevolverDrawn || 0];
"""


def test_a_headless_browser_draws_the_mesh(tmp_path):
    s = _cube()
    s.run("r")
    path = write_viewer(s.surface, str(tmp_path / "cube.html"), title="cube")
    drv = _browser()
    try:
        drv.get("file://" + path)
        drawn, total, colours, nf = drv.execute_script(_PIXELS)
        assert nf == s.surface.nf
        assert drawn > 0.1 * total, (drawn, total)          # the cube fills the view
        assert colours >= 16, colours                       # shaded and coloured
        # rotating changes the picture; "none" paints it grey
        before = drv.execute_script("return document.getElementById('view').toDataURL()")
        drv.execute_script("yaw += 0.7; draw();")
        assert drv.execute_script("return document.getElementById('view').toDataURL()") != before
        drv.execute_script("const s = document.getElementById('field'); s.value = 'none';"
                           "s.dispatchEvent(new Event('change'));")
        assert drv.execute_script(_PIXELS)[0] > 0.1 * total
    finally:
        drv.quit()


def test_a_session_displays_itself_in_a_notebook():
    import html as H

    from pyevolver.io.viewer import viewer_html
    s = _cube()
    frame = s._repr_html_()
    assert frame.startswith('<iframe srcdoc="') and frame.endswith("</iframe>")
    page = H.unescape(frame[len('<iframe srcdoc="'):frame.index('" width=')])
    assert page == viewer_html(s.surface, title=repr(s))
    assert "<canvas" in page and "&lt;Session" in page
