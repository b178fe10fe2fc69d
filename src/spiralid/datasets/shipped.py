"""The data sets shipped with the package, by the name the command line
accepts in place of a file (:data:`NAMES`); :mod:`spiralid.datasets`
re-exports them, and :func:`~spiralid.datasets.files.read_record` looks a
name up here."""

from __future__ import annotations

from dataclasses import replace
from importlib import resources

from spiralid._checks import one_of
from spiralid.sysid.data import IOData

__all__ = ["CASCADED_TANKS_PUBLISHED", "NAMES", "cascaded_tanks", "load", "robot_arm"]


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


#: Published test-record scores of the Cascaded Tanks benchmark (RMS of the
#: free-run error on the test record after its first 5 samples, in V), by
#: model; sources in ``datasets/README.md``.
CASCADED_TANKS_PUBLISHED = {
    "best linear approximation": 0.75,
    "Volterra": 0.54,
    "PNLSS (Relan et al. 2017)": 0.45,
    "flexible state space (Svensson & Schön 2017)": 0.45,
    "NLSS2-initialised state space (Relan et al. 2017)": 0.34,
    "neural continuous-time state space (Forgione & Piga 2021)": 0.33,
    "grey box with overflow (Rogers et al. 2017)": 0.18,
}

_TANKS_FILES = {
    "estimation": "cascaded_tanks_est.csv",
    "test": "cascaded_tanks_val.csv",
}


def cascaded_tanks(record: str = "estimation") -> IOData:
    """A record of the Cascaded Tanks benchmark (measured; 1,024 samples at 4 s).

    Parameters
    ----------
    record : {"estimation", "test"}
        The benchmark's estimation record (``uEst``, ``yEst``) or its test
        record (``uVal``, ``yVal``). Both start from the same unknown state.

    Returns
    -------
    IOData
        ``u`` the pump voltage, ``y`` the lower tank's water-level sensor
        (both in V; the sensor saturates at 10 V when a tank overflows).

    Notes
    -----
    The benchmark's score is the RMS of the free-run error on the test
    record, in V, after its first 5 samples (which may set the model's
    state); :data:`CASCADED_TANKS_PUBLISHED` lists published scores.

    Examples
    --------
    >>> est, test = cascaded_tanks(), cascaded_tanks("test")
    >>> est.n, test.n, est.ts, est.input_unit
    (1024, 1024, 4.0, 'V')
    """
    one_of(record, "record", sorted(_TANKS_FILES))
    source = resources.files("spiralid.datasets").joinpath(_TANKS_FILES[record])
    with resources.as_file(source) as path:
        data = IOData.from_csv(path, input="u", output="y", ts=4.0)
    return replace(
        data,
        input_name="pump",
        output_name="level",
        input_unit="V",
        output_unit="V",
    )


# Data sets by the name the command line accepts in place of a file.
NAMES = {
    "robot_arm": robot_arm,
    "cascaded_tanks": cascaded_tanks,
    "cascaded_tanks_test": lambda: cascaded_tanks("test"),
}


def load(name: str, ts: float | None = None) -> IOData:
    """A shipped data set by `name` (one of :data:`NAMES`); `ts` overrides its own."""
    one_of(name, "name", sorted(NAMES))
    data = NAMES[name]()
    return data if ts is None else replace(data, ts=ts)
