"""The README's and the documentation's examples run as written.

Each block is found by the HTML comment that marks it (``<!-- name -->``
right above the fence), in README.md or in a page under docs/.
"""

import json
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
DOCS = ROOT / "docs"


def block(path: Path, marker: str, language: str = "") -> str:
    """The fenced block right below ``<!-- marker -->`` in ``path``."""
    text = path.read_text(encoding="utf-8")
    found = re.search(
        rf"<!-- {re.escape(marker)} -->\n```{language}\n(.*?)```", text, flags=re.S
    )
    assert found, f"no <!-- {marker} --> block in {path.relative_to(ROOT)}"
    return found.group(1)


def run_python(path: Path, marker: str) -> None:
    code = block(path, marker, "python")
    exec(compile(code, f"{path.relative_to(ROOT)}:{marker}", "exec"), {})


def run_commands(text: str, cwd: Path):
    from clitools import run

    proc = None
    for line in text.strip().splitlines():
        command = line.split()
        assert command[0] == "spiralid"
        proc = run(*command[1:], cwd=cwd)
        assert proc.returncode == 0, (line, proc.stderr)
    return proc


def test_readme_own_data_example_runs(monkeypatch, tmp_path, capsys):
    from clitools import run

    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    # The record the README says stands in for yours.
    command = "simulate --signal prbs --duration 4 --out rig.csv --quiet"
    proc = run(*command.split(), cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    run_python(README, "own-data-example")
    lines = capsys.readouterr().out.splitlines()
    assert [line.split()[0] for line in lines[:2]] == ["spiral", "oe"]
    # The recommended method validates within a point of output error.
    fits = [float(line.split()[1]) for line in lines[:2]]
    assert abs(fits[0] - fits[1]) <= 1.0 and fits[1] > 50
    assert json.loads((tmp_path / "model.json").read_text())["method"] == "spiral"


def test_readme_figures_exist_and_no_placeholder_is_left():
    text = README.read_text()
    assert "PLACEHOLDER" not in text
    images = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", text)
    assert images
    for image in images:
        assert (ROOT / image).stat().st_size > 10_000, image


def test_readme_links_into_the_docs_exist():
    text = README.read_text()
    links = re.findall(r"\]\(((?:docs|examples)/[^)#]*)", text)
    assert len(links) > 10
    for link in links:
        assert (ROOT / link).exists(), link


def test_readme_own_data_commands_run_and_model_json_loads(
    monkeypatch, tmp_path, capsys
):
    proc = run_commands(block(README, "own-data-commands"), tmp_path)
    assert proc.stdout.strip().splitlines()[-1].startswith("wrote ")
    assert (tmp_path / "rig-val" / "validation.json").is_file()
    fit = json.loads((tmp_path / "rig-val" / "validation.json").read_text())
    assert fit["fit_percent"] > 50
    # The output files page's way to load it, to python-control.
    monkeypatch.chdir(tmp_path / "rig-oe")
    run_python(DOCS / "guide" / "outputs.md", "load-model-example")
    assert "z^8" in capsys.readouterr().out  # the transfer function


def test_readme_first_identification_gives_its_figures(tmp_path):
    run_commands(block(README, "first-identification"), tmp_path)
    out = tmp_path / "arm-model"
    validation = json.loads((out / "validation.json").read_text())["validation"]
    # The README's figures: a fit of 89.7 % and modes at 5.84 and 12.67 Hz.
    assert abs(validation["fit_percent"] - 89.7) <= 0.5
    freq = validation["modes"]["frequency_hz"]
    for f in (5.84, 12.67):
        assert min(abs(g - f) for g in freq) < 0.05


def test_readme_several_outputs_commands_give_the_rigs_modes(tmp_path):
    run_commands(block(README, "outputs-commands"), tmp_path)
    model = json.loads((tmp_path / "rig-modes" / "model.json").read_text())
    assert model["output_names"] == ["hub_velocity_rad_s", "end_acceleration_m_s2"]
    freq = [m["frequency_hz"] for m in model["modes"]["modes"]]
    # The FEM's three modes (FlexibleManipulator().modes(3)) within 0.5 %.
    for f in (13.3105, 35.1080, 64.8340):
        assert min(abs(g - f) / f for g in freq) < 0.005


def test_docs_methods_example_runs(monkeypatch, tmp_path, capsys):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    run_python(DOCS / "guide" / "estimation.md", "api-example")
    lines = capsys.readouterr().out.splitlines()
    methods = [line.split()[0] for line in lines[:5]]
    assert methods == ["ls", "oe", "ebsda", "ebsda", "spiral"]
    # The recommended method validates within a point of output error.
    assert abs(float(lines[4].split()[1]) - float(lines[1].split()[1])) <= 1.0
    # The data README's reference: least squares validates at about 95 %.
    assert abs(float(lines[0].split()[1]) - 95.0) <= 1.0


def test_docs_pareto_example_runs(monkeypatch, tmp_path, capsys):
    monkeypatch.chdir(tmp_path)
    run_python(DOCS / "guide" / "estimation.md", "pareto-example")
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].endswith("('cost', 'frequency', 'order')")
    # The knee and the choice validate as the comments say (within a point).
    assert abs(float(lines[1].split()[-1]) - 89.6) <= 1.0
    assert abs(float(lines[2].split()[-1]) - 91.3) <= 1.0
    assert lines[3].startswith("ARX(5, 5, 0)")  # fits by order: 10 params 89.6 %
    assert abs(float(lines[3].split()[-1]) - 89.6) <= 1.0


def test_docs_pareto_command_runs(tmp_path):
    text = block(DOCS / "guide" / "estimation.md", "pareto-commands")
    command = text.strip().split()
    run_commands(text, tmp_path)
    out = tmp_path / command[command.index("--out") + 1]
    assert (out / "front.csv").is_file() and (out / "point-0" / "model.json").is_file()
    assert json.loads((out / "validation.json").read_text())["validation"]


def test_docs_pareto_search_example_runs(capsys):
    run_python(DOCS / "guide" / "optimisers.md", "pareto-search-example")
    shape, hv = capsys.readouterr().out.strip().split(") ")
    assert shape == "(100, 2"
    # Within a hundredth of the printed figure; NSGA-II's median is 0.870.
    assert abs(float(hv) - 0.871) <= 0.01


def test_docs_first_examples_run(monkeypatch, tmp_path, capsys):
    monkeypatch.chdir(tmp_path)
    run_python(DOCS / "index.md", "five-lines")
    assert "fit %" in capsys.readouterr().out
    run_python(DOCS / "guide" / "data.md", "iodata-example")


@pytest.mark.slow
def test_docs_narx_example_runs(capsys):
    run_python(DOCS / "guide" / "models.md", "narx-example")
    run_python(DOCS / "guide" / "models.md", "narx-choice-example")
    assert "Billings-Voon" in capsys.readouterr().out
