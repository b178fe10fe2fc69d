"""Every parameter of a public function or class is in its docstring.

As python-control's ``tests/docstrings_test.py``: a public name of the
package's modules whose signature has a parameter that its docstring's
``Parameters`` or ``Attributes`` section does not name fails here, so a new
option cannot ship undocumented. Entries may name several parameters
(``fun, bounds : ...``); ``*args``-style entries count by their name. A
short docstring without such a section must name each parameter in
backquotes in its text.
"""

import importlib
import inspect
import re

import pytest

MODULES = (
    "spiralid",
    "spiralid.optim",
    "spiralid.sysid",
    "spiralid.fms",
    "spiralid.study",
    "spiralid.datasets",
    "spiralid.reproduction",
)
_SECTION = re.compile(r"^(Parameters|Attributes|Other Parameters)\n-+\n", re.M)
_HEADER = re.compile(r"^\S.*\n-+\n", re.M)
_ENTRY = re.compile(r"^\**([A-Za-z_]\w*(?:\s*,\s*\**[A-Za-z_]\w*)*)\s*(?::|$)")


def documented(doc: str) -> set[str]:
    """Names listed in the docstring's Parameters/Attributes sections."""
    names = set()
    for match in _SECTION.finditer(doc):
        rest = doc[match.end() :]
        end = _HEADER.search(rest)
        for line in (rest[: end.start()] if end else rest).splitlines():
            entry = _ENTRY.match(line)
            if entry:
                names.update(n.strip().lstrip("*") for n in entry.group(1).split(","))
    return names


def public_callables():
    seen = set()
    for module_name in MODULES:
        module = importlib.import_module(module_name)
        for name in getattr(module, "__all__", ()):
            obj = getattr(module, name)
            if not (inspect.isfunction(obj) or inspect.isclass(obj)) or id(obj) in seen:
                continue
            seen.add(id(obj))
            yield f"{module_name}.{name}", obj


def _parameters(obj) -> list[str]:
    try:
        signature = inspect.signature(obj)
    except (TypeError, ValueError):
        return []
    return [
        name
        for name in signature.parameters
        if name not in ("self", "cls") and not name.startswith("_")
    ]


CASES = sorted(public_callables())


def test_the_parser_reads_numpy_style_sections():
    doc = (
        "Summary.\n\nParameters\n----------\nfun, bounds : callable\n    Text.\n"
        "**overrides\n    More.\n\nReturns\n-------\nx : float\n"
    )
    assert documented(doc) == {"fun", "bounds", "overrides"}


def _mentioned(doc: str, name: str) -> bool:
    return re.search(r"`\**" + re.escape(name) + r"\b", doc) is not None


@pytest.mark.parametrize(("name", "obj"), CASES, ids=[c[0] for c in CASES])
def test_every_parameter_is_documented(name, obj):
    doc = inspect.getdoc(obj) or ""
    if _SECTION.search(doc):
        listed = documented(doc)
        missing = [p for p in _parameters(obj) if p not in listed]
    else:
        missing = [p for p in _parameters(obj) if not _mentioned(doc, p)]
    assert not missing, f"{name}: undocumented parameters {missing}"
