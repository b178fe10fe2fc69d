"""The package layout's one-way flow, read from the import statements.

`sysid` runs data -> models -> estimation -> validation (docs/design-notes.md,
"Layout and dependencies"): a subpackage imports only from those before it,
and nothing in the library below the command imports the command, the
report or the study. Above the library the flow is study -> reproduction ->
report -> cli, and the output plumbing (`outputs`) is a leaf that only
those four use.
"""

import ast
from pathlib import Path

import pytest

import spiralid

ROOT = Path(spiralid.__file__).parent
STAGES = ["models", "estimation", "validation"]


def _imports(path: Path) -> set[str]:
    """The absolute module names a file imports (relative ones resolved)."""
    package = path.relative_to(ROOT.parent).with_suffix("").parts[:-1]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package[: len(package) - node.level + 1]
                name = ".".join([*base, *([node.module] if node.module else [])])
                if not node.module:
                    found.update(f"{name}.{alias.name}" for alias in node.names)
                    continue
            else:
                name = node.module
            found.add(name)
    return found


def _files(sub: str) -> list[Path]:
    return sorted((ROOT / sub).rglob("*.py"))


def test_the_import_reader_sees_relative_imports():
    # Guards the helper the checks below rely on.
    found = _imports(ROOT / "sysid" / "estimation" / "cost.py")
    assert "spiralid.sysid.models.arx" in found
    assert "spiralid.sysid.data" in found


@pytest.mark.parametrize("stage", STAGES)
def test_sysid_stages_import_only_earlier_stages(stage):
    later = STAGES[STAGES.index(stage) + 1 :]
    for path in _files(f"sysid/{stage}"):
        for name in _imports(path):
            for other in later:
                assert not name.startswith(f"spiralid.sysid.{other}"), (
                    f"{path.relative_to(ROOT)} imports {name}"
                )


LIBRARY = ["optim", "fms", "sysid", "datasets"]
# Above the library, each of these imports only from those before it.
UPPER = ["study", "reproduction", "report", "cli"]


def _sources(sub: str) -> list[Path]:
    """A subpackage's files, or the one module `sub`.py."""
    module = ROOT / f"{sub}.py"
    return [module] if module.is_file() else _files(sub)


def _assert_no_import(subs, banned):
    banned = tuple(f"spiralid.{b}" for b in banned)
    for sub in subs:
        for path in _sources(sub):
            for name in _imports(path):
                assert not (
                    name in banned or name.startswith(tuple(f"{b}." for b in banned))
                ), f"{path.relative_to(ROOT)} imports {name}"


@pytest.mark.parametrize("sub", LIBRARY)
def test_the_library_imports_nothing_above_it(sub):
    # The library reports progress through callbacks and never writes a
    # command's files, so `outputs` is above it too.
    _assert_no_import([sub], [*UPPER, "outputs"])


@pytest.mark.parametrize("stage", UPPER[:-1])
def test_the_upper_packages_import_only_earlier_ones(stage):
    _assert_no_import([stage], UPPER[UPPER.index(stage) + 1 :])


def test_the_output_plumbing_imports_nothing_of_ours():
    for path in _files("outputs"):
        for name in _imports(path):
            assert not name.startswith("spiralid"), (
                f"{path.relative_to(ROOT)} imports {name}"
            )


def test_the_reader_sees_every_upper_package():
    # Guards the checks above against a renamed or moved package.
    for sub in [*UPPER, "outputs"]:
        assert _sources(sub), sub


def test_data_and_spectra_import_no_later_stage():
    for path in (ROOT / "sysid" / "data.py", ROOT / "sysid" / "spectra.py"):
        for name in _imports(path):
            assert not name.startswith(tuple(f"spiralid.sysid.{s}" for s in STAGES)), (
                f"{path.relative_to(ROOT)} imports {name}"
            )
