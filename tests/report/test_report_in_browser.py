"""The report renders its figures in a real browser (headless Chromium), and
its text fits the page: no code, pre or table block runs past the column
(the transfer functions' denominators once hid behind a scroll bar), and
every image loads.

Chromium comes from Debian's packages (.ci/run installs it when it can);
without it the test is skipped and says why.
"""

import html
import json
import re
import shutil
import subprocess

import numpy as np
import pytest
from patience import allowance

from spiralid.report import write_reproduction
from spiralid.reproduction import reproduce

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")

pytestmark = pytest.mark.skipif(
    CHROMIUM is None,
    reason="headless Chromium not installed (Debian: apt-get install chromium; "
    ".ci/run installs it when run as root with apt available)",
)


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    """A small reproduction's report.html (every configuration)."""
    out = tmp_path_factory.mktemp("report") / "rep"
    rep = reproduce(seeds=range(2), max_nfev=300, n_points=10, workers=1)
    write_reproduction(rep, out)
    return out / "report.html"


def _chromium(*args, profile):
    proc = subprocess.run(
        [
            CHROMIUM,
            "--headless",
            "--no-sandbox",  # CI runs as root
            "--disable-gpu",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            f"--user-data-dir={profile}",
            *args,
        ],
        capture_output=True,
        text=True,
        timeout=allowance(120),  # a safety net only, see patience.py
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    return proc.stdout


def _screenshot(page, png):
    _chromium(
        "--hide-scrollbars",
        "--window-size=1000,9000",
        f"--screenshot={png}",
        page.as_uri(),
        profile=png.parent / "profile",
    )
    assert png.is_file()
    from matplotlib.image import imread

    return (imread(png)[..., :3] * 255).round().astype(int)


def _plot_pixels(image) -> int:
    """Pixels in matplotlib's first two line colours (C0 blue, C1 orange):
    the page's own text and tables are black, grey and white."""
    colours = np.array([[31, 119, 180], [255, 127, 14]])
    near = np.abs(image[:, :, None, :] - colours[None, None]).max(axis=-1) <= 30
    return int(near.any(axis=-1).sum())


def test_report_renders_its_figures(report, tmp_path):
    page = report
    with_figures = _plot_pixels(_screenshot(page, tmp_path / "page.png"))
    # The same page with its images removed: the colour test must tell them apart.
    bare = tmp_path / "bare.html"
    bare.write_text(re.sub(r"<img [^>]*>", "", page.read_text()))
    without = _plot_pixels(_screenshot(bare, tmp_path / "bare.png"))
    assert without < 50
    assert with_figures > 5000, (with_figures, without)


# Run in the page once it has loaded (images included): every pre, code and
# table block against the column (the body's content box). Text (pre, code)
# must show whole, wrapped if need be; a table may scroll inside a box of
# the column's width. The findings go into the page, read with --dump-dom.
_LAYOUT_CHECK = """
window.addEventListener("load", () => {
  const scrolls = (el) => ["auto", "scroll"].includes(getComputedStyle(el).overflowX);
  const body = document.body;
  const style = getComputedStyle(body);
  const rect = body.getBoundingClientRect();
  const left = rect.left + parseFloat(style.paddingLeft);
  const right = rect.right - parseFloat(style.paddingRight);
  const bad = [];
  for (const el of document.querySelectorAll("pre, code, table")) {
    let box = el;
    for (let p = el; p && p !== body; p = p.parentElement) {
      if (scrolls(p)) { box = p; break; }
    }
    const r = box.getBoundingClientRect();
    const what = el.tagName + ": " + el.textContent.slice(0, 60);
    if (r.left < left - 1 || r.right > right + 1) {
      bad.push([what, "outside the column", r.left, r.right]);
    }
    const strict = el.tagName !== "TABLE" || !scrolls(el);
    const inline = getComputedStyle(el).display === "inline";
    if (strict && !inline && el.scrollWidth > el.clientWidth + 1) {
      bad.push([what, "wider than its box", el.scrollWidth, el.clientWidth]);
    }
  }
  const images = [...document.images].map(
    (i) => [i.alt, i.complete && i.naturalWidth > 0]);
  const out = document.createElement("pre");
  out.id = "layout-check";
  out.textContent = JSON.stringify({bad, images, column: [left, right]});
  body.appendChild(out);
});
"""


def _layout(page, tmp_path, width):
    checked = tmp_path / f"checked-{width}.html"
    checked.write_text(
        page.read_text().replace("</body>", f"<script>{_LAYOUT_CHECK}</script></body>")
    )
    dom = _chromium(
        f"--window-size={width},2000",
        "--virtual-time-budget=10000",
        "--dump-dom",
        checked.as_uri(),
        profile=tmp_path / "profile",
    )
    found = re.search(r'<pre id="layout-check">(.*?)</pre>', dom, re.S)
    assert found, dom[-2000:]
    return json.loads(html.unescape(found.group(1)))


@pytest.mark.parametrize("width", [1400, 700])
def test_report_fits_its_column_and_loads_every_image(report, tmp_path, width):
    layout = _layout(report, tmp_path, width)
    assert layout["bad"] == [], layout
    pngs = sorted(p.stem for p in report.parent.glob("*.png"))
    assert len(layout["images"]) == len(pngs) == 6
    assert all(ok for _, ok in layout["images"]), layout["images"]


def test_layout_check_finds_a_block_wider_than_the_column(report, tmp_path):
    # The report's transfer functions as they were: one long line each in a
    # box that scrolled, the denominator out of sight.
    page = tmp_path / "old.html"
    long_line = "H(z) = (" + " + ".join(f"{k}.125 z^{k}" for k in range(40)) + ")"
    page.write_text(
        report.read_text().replace(
            "<pre class='tf'>",
            f"<pre style='white-space: pre; overflow-x: auto'>{long_line}</pre><pre>",
        )
    )
    bad = _layout(page, tmp_path, 1400)["bad"]
    assert [b[1] for b in bad] == ["wider than its box"], bad
