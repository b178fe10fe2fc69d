"""Sphinx configuration of spiralid's documentation site.

Build it with ``sphinx-build -W --keep-going -b html docs docs/_build/html``
(the ``docs`` extra installs what it needs). The API pages are written at
build time from each package's ``__all__`` into ``docs/api-generated/``, so
a name added to a package's public list gets its page without editing
anything here.
"""

import ast
import importlib
import inspect
import os
import pprint
import re
import sys
import types
from pathlib import Path

# The gallery's scripts draw figures without a display.
os.environ["MPLBACKEND"] = "Agg"
# One BLAS thread, as the spiralid command runs: the examples' linear
# algebra is small, and a threaded OpenBLAS made the reproduction example
# several times slower on a loaded 2-core machine. Set before NumPy loads.
for _name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "src"))

project = "spiralid"
author = "spiralid developers"
copyright = "spiralid developers, BSD 3-Clause"
try:
    from importlib.metadata import version as _version

    release = _version("spiralid")
except Exception:  # a source tree without install
    release = "0.0.0+unknown"
version = release

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "**.ipynb_checkpoints", "auto_examples/*.ipynb"]
templates_path = ["_templates"]

# --- API reference -----------------------------------------------------------
autosummary_generate = True
toc_object_entries_show_parents = "hide"  # "simulate()", not "Model.simulate()"
autosummary_imported_members = True
autodoc_typehints = "none"  # the numpydoc sections give the types
autodoc_member_order = "bysource"
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False
numpydoc_validation_checks: set[str] = set()

# --- Markdown ----------------------------------------------------------------
myst_enable_extensions = ["dollarmath"]
myst_heading_anchors = 3

# --- Gallery -----------------------------------------------------------------
sphinx_gallery_conf = {
    "examples_dirs": "../examples",
    "gallery_dirs": "auto_examples",
    # Every plot_*.py runs at build time, and a failing one fails the build.
    "filename_pattern": re.escape(os.sep) + r"plot_.*\.py$",
    "ignore_pattern": r"__init__\.py",
    "within_subsection_order": "FileNameSortKey",
    "image_scrapers": ("matplotlib",),
    "remove_config_comments": True,
    "download_all_examples": False,
    "show_memory": False,
}

# --- HTML --------------------------------------------------------------------
html_theme = "pydata_sphinx_theme"
html_title = f"spiralid {release}"
html_static_path = ["_static"]
html_css_files = ["spiralid.css"]
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "secondary_sidebar_items": ["page-toc"],
    "footer_start": ["copyright"],
    "footer_end": ["sphinx-version"],
}
html_show_sourcelink = False
# The results pages' tables take the page's whole width: no navigation
# column (the header links every page), and no page contents column (their
# front matter removes it).
html_sidebars = {"results/*": []}

# --- API pages from __all__ --------------------------------------------------
# The packages whose public names the reference lists, with a line on each.
PACKAGES = {
    "spiralid": "The names a script usually needs, at the top level.",
    "spiralid.sysid": "Records, model structures, estimation and validation.",
    "spiralid.optim": "The spiral optimisers, restarts, DE and the Pareto search.",
    "spiralid.fms": "The finite-element flexible manipulator rig and its signals.",
    "spiralid.datasets": "Data shipped with the package and the record reader.",
    "spiralid.study": "Studies over every reading of the paper's cost (Dask).",
    "spiralid.reproduction": "The paper's SDA vs Eb-SDA experiment, computed.",
    "spiralid.report": "The reproduction's and study's figures, HTML and files.",
    "spiralid.choices": "The names a user chooses among, in one light module.",
}


def public_names(package: str) -> list[str]:
    """A package's public names: its ``__all__``."""
    return list(importlib.import_module(package).__all__)


def _kind(value) -> str:
    if isinstance(value, types.ModuleType):
        return "Modules"
    if inspect.isclass(value):
        return "Classes"
    if callable(value):
        return "Functions"
    return "Data"


def _summary(value) -> str:
    doc = inspect.getdoc(value) or ""
    first = doc.strip().split("\n\n")[0].replace("\n", " ")
    return first.replace("|", r"\|")


class _Printer(pprint.PrettyPrinter):
    """Values as a reader wants them: classes and functions by name."""

    def format(self, obj, context, maxlevels, level):
        if inspect.isclass(obj) or inspect.isfunction(obj):
            return obj.__qualname__.replace("<lambda>", "lambda"), True, False
        if isinstance(obj, Path):
            return repr(obj.name), True, False
        return super().format(obj, context, maxlevels, level)


class _Elided:
    def __init__(self, value):
        self.text = f"{type(value).__name__}(...)"

    def __repr__(self) -> str:
        return self.text


def _value_text(value) -> str:
    printer = _Printer(width=72, compact=True, sort_dicts=False)
    text = printer.pformat(value)
    if isinstance(value, dict) and len(text) > 1200:  # the keys, values elided
        text = printer.pformat({k: _Elided(v) for k, v in value.items()})
    return text


def _comment_above(package: str, name: str, value) -> str:
    """The ``#`` comment right above the module-level assignment that made
    ``value``, searched in the package's own files."""
    module = importlib.import_module(package)
    base = Path(importlib.import_module("spiralid").__file__).parent.parent
    if hasattr(module, "__path__"):
        files = sorted(Path(module.__file__).parent.rglob("*.py"))
    else:
        files = [Path(module.__file__)]
    for path in files:
        source = path.read_text(encoding="utf-8")
        for node in ast.parse(source).body:
            targets = (
                (node.targets if isinstance(node, ast.Assign) else [node.target])
                if isinstance(node, ast.Assign | ast.AnnAssign)
                else []
            )
            if not any(isinstance(t, ast.Name) and t.id == name for t in targets):
                continue
            relative = path.relative_to(base).with_suffix("")
            modname = ".".join(relative.parts).removesuffix(".__init__")
            if getattr(importlib.import_module(modname), name, None) is not value:
                continue
            lines = source.splitlines()[: node.lineno - 1]
            comment: list[str] = []
            while lines and lines[-1].lstrip().startswith("#"):
                comment.insert(0, lines.pop().lstrip().lstrip("#").strip())
            return " ".join(comment)
    return ""


def _data_entry(package: str, name: str, value) -> list[str]:
    lines = [f".. py:data:: {name}", ""]
    comment = _comment_above(package, name, value)
    if comment:
        lines += ["   " + comment.replace("*", r"\*"), ""]
    lines += ["   .. code-block:: python", ""]
    lines += ["      " + line for line in _value_text(value).splitlines()]
    return [*lines, ""]


def _heading(text: str, mark: str) -> list[str]:
    return [text, mark * len(text), ""]


def _package_page(package: str) -> tuple[str, list[str]]:
    """The package's page, and the names autosummary writes a page for."""
    module = importlib.import_module(package)
    lines = _heading(package, "=")
    lines += [f".. automodule:: {package}", "   :no-members:", ""]
    lines += [f".. currentmodule:: {package}", ""]
    groups: dict[str, list[str]] = {}
    aliases: list[tuple[str, str]] = []
    first_name: dict[int, str] = {}
    for name in public_names(package):
        value = getattr(module, name)
        if (inspect.isclass(value) or callable(value)) and id(value) in first_name:
            aliases.append((name, first_name[id(value)]))
            continue
        first_name.setdefault(id(value), name)
        groups.setdefault(_kind(value), []).append(name)
    stubs: list[str] = []
    for kind in ("Classes", "Functions", "Modules"):
        if kind not in groups:
            continue
        stubs += [f"{package}.{name}" for name in groups[kind]]
        lines += _heading(kind, "-")
        lines += [".. autosummary::", "   :toctree: .", "   :nosignatures:", ""]
        lines += [f"   {name}" for name in groups[kind]] + [""]
    if "Data" in groups:
        lines += _heading("Data", "-")
        for name in groups["Data"]:
            lines += _data_entry(package, name, getattr(module, name))
    if aliases:
        lines += _heading("Aliases", "-")
        for name, target in aliases:
            role = "class" if inspect.isclass(getattr(module, name)) else "func"
            directive = "class" if role == "class" else "function"
            lines += [f".. py:{directive}:: {name}", ""]
            lines += [f"   Another name of :{role}:`{package}.{target}`.", ""]
    return "\n".join(lines), stubs


def _top_level_page() -> str:
    """``spiralid``'s names are the subpackages' own objects: this page says
    where each is documented instead of documenting it twice."""
    import spiralid

    lines = _heading("spiralid", "=")
    lines += [".. automodule:: spiralid", "   :no-members:", ""]
    lines += [
        "Every name below is also a name of a subpackage, where it is",
        "documented; ``import spiralid as sid`` then ``sid.identify(...)`` is",
        "the same function as ``spiralid.sysid.identify``.",
        "",
    ]
    modules: list[str] = []
    for name in spiralid.__all__:
        value = getattr(spiralid, name)
        if name == "__version__":
            lines += [".. py:data:: __version__", ""]
            lines += ["   The installed version, a string.", ""]
            continue
        if isinstance(value, types.ModuleType):
            modules.append(f"* :mod:`{value.__name__}`: {_summary(value)}")
            continue
        home = next(
            p
            for p in PACKAGES
            if p != "spiralid"
            and getattr(importlib.import_module(p), name, None) is value
            and name in public_names(p)
        )
        directive, role = (
            ("class", "class")
            if inspect.isclass(value)
            else (
                "function",
                "func",
            )
        )
        lines += [f".. py:{directive}:: {name}", ""]
        lines += [f"   :{role}:`{home}.{name}`: {_summary(value)}", ""]
    lines += _heading("Subpackages", "-") + modules + [""]
    return "\n".join(lines)


def write_api_pages(out: Path = HERE / "api-generated") -> None:
    """Write one page per package into ``out`` (autosummary writes the pages
    of its names there); unchanged pages are left untouched, and pages of
    names no longer public are removed."""
    out.mkdir(exist_ok=True)
    pages = {"spiralid": _top_level_page()}
    keep = {"spiralid"}
    for package in PACKAGES:
        if package != "spiralid":
            pages[package], stubs = _package_page(package)
            keep.update([package, *stubs])
    for package, text in pages.items():
        path = out / f"{package}.rst"
        if not path.is_file() or path.read_text() != text:
            path.write_text(text)
    for path in out.glob("*.rst"):
        if path.stem not in keep:
            path.unlink()


write_api_pages()
