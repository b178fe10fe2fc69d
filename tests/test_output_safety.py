"""The README's promise under interruption and concurrency, run as a user would.

No file is overwritten without --force; an interrupted or failed run leaves
nothing behind; a second run into the same folder is refused while the first
writes; an unwritable folder is refused before any computation.
"""

import os
import signal
import subprocess
from pathlib import Path

import pytest
from clitools import SCRIPT, cli_env, run, start
from patience import allowance, until, wait_for

from spiralid import cli

REPRODUCE = ("reproduce", "--seeds", "1", "--budget", "300", "--points", "10")
REPRODUCE += ("--workers", "1", "--quiet")


def _wait_for(predicate, proc: subprocess.Popen, what: str):
    # The event, however long the run takes to reach it; the safety net
    # (patience.py) only stops a run that hangs. The reproductions here take
    # 5-30 s unloaded, ten times that on a loaded machine.
    wait_for(predicate, what, proc=proc, seconds=300)


def _staged_png(parent: Path) -> bool:
    return any(parent.glob(".spiralid-staging-*-rep-*/*.png"))


def _nothing_left(parent: Path) -> bool:
    return sorted(p.name for p in parent.iterdir()) == []


def _locked(parent: Path):
    return lambda: (parent / ".spiralid-lock-rep").exists()


@pytest.mark.slow
@pytest.mark.parametrize(
    "sig, status, word",
    [(signal.SIGINT, 130, "interrupted"), (signal.SIGTERM, 143, "terminated")],
)
def test_signal_while_writing_leaves_nothing_and_rerun_works(
    tmp_path, sig, status, word
):
    proc = start(*REPRODUCE, "--out", "rep", cwd=tmp_path)
    _wait_for(lambda: _staged_png(tmp_path), proc, "a figure is staged")
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=allowance(120))
    assert proc.returncode == status, err
    assert err.strip().splitlines() == [f"spiralid reproduce: {word}"]
    assert _nothing_left(tmp_path)
    again = run(*REPRODUCE, "--out", "rep", cwd=tmp_path)
    assert again.returncode == 0, again.stderr
    assert (tmp_path / "rep" / "report.html").is_file()


@pytest.mark.slow
def test_ctrl_c_while_computing_leaves_nothing(tmp_path):
    proc = start(*REPRODUCE, "--out", "rep", cwd=tmp_path)
    _wait_for(_locked(tmp_path), proc, "the output is locked")
    proc.send_signal(signal.SIGINT)
    proc.communicate(timeout=allowance(120))
    assert proc.returncode == 130
    assert _nothing_left(tmp_path)


@pytest.mark.slow
def test_two_concurrent_runs_one_writes_the_other_is_refused(tmp_path):
    first = start(*REPRODUCE, "--out", "rep", cwd=tmp_path)
    _wait_for(_locked(tmp_path), first, "the output is locked")
    second = run(*REPRODUCE, "--out", "rep", cwd=tmp_path)
    assert second.returncode == 2
    assert second.stderr.strip().splitlines() == [
        f"spiralid reproduce: error: another spiralid run is writing to "
        f"{str(tmp_path / 'rep')!r}; wait for it to finish or choose another output"
    ]
    _, err = first.communicate(timeout=allowance(600))
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
        (["reproduce", "--out", "OUT"], "spiralid.reproduction.reproduce"),
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


# -- Ctrl-C to the whole job, worker processes, stale files, file modes ------

POOLED = ("reproduce", "--seeds", "2", "--budget", "3000", "--points", "20")
POOLED += ("--workers", "2", "--quiet")


def _group_alive(pgid: int) -> list[int]:
    found = subprocess.run(["pgrep", "-g", str(pgid)], capture_output=True, text=True)
    return [int(p) for p in found.stdout.split()]


def _gone(pgid: int) -> bool:
    # The group empties as soon as every worker has noticed: at once for a
    # worker that is computing (it dies with its parent), after its imports
    # for one still starting, which a loaded machine stretches to seconds.
    return until(lambda: not _group_alive(pgid), seconds=60, interval=0.1)


def _catches(pid: int, signum: int) -> bool:
    """Whether the main thread of `pid` has a handler for `signum` and does
    not block it (its masks in /proc/PID/status)."""
    try:
        with open(f"/proc/{pid}/status") as fh:
            masks = {k: v.strip() for k, _, v in (line.partition(":") for line in fh)}
    except FileNotFoundError:
        return False
    bit = 1 << (signum - 1)
    return bool(int(masks["SigCgt"], 16) & bit and not int(masks["SigBlk"], 16) & bit)


def _in_the_command(pid: int) -> bool:
    """The command's own code runs, inside its handling of Ctrl-C: its
    SIGTERM handler is installed (spiralid.cli._interrupts; Python itself
    does not catch SIGTERM) and it has started importing the library (NumPy
    is mapped, which building the parser does not import)."""
    if not _catches(pid, signal.SIGTERM):
        return False
    try:
        return "_multiarray_umath" in Path(f"/proc/{pid}/maps").read_text()
    except FileNotFoundError:
        return False


def _workers_computing(pid: int) -> bool:
    """Both pool workers are up and the command has left the moment of
    spawning them (spiralid.study.runner._children_ignore_sigint blocks and
    ignores SIGINT meanwhile): the group holds the command, the resource
    tracker and 2 workers, and the command catches SIGINT again."""
    return len(_group_alive(pid)) >= 4 and _catches(pid, signal.SIGINT)


@pytest.mark.slow
@pytest.mark.parametrize("moment", ["start-up", "computing"])
def test_ctrl_c_to_the_job_is_one_line_and_stops_every_worker(tmp_path, moment):
    # What a terminal's Ctrl-C does: SIGINT to every process of the job. (In
    # the few milliseconds while the workers are spawned SIGINT is ignored,
    # see spiralid/study/runner.py: a Ctrl-C then needs pressing again.)
    proc = start(*POOLED, "--out", "rep", cwd=tmp_path, new_group=True)
    if moment == "start-up":
        # Importing the library, loading the record. (Before the first line
        # of our code runs, while the interpreter itself starts, a Ctrl-C is
        # Python's to report.)
        what = "the command imports the library"
        _wait_for(lambda: _in_the_command(proc.pid), proc, what)
    else:
        what = "the workers compute"
        _wait_for(lambda: _workers_computing(proc.pid), proc, what)
    os.killpg(proc.pid, signal.SIGINT)
    _, err = proc.communicate(timeout=allowance(120))
    assert proc.returncode == 130
    assert err.splitlines() == ["spiralid reproduce: interrupted"]
    assert _gone(proc.pid)
    assert _nothing_left(tmp_path)


def test_ctrl_c_after_the_work_is_done_is_still_one_line(monkeypatch, capsys):
    # A signal can arrive after the commit, or be swallowed by a library on
    # its way up: the command still ends with one line and status 130.
    def run(args, argv):
        try:
            signal.raise_signal(signal.SIGINT)  # handled before it returns
        except KeyboardInterrupt:
            pass
        return 0

    monkeypatch.setattr("spiralid.cli.simulate.run", run)
    # SIGINT as an interactive shell leaves it: a test run started in the
    # background of a script inherits it ignored, and the command then
    # rightly keeps ignoring it (the interpreter's own rule).
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        status = cli.main(["simulate"])
    finally:
        signal.signal(signal.SIGINT, previous)
    assert status == 130
    assert capsys.readouterr().err.splitlines() == ["spiralid simulate: interrupted"]


@pytest.mark.slow
def test_kill_9_leaves_no_worker_and_the_next_run_tidies_up(tmp_path):
    proc = start(*POOLED, "--out", "rep", cwd=tmp_path, new_group=True)
    _wait_for(lambda: _workers_computing(proc.pid), proc, "the workers compute")
    proc.kill()
    proc.wait()
    assert _gone(proc.pid)
    left = sorted(p.name for p in tmp_path.iterdir())
    assert left and all(name.startswith(".spiralid-") for name in left)
    # Any later run writing beside them removes them, and says so in a line.
    later = run("simulate", "--out", "rig.csv", cwd=tmp_path)
    assert later.returncode == 0, later.stderr
    assert len(later.stderr.splitlines()) == 1
    assert "removed 2 file(s)" in later.stderr and "killed" in later.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["rig.csv"]


def _stored_runs(path) -> int:
    import sqlite3

    if not path.exists():
        return 0
    try:
        with sqlite3.connect(f"file:{path}?mode=ro", uri=True, timeout=1.0) as db:
            return db.execute("SELECT COUNT(*) FROM runs").fetchone()[0]
    except sqlite3.Error:  # not created yet, or locked by the writer
        return 0


@pytest.mark.slow
def test_study_on_dask_ctrl_c_is_one_line(tmp_path):
    pytest.importorskip("distributed")
    spec = run("study", "--show-default", cwd=tmp_path).stdout
    spec = spec.replace("seeds = 20", "seeds = 2 #")
    spec = spec.replace("budget = 20000", "budget = 2000 #")
    (tmp_path / "s.toml").write_text(spec)
    proc = start("study", "s.toml", "--out", "st", "--workers", "2", "--quiet",
                 cwd=tmp_path, new_group=True)  # fmt: skip
    # Once a run is stored the workers are up: a Ctrl-C while they are still
    # importing is the known gap of spiralid.study.runner (a worker that has
    # not yet started ignoring it prints its own traceback), which a loaded
    # machine widens from milliseconds to seconds.
    store = tmp_path / "st" / "study.sqlite"
    _wait_for(lambda: _stored_runs(store) > 0, proc, "a run is stored")
    os.killpg(proc.pid, signal.SIGINT)
    _, err = proc.communicate(timeout=allowance(120))
    assert proc.returncode == 130
    assert err.splitlines() == ["spiralid study: interrupted"]
    assert _gone(proc.pid)


MODES = [(0o022, 0o644, 0o755), (0o077, 0o600, 0o700)]


@pytest.mark.parametrize("mask, file_mode, dir_mode", MODES)
def test_outputs_follow_the_umask(tmp_path, mask, file_mode, dir_mode):
    def with_mask(*args):
        return subprocess.run(
            [str(SCRIPT), *args], cwd=tmp_path, env=cli_env(), umask=mask,
            capture_output=True, text=True,
        )  # fmt: skip

    assert with_mask("simulate", "--out", "rig.csv", "--quiet").returncode == 0
    made = with_mask("identify", "rig.csv", "--method", "ls", "--out", "m", "--quiet")
    assert made.returncode == 0, made.stderr
    assert (tmp_path / "rig.csv").stat().st_mode & 0o777 == file_mode
    assert (tmp_path / "m").stat().st_mode & 0o777 == dir_mode
    for p in (tmp_path / "m").iterdir():
        assert p.stat().st_mode & 0o777 == file_mode, p.name
