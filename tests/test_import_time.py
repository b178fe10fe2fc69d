"""`import spiralid` is cheap: SciPy, Numba and matplotlib load on first use."""

import subprocess
import sys

import pytest


def _fresh(code: str) -> str:
    proc = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    )
    return proc.stdout.strip()


def test_import_loads_no_heavy_dependency():
    loaded = _fresh(
        "import sys, spiralid; "
        "print(sorted(m for m in ('scipy', 'numba', 'matplotlib', 'numpy') "
        "if m in sys.modules))"
    )
    assert loaded == "[]"


def test_import_loads_fewer_modules_than_numpy_alone():
    # Counted, not timed (a loaded machine stretches any time): NumPy itself
    # is the yardstick of a light import.
    def count(module):
        return len(_modules_imported(f"import {module}"))

    assert count("spiralid") < count("numpy")


def test_public_names_still_resolve():
    import spiralid

    assert spiralid.IOData is spiralid.sysid.IOData
    assert spiralid.minimize is spiralid.optim.minimize
    # Documented at the top level (README, "Which method to use").
    assert spiralid.steiglitz_mcbride is spiralid.sysid.steiglitz_mcbride
    assert {"identify", "datasets", "fms"} <= set(dir(spiralid))


_HEAVY = ("numpy", "scipy", "numba", "matplotlib")
_SUBCOMMANDS = (
    "simulate",
    "identify",
    "pareto",
    "validate",
    "export",
    "reproduce",
    "study",
    "study-report",
)


def _modules_imported(code: str) -> set[str]:
    # -X importtime lists every module a fresh interpreter imports, one line
    # each ("import time: self | cumulative | name"): what was loaded, read
    # from the interpreter itself rather than from a clock a loaded machine
    # slows down.
    proc = subprocess.run(
        [sys.executable, "-X", "importtime", "-c", code],
        capture_output=True,
        text=True,
        check=False,
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    return {
        line.rsplit("|", 1)[1].strip()
        for line in proc.stderr.splitlines()
        if line.startswith("import time:") and "|" in line
    }


@pytest.mark.parametrize("argv", [[], *([c] for c in _SUBCOMMANDS)])
def test_help_builds_its_parser_without_a_heavy_import(argv):
    # `spiralid --help` and each subcommand's --help: the parsers take their
    # choices from spiralid.choices, so NumPy, SciPy, Numba and matplotlib
    # (0.5-10 s on a loaded machine) stay unloaded.
    code = (
        "import sys; from spiralid.cli import main; "
        f"sys.argv = ['spiralid']; main({[*argv, '--help']!r})"
    )
    loaded = _modules_imported(code)
    assert "spiralid.cli" in loaded  # the parse really ran in that process
    heavy = {m for m in loaded if m.split(".")[0] in _HEAVY}
    assert not heavy, sorted(heavy)[:10]


def test_a_table_that_strays_from_its_names_fails_at_import():
    from spiralid.choices import RULE_NAMES, require_names
    from spiralid.optim import RULES

    require_names(RULES, RULE_NAMES, "RULES")
    with pytest.raises(RuntimeError, match="update both together"):
        require_names(reversed(RULE_NAMES), RULE_NAMES, "RULES")
