"""The reproduction's and the study's figures, HTML report and files.

The report only draws and writes: the experiment it reports is
:mod:`spiralid.reproduction`, and the atomic folders it writes into are
:mod:`spiralid.outputs`.
"""

from spiralid.report.output import summary_text, write_reproduction

__all__ = ["summary_text", "write_reproduction"]
