import io

from patience import until

import spiralid.outputs.progress as progress_module
from spiralid.outputs.progress import Progress


class Terminal(io.StringIO):
    def isatty(self):
        return True


def test_waits_for_the_delay():
    for stream in (Terminal(), io.StringIO()):
        with Progress("run", stream=stream, delay=60.0) as progress:
            steps = progress.phase("search", total=4)
            steps(1)
            steps(4)
        assert stream.getvalue() == ""


def test_plain_lines_at_every_tenth_not_every_step():
    log = io.StringIO()
    with Progress("spiralid x", stream=log, delay=0.0) as progress:
        steps = progress.phase("search", "searching", total=1000, unit="evaluations")
        for done in range(1, 1001):
            steps(done)
    lines = log.getvalue().splitlines()
    assert len(lines) == 12  # 0 %, 10 %, ..., 100 %, done
    assert lines[0] == "spiralid x: searching: 0/1,000 evaluations (0 %), 0 s"
    assert lines[-2].startswith(
        "spiralid x: searching: 1,000/1,000 evaluations (100 %)"
    )
    assert lines[-1].startswith("spiralid x: done in ")


def test_a_quiet_phase_still_says_it_runs(monkeypatch):
    # Between the library's reports a line every PLAIN_EVERY seconds.
    monkeypatch.setattr(progress_module, "PLAIN_EVERY", 0.2)
    monkeypatch.setattr(progress_module, "_TICK", 0.05)
    # Waits for the lines themselves, not for a time a loaded machine may
    # stretch: the safety net only stops a hang.
    log = io.StringIO()
    with Progress("spiralid x", stream=log, delay=0.0) as progress:
        progress.phase("polish", "polishing")
        assert until(lambda: len(log.getvalue().splitlines()) >= 3, 60.0, 0.01)
    lines = log.getvalue().splitlines()
    assert len(lines) >= 4, lines  # three or more, then "done"
    assert all(line.startswith("spiralid x: polishing, ") for line in lines[:-1])


def test_timings_of_the_phases_in_their_order():
    with Progress("run", enabled=False) as progress:
        progress.phase("load")
        progress.phase("search", total=2)(1)
        progress.phase("load")  # a name used again adds up
    times = progress.timings()
    assert list(times) == ["load", "search", "total"]
    assert times["load"] + times["search"] <= times["total"]


def test_total_can_be_updated_by_the_caller():
    log = io.StringIO()
    with Progress("run", stream=log, delay=0.0) as progress:
        progress.phase("runs", "running", unit="runs")
        progress(2, 10)
    assert "running: 2/10 runs (20 %)" in log.getvalue()


def test_a_closed_stream_is_not_an_error():
    stream = io.StringIO()
    with Progress("run", stream=stream, delay=0.0) as progress:
        stream.close()
        progress.phase("search", total=3)(2)
