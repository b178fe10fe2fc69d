"""Atomic output: all files or none, one writer at a time, no clobbering."""

import subprocess
import sys
import textwrap
from contextlib import contextmanager
from pathlib import Path

import pytest
from patience import allowance

from spiralid.outputs.atomic import OutputError, OutputFile, OutputFolder


def _leftovers(parent: Path) -> list[str]:
    return sorted(p.name for p in parent.iterdir() if p.name.startswith(".spiralid"))


def test_folder_appears_complete_on_commit(tmp_path):
    target = tmp_path / "a" / "b" / "out"
    with OutputFolder(target) as folder:
        (folder.path / "x.txt").write_text("x")
        (folder.path / "y.txt").write_text("y")
        assert not target.exists()
        written = folder.commit(last="x.txt")
    assert [p.name for p in written] == ["y.txt", "x.txt"]
    assert sorted(p.name for p in target.iterdir()) == ["x.txt", "y.txt"]
    assert _leftovers(target.parent) == []


def test_failure_leaves_nothing_not_even_the_parents_it_made(tmp_path):
    target = tmp_path / "new" / "deeper" / "out"
    with pytest.raises(RuntimeError), OutputFolder(target) as folder:
        (folder.path / "x.txt").write_text("x")
        raise RuntimeError("the computation failed")
    assert list(tmp_path.iterdir()) == []


def test_non_empty_folder_refused_without_force_and_spared_with_it(tmp_path):
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "notes.txt").write_text("mine")
    (tmp_path / "out" / "x.txt").write_text("old")
    with pytest.raises(OutputError, match="not empty"):
        OutputFolder(tmp_path / "out").open()
    with OutputFolder(tmp_path / "out", force=True) as folder:
        (folder.path / "x.txt").write_text("new")
        folder.commit()
    assert (tmp_path / "out" / "notes.txt").read_text() == "mine"
    assert (tmp_path / "out" / "x.txt").read_text() == "new"
    assert _leftovers(tmp_path) == []


def test_second_writer_is_refused_while_the_first_holds_the_lock(tmp_path):
    with OutputFolder(tmp_path / "out"):
        with pytest.raises(OutputError, match="another spiralid run"):
            OutputFolder(tmp_path / "out").open()
    # Released: a new writer gets in.
    with OutputFolder(tmp_path / "out") as folder:
        folder.commit()
    assert _leftovers(tmp_path) == []


def test_lock_taken_in_another_process_is_refused(tmp_path):
    # flock is per open file description: a real second process must see it.
    code = textwrap.dedent(
        f"""
        import sys, time
        from spiralid.outputs.atomic import OutputFolder
        with OutputFolder({str(tmp_path / "out")!r}):
            print("locked", flush=True)
            sys.stdin.readline()
        """
    )
    holder = subprocess.Popen(
        [sys.executable, "-c", code],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert holder.stdout.readline().strip() == "locked"
        with pytest.raises(OutputError, match="another spiralid run is writing"):
            OutputFolder(tmp_path / "out").open()
    finally:
        holder.communicate("\n", timeout=allowance(30))
    assert _leftovers(tmp_path) == []


def test_stale_staging_of_a_killed_run_is_removed(tmp_path):
    stale = tmp_path / ".spiralid-staging-out-abc123"
    stale.mkdir()
    (stale / "half.png").write_bytes(b"x")
    # The user is told what was removed and why.
    told = pytest.warns(UserWarning, match=r"removed 1 file\(s\) .* was killed")
    with told, OutputFolder(tmp_path / "out") as folder:
        assert not stale.exists()
        folder.commit()


def test_file_is_never_clobbered_without_force(tmp_path):
    target = tmp_path / "rig.csv"
    with OutputFile(target) as out:
        out.path.write_text("mine")
        # Someone else creates the file while we compute: it is kept.
        target.write_text("theirs")
        with pytest.raises(OutputError, match="exists"):
            out.commit()
    assert target.read_text() == "theirs"
    assert _leftovers(tmp_path) == []
    with OutputFile(target, force=True) as out:
        out.path.write_text("mine")
        out.commit()
    assert target.read_text() == "mine"


@contextmanager
def _immutable(path: Path):
    """`chattr +i` (root bypasses permission bits but not the immutable flag)."""
    proc = subprocess.run(["chattr", "+i", str(path)], capture_output=True)
    if proc.returncode != 0:
        pytest.skip(f"chattr +i not possible here: {proc.stderr.decode().strip()}")
    try:
        yield
    finally:
        subprocess.run(["chattr", "-i", str(path)], check=True)


def test_unwritable_target_refused_when_opened(tmp_path):
    target = tmp_path / "out"
    target.mkdir()
    with _immutable(target), pytest.raises(OutputError, match="not writable"):
        OutputFolder(target).open()
    assert _leftovers(tmp_path) == []


def test_unwritable_parent_refused_when_opened(tmp_path):
    parent = tmp_path / "ro"
    parent.mkdir()
    with _immutable(parent), pytest.raises(OutputError, match="permission denied"):
        OutputFolder(parent / "out").open()
    with _immutable(parent), pytest.raises(OutputError, match="permission denied"):
        OutputFile(parent / "rig.csv").open()
    assert list(parent.iterdir()) == []


def test_read_only_bind_mount_refused_when_opened(tmp_path):
    target = tmp_path / "out"
    target.mkdir()
    proc = subprocess.run(
        ["mount", "--bind", "-o", "ro", str(target), str(target)], capture_output=True
    )
    if proc.returncode != 0:
        pytest.skip(f"bind mount not possible here: {proc.stderr.decode().strip()}")
    try:
        with pytest.raises(OutputError, match="read-only file system"):
            OutputFolder(target).open()
    finally:
        subprocess.run(["umount", str(target)], check=True)
    assert _leftovers(tmp_path) == []
