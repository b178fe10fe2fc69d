"""The data sets shipped with the package, by the name the command line
accepts in place of a file (:data:`NAMES`); :mod:`spiralid.datasets`
re-exports them, and :func:`~spiralid.datasets.files.read_record` looks a
name up here."""

from __future__ import annotations

from importlib import resources

from spiralid._checks import one_of
from spiralid.sysid.data import IOData

__all__ = ["NAMES", "load", "robot_arm"]


def robot_arm(ts: float = 0.01) -> IOData:
    """The DaISy 96-009 flexible robot arm: 1024 samples, torque in, acceleration out.

    Parameters
    ----------
    ts : float, default 0.01
        Sample time in seconds. The source does not state it; 0.01 s is the
        value tools that need one commonly assume.

    Returns
    -------
    IOData
        ``u`` the measured reaction torque, ``y`` the arm's acceleration
        (names ``"u"`` and ``"y"``; the source states no units). The record
        is a slice of a periodic sine sweep and starts in motion.

    Examples
    --------
    >>> data = robot_arm()
    >>> data.n, data.ts, data.input_name, data.output_name
    (1024, 0.01, 'u', 'y')
    """
    source = resources.files("spiralid.datasets").joinpath("daisy_robot_arm.csv")
    with resources.as_file(source) as path:
        return IOData.from_csv(path, input="u", output="y", ts=ts)


# Data sets by the name the command line accepts in place of a file.
NAMES = {"robot_arm": robot_arm}


def load(name: str, ts: float | None = None) -> IOData:
    """A shipped data set by `name` (one of :data:`NAMES`); `ts` overrides its own."""
    one_of(name, "name", sorted(NAMES))
    return NAMES[name]() if ts is None else NAMES[name](ts=ts)
