"""The README's API example runs as written (on the shipped real data)."""

import json
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_readme_api_example_runs(monkeypatch, tmp_path, capsys):
    text = (ROOT / "README.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    assert blocks, "README has no python example"
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    exec(compile(blocks[0], "README.md", "exec"), {})
    lines = capsys.readouterr().out.splitlines()
    methods = [line.split()[0] for line in lines[:5]]
    assert methods == ["ls", "oe", "ebsda", "ebsda", "spiral"]
    # The recommended method validates within a point of output error.
    assert abs(float(lines[4].split()[1]) - float(lines[1].split()[1])) <= 1.0
    # The data README's reference: least squares validates at about 95 %.
    assert abs(float(lines[0].split()[1]) - 95.0) <= 1.0


def test_readme_figures_exist_and_no_placeholder_is_left():
    text = (ROOT / "README.md").read_text()
    assert "PLACEHOLDER" not in text
    images = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", text)
    assert images
    for image in images:
        assert (ROOT / image).stat().st_size > 10_000, image


def test_readme_own_data_commands_run(tmp_path):
    from clitools import run

    text = (ROOT / "README.md").read_text()
    block = re.search(
        r"<!-- own-data-commands -->\n```\n(.*?)```", text, flags=re.S
    ).group(1)
    for line in block.strip().splitlines():
        command = line.split()
        assert command[0] == "spiralid"
        proc = run(*command[1:], cwd=tmp_path)
        assert proc.returncode == 0, (line, proc.stderr)
    assert proc.stdout.strip().splitlines()[-1].startswith("wrote ")
    assert (tmp_path / "rig-val" / "validation.json").is_file()
    fit = json.loads((tmp_path / "rig-val" / "validation.json").read_text())
    assert fit["fit_percent"] > 50


def test_readme_pareto_example_runs(monkeypatch, tmp_path, capsys):
    text = (ROOT / "README.md").read_text()
    block = re.search(
        r"<!-- pareto-example -->\n```python\n(.*?)```", text, flags=re.S
    ).group(1)
    monkeypatch.chdir(tmp_path)
    exec(compile(block, "README.md", "exec"), {})
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].endswith("('cost', 'frequency', 'order')")
    # The knee and the choice validate as the comments say (within a point).
    assert abs(float(lines[1].split()[-1]) - 89.6) <= 1.0
    assert abs(float(lines[2].split()[-1]) - 91.2) <= 1.0
    assert lines[3].startswith("ARX(5, 5, 0)")  # fits by order: 10 params 89.6 %
    assert abs(float(lines[3].split()[-1]) - 89.6) <= 1.0


def test_readme_pareto_command_runs(tmp_path):
    from clitools import run

    text = (ROOT / "README.md").read_text()
    block = re.search(r"<!-- pareto-commands -->\n```\n(.*?)```", text, flags=re.S)
    command = block.group(1).strip().split()
    assert command[0] == "spiralid"
    proc = run(*command[1:], cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    out = tmp_path / command[command.index("--out") + 1]
    assert (out / "front.csv").is_file() and (out / "point-0" / "model.json").is_file()
    assert json.loads((out / "validation.json").read_text())["validation"]


def test_readme_pareto_search_example_runs(capsys):
    text = (ROOT / "README.md").read_text()
    block = re.search(
        r"<!-- pareto-search-example -->\n```python\n(.*?)```", text, flags=re.S
    ).group(1)
    exec(compile(block, "README.md", "exec"), {})
    shape, hv = capsys.readouterr().out.strip().split(") ")
    assert shape == "(100, 2"
    # Within a hundredth of the printed figure; NSGA-II's median is 0.870.
    assert abs(float(hv) - 0.871) <= 0.01
