"""The built documentation site, read as a reader's browser shows it.

It checks the HTML that ``sphinx-build -W --keep-going -b html docs
docs/_build/html`` wrote (.ci/run builds it before running this module; the
tests skip, saying why, where it was not built): every public name of every
package has its entry on an API page, and in headless Chromium every image
of every page loads and no table or code block overflows its column.

The overflow rule: a table must fit its column whole (a results table whose
last columns hide behind a scroll bar is read wrong), and so must every code
block's box; a code block's *content* may be wider than the box only if the
block scrolls itself (``overflow-x: auto``), as a long command line must.

Chromium comes from Debian's packages (.ci/run installs it when it runs as
root); it is driven over the DevTools protocol on a pipe, one browser for
all pages.
"""

import fcntl
import importlib
import json
import os
import re
import select
import shutil
import subprocess
import types
from pathlib import Path

import pytest
from patience import allowance

ROOT = Path(__file__).resolve().parents[1]
SITE = ROOT / "docs" / "_build" / "html"
CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
PACKAGES = (
    "spiralid",
    "spiralid.sysid",
    "spiralid.optim",
    "spiralid.fms",
    "spiralid.datasets",
    "spiralid.study",
    "spiralid.reproduction",
    "spiralid.report",
    "spiralid.choices",
)
WIDTH, HEIGHT = 1280, 900  # a laptop's browser window

pytestmark = pytest.mark.skipif(
    not (SITE / "index.html").is_file(),
    reason="the documentation is not built (pip install -e '.[docs]'; "
    "sphinx-build -W --keep-going -b html docs docs/_build/html; .ci/run does)",
)
needs_chromium = pytest.mark.skipif(
    CHROMIUM is None,
    reason="headless Chromium not installed (Debian: apt-get install chromium; "
    ".ci/run installs it when run as root with apt available)",
)


def public_names(package: str) -> list[str]:
    """A package's public names: its ``__all__`` (every package has one)."""
    return list(importlib.import_module(package).__all__)


def _ids(page: Path) -> set[str]:
    return set(re.findall(r'\bid="([^"]+)"', page.read_text(encoding="utf-8")))


def test_every_public_name_has_an_api_entry():
    api = sorted((SITE / "api-generated").glob("*.html"))
    assert api, "no API pages were built"
    ids = set().union(*(_ids(page) for page in api))
    missing = []
    for package in PACKAGES:
        module = importlib.import_module(package)
        names = public_names(package)
        assert names, package
        for name in names:
            value = getattr(module, name)
            if isinstance(value, types.ModuleType):
                anchor = f"module-{value.__name__}"
            else:
                anchor = f"{package}.{name}"
            if anchor not in ids:
                missing.append(anchor)
    assert not missing, f"public names without an API entry: {missing}"


def test_the_api_index_links_every_package_page():
    text = (SITE / "api.html").read_text(encoding="utf-8")
    for package in PACKAGES:
        assert f'href="api-generated/{package}.html"' in text, package


class Browser:
    """Headless Chromium driven over ``--remote-debugging-pipe``: commands
    go in on the browser's descriptor 3, answers and events come out of 4,
    as JSON messages ended by a NUL byte."""

    def __init__(self, profile: Path):
        to_browser, self._to_browser = os.pipe()
        self._from_browser, from_browser = os.pipe()
        # Out of the way of 3 and 4, which the child's descriptors become.
        high_in = fcntl.fcntl(to_browser, fcntl.F_DUPFD, 10)
        high_out = fcntl.fcntl(from_browser, fcntl.F_DUPFD, 10)
        os.close(to_browser)
        os.close(from_browser)

        def descriptors():
            os.dup2(high_in, 3)
            os.dup2(high_out, 4)

        self.proc = subprocess.Popen(
            [
                CHROMIUM,
                "--headless",
                "--no-sandbox",  # CI runs as root
                "--disable-gpu",
                "--hide-scrollbars",
                "--remote-debugging-pipe",
                f"--user-data-dir={profile}",
                f"--window-size={WIDTH},{HEIGHT}",
                "about:blank",
            ],
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            preexec_fn=descriptors,
            pass_fds=(3, 4),
        )
        os.close(high_in)
        os.close(high_out)
        self._buffer = b""
        self._id = 0
        target = self.call("Target.createTarget", url="about:blank")["targetId"]
        self.session = self.call(
            "Target.attachToTarget", targetId=target, flatten=True
        )["sessionId"]
        self.call("Page.enable", session=self.session)
        self.call(
            "Emulation.setDeviceMetricsOverride",
            session=self.session,
            width=WIDTH,
            height=HEIGHT,
            deviceScaleFactor=1,
            mobile=False,
        )

    def _read(self) -> dict:
        while b"\0" not in self._buffer:
            # A safety net only (see patience.py): a page loads in well under
            # a second.
            wait = allowance(60)
            if not select.select([self._from_browser], [], [], wait)[0]:
                raise RuntimeError(f"Chromium did not answer in {wait:.0f} s")
            chunk = os.read(self._from_browser, 1 << 16)
            if not chunk:
                raise RuntimeError("Chromium closed its pipe")
            self._buffer += chunk
        message, self._buffer = self._buffer.split(b"\0", 1)
        return json.loads(message)

    def call(self, method: str, session: str | None = None, **params) -> dict:
        self._id += 1
        message = {"id": self._id, "method": method, "params": params}
        if session:
            message["sessionId"] = session
        os.write(self._to_browser, json.dumps(message).encode() + b"\0")
        while True:
            answer = self._read()
            if answer.get("id") == self._id:
                if "error" in answer:
                    raise RuntimeError(f"{method}: {answer['error']}")
                return answer["result"]

    def open(self, url: str) -> None:
        self._id += 1
        ask = self._id
        message = {
            "id": ask,
            "method": "Page.navigate",
            "params": {"url": url},
            "sessionId": self.session,
        }
        os.write(self._to_browser, json.dumps(message).encode() + b"\0")
        answered = loaded = False
        while not (answered and loaded):
            event = self._read()
            answered = answered or event.get("id") == ask
            loaded = loaded or event.get("method") == "Page.loadEventFired"

    def evaluate(self, expression: str):
        result = self.call(
            "Runtime.evaluate",
            session=self.session,
            expression=expression,
            awaitPromise=True,
            returnByValue=True,
        )
        if "exceptionDetails" in result:
            raise RuntimeError(result["exceptionDetails"])
        return result["result"]["value"]

    def close(self) -> None:
        try:
            self.call("Browser.close")
        except (RuntimeError, OSError):
            pass
        try:
            self.proc.wait(timeout=allowance(30))
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
        os.close(self._to_browser)
        os.close(self._from_browser)


# Run in each page once it has loaded: lazy images are made eager and
# decoded, then every image, table and code block of the article is measured.
CHECK = """
(async () => {
  const images = [...document.images];
  images.forEach((img) => { img.loading = "eager"; });
  await Promise.all(images.map((img) => img.decode().catch(() => null)));
  const broken = images
    .filter((img) => !(img.complete && img.naturalWidth > 0))
    .map((img) => img.getAttribute("src"));
  const column = document.querySelector("article.bd-article") || document.body;
  const edge = column.getBoundingClientRect();
  const style = getComputedStyle(column);
  const right = edge.right - parseFloat(style.paddingRight);
  const left = edge.left + parseFloat(style.paddingLeft);
  const overflowing = [];
  for (const block of column.querySelectorAll("table, pre")) {
    const box = block.getBoundingClientRect();
    if (box.width === 0) continue;  // not displayed
    const name = block.tagName.toLowerCase() + ": " +
      block.textContent.trim().replace(/\\s+/g, " ").slice(0, 60);
    if (box.right > right + 1 || box.left < left - 1) {
      overflowing.push(`${name} (box ${Math.round(box.width)} px, ` +
        `column ${Math.round(right - left)} px)`);
    } else if (block.tagName === "TABLE") {
      if (block.scrollWidth > block.clientWidth + 1) {
        overflowing.push(`${name} (content ${block.scrollWidth} px, ` +
          `box ${block.clientWidth} px)`);
      }
    } else if (block.scrollWidth > block.clientWidth + 1 &&
               !["auto", "scroll"].includes(getComputedStyle(block).overflowX)) {
      overflowing.push(`${name} (content ${block.scrollWidth} px, not scrollable)`);
    }
  }
  const page = document.documentElement.scrollWidth > window.innerWidth + 1;
  return {broken, overflowing, page, images: images.length};
})()
"""


@pytest.fixture(scope="module")
def pages(tmp_path_factory):
    """Every page of the site, measured in one browser."""
    browser = Browser(tmp_path_factory.mktemp("chromium-profile"))
    try:
        found = {}
        for page in sorted(SITE.rglob("*.html")):
            if page.name == "search.html" or "_static" in page.parts:
                continue
            browser.open(page.as_uri())
            found[page.relative_to(SITE).as_posix()] = browser.evaluate(CHECK)
        return found
    finally:
        browser.close()


@needs_chromium
def test_the_site_was_measured(pages):
    assert len(pages) > 50, sorted(pages)
    for page in ("index.html", "api.html", "design-notes.html"):
        assert page in pages
    # The figures: the reproduction's two and the gallery's thumbnails.
    assert pages["results/reproduction.html"]["images"] >= 2
    assert pages["auto_examples/index.html"]["images"] >= 1


@needs_chromium
def test_every_image_loads(pages):
    broken = {page: got["broken"] for page, got in pages.items() if got["broken"]}
    assert not broken


@needs_chromium
def test_no_table_or_code_block_overflows_its_column(pages):
    overflowing = {
        page: got["overflowing"] for page, got in pages.items() if got["overflowing"]
    }
    assert not overflowing
    assert not [page for page, got in pages.items() if got["page"]]
