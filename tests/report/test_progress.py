import io

from spiralid.report.progress import ProgressBar


class Terminal(io.StringIO):
    def isatty(self):
        return True


def test_waits_for_the_delay_but_draws_the_end():
    out = Terminal()
    bar = ProgressBar(4, "run", stream=out, delay=60.0)
    bar(1)
    assert out.getvalue() == ""
    bar(4)
    assert "4/4" in out.getvalue()


def test_draws_on_a_terminal():
    out = Terminal()
    bar = ProgressBar(4, "run", stream=out, delay=0.0)
    bar(1)
    bar(4)
    bar.close()
    text = out.getvalue()
    assert "run [" in text and "1/4" in text and "4/4" in text
    assert text.endswith("\n")


def test_silent_when_quiet_or_not_a_terminal():
    for stream, enabled in ((Terminal(), False), (io.StringIO(), True)):
        bar = ProgressBar(3, stream=stream, enabled=enabled, delay=0.0)
        bar(1)
        bar(3, 3)
        bar.close()
        assert stream.getvalue() == ""


def test_total_can_be_updated_by_the_caller():
    out = Terminal()
    bar = ProgressBar(1, stream=out, delay=0.0)
    bar(2, 10)
    assert "2/10" in out.getvalue()
