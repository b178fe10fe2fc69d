"""The report renders its figures in a real browser (headless Chromium).

Chromium comes from Debian's packages (.ci/run installs it when it can);
without it the test is skipped and says why.
"""

import re
import shutil
import subprocess

import numpy as np
import pytest
from patience import allowance

from spiralid.report import reproduce, write_reproduction

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")

pytestmark = pytest.mark.skipif(
    CHROMIUM is None,
    reason="headless Chromium not installed (Debian: apt-get install chromium; "
    ".ci/run installs it when run as root with apt available)",
)


def _screenshot(page, png):
    proc = subprocess.run(
        [
            CHROMIUM,
            "--headless",
            "--no-sandbox",  # CI runs as root
            "--disable-gpu",
            "--hide-scrollbars",
            "--window-size=1000,9000",
            f"--screenshot={png}",
            page.as_uri(),
        ],
        capture_output=True,
        text=True,
        timeout=allowance(120),  # a safety net only, see patience.py
    )
    assert proc.returncode == 0 and png.is_file(), proc.stderr[-2000:]
    from matplotlib.image import imread

    return (imread(png)[..., :3] * 255).round().astype(int)


def _plot_pixels(image) -> int:
    """Pixels in matplotlib's first two line colours (C0 blue, C1 orange):
    the page's own text and tables are black, grey and white."""
    colours = np.array([[31, 119, 180], [255, 127, 14]])
    near = np.abs(image[:, :, None, :] - colours[None, None]).max(axis=-1) <= 30
    return int(near.any(axis=-1).sum())


def test_report_renders_its_figures(tmp_path):
    rep = reproduce(seeds=range(2), max_nfev=300, n_points=10, workers=1)
    write_reproduction(rep, tmp_path / "rep")
    page = tmp_path / "rep" / "report.html"
    with_figures = _plot_pixels(_screenshot(page, tmp_path / "page.png"))
    # The same page with its images removed: the colour test must tell them apart.
    bare = tmp_path / "bare.html"
    bare.write_text(re.sub(r"<img [^>]*>", "", page.read_text()))
    without = _plot_pixels(_screenshot(bare, tmp_path / "bare.png"))
    assert without < 50
    assert with_figures > 5000, (with_figures, without)
