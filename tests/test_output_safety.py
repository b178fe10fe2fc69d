"""The README's promise under interruption and concurrency, run as a user would.

No file is overwritten without --force; an interrupted or failed run leaves
nothing behind; a second run into the same folder is refused while the first
writes; an unwritable folder is refused before any computation.
"""

import signal
import subprocess
import time
from pathlib import Path

import pytest
from clitools import run, start

from spiralid import cli

REPRODUCE = ("reproduce", "--seeds", "1", "--budget", "300", "--points", "10")
REPRODUCE += ("--workers", "1", "--quiet")


def _wait_for(predicate, proc: subprocess.Popen, timeout: float = 120.0):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if predicate():
            return
        if proc.poll() is not None:
            pytest.fail(f"the run ended first: {proc.communicate()}")
        time.sleep(0.005)
    proc.kill()
    pytest.fail("timed out waiting")


def _staged_png(parent: Path) -> bool:
    return any(parent.glob(".spiralid-staging-*-rep-*/*.png"))


def _nothing_left(parent: Path) -> bool:
    return sorted(p.name for p in parent.iterdir()) == []


@pytest.mark.parametrize(
    "sig, status, word",
    [(signal.SIGINT, 130, "interrupted"), (signal.SIGTERM, 143, "terminated")],
)
def test_signal_while_writing_leaves_nothing_and_rerun_works(
    tmp_path, sig, status, word
):
    proc = start(*REPRODUCE, "--out", "rep", cwd=tmp_path)
    _wait_for(lambda: _staged_png(tmp_path), proc)
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == status, err
    assert err.strip().splitlines() == [f"spiralid reproduce: {word}"]
    assert _nothing_left(tmp_path)
    again = run(*REPRODUCE, "--out", "rep", cwd=tmp_path)
    assert again.returncode == 0, again.stderr
    assert (tmp_path / "rep" / "report.html").is_file()


def test_ctrl_c_while_computing_leaves_nothing(tmp_path):
    proc = start(*REPRODUCE, "--out", "rep", cwd=tmp_path)
    _wait_for(lambda: (tmp_path / ".spiralid-lock-rep").exists(), proc)
    proc.send_signal(signal.SIGINT)
    proc.communicate(timeout=120)
    assert proc.returncode == 130
    assert _nothing_left(tmp_path)


def test_two_concurrent_runs_one_writes_the_other_is_refused(tmp_path):
    first = start(*REPRODUCE, "--out", "rep", cwd=tmp_path)
    _wait_for(lambda: (tmp_path / ".spiralid-lock-rep").exists(), first)
    second = run(*REPRODUCE, "--out", "rep", cwd=tmp_path)
    assert second.returncode == 2
    assert second.stderr.strip().splitlines() == [
        f"spiralid reproduce: error: another spiralid run is writing to "
        f"{str(tmp_path / 'rep')!r}; wait for it to finish or choose another output"
    ]
    _, err = first.communicate(timeout=300)
    assert first.returncode == 0, err
    # Done: the folder is full, and a third run needs --force.
    third = run(*REPRODUCE, "--out", "rep", cwd=tmp_path)
    assert third.returncode == 2 and "not empty" in third.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["rep"]


@pytest.fixture
def immutable_folder(tmp_path):
    folder = tmp_path / "out"
    folder.mkdir()
    proc = subprocess.run(["chattr", "+i", str(folder)], capture_output=True)
    if proc.returncode != 0:
        pytest.skip(f"chattr +i not possible here: {proc.stderr.decode().strip()}")
    yield folder
    subprocess.run(["chattr", "-i", str(folder)], check=True)


def _never_called(*args, **kwargs):
    raise AssertionError("computed before checking the output folder")


@pytest.mark.parametrize(
    "argv, patch",
    [
        (["reproduce", "--out", "OUT"], "spiralid.report.reproduce"),
        (
            ["identify", "DATA", "--ts", "0.1", "--method", "ls", "--out", "OUT"],
            "spiralid.sysid.identify",
        ),
    ],
)
def test_unwritable_folder_refused_before_computing(
    immutable_folder, monkeypatch, capsys, argv, patch
):
    monkeypatch.setattr(patch, _never_called)
    data = immutable_folder.parent / "rec.csv"
    data.write_text("u,y\n" + "".join(f"{i % 3},{i % 5}\n" for i in range(200)))
    argv = [
        str(immutable_folder) if a == "OUT" else str(data) if a == "DATA" else a
        for a in argv
    ]
    assert cli.main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "not writable" in err[0]
    assert list(immutable_folder.iterdir()) == []
