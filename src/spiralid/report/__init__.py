"""The paper-reproduction experiment, its figures and its report."""

from spiralid.report.experiment import (
    CONFIGURATIONS,
    Configuration,
    Reproduction,
    Run,
    default_data,
    reproduce,
)
from spiralid.report.output import summary_text, write_reproduction

__all__ = [
    "CONFIGURATIONS",
    "Configuration",
    "Reproduction",
    "Run",
    "default_data",
    "reproduce",
    "summary_text",
    "write_reproduction",
]
