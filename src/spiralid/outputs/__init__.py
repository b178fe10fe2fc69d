"""How every command writes: atomic output folders and files
(:mod:`~spiralid.outputs.atomic`) and progress on standard error
(:mod:`~spiralid.outputs.progress`).

It imports nothing of ours, so the report, the study and the command line
can all use it; the library below them reports through callbacks and never
writes here (``tests/test_layout.py``).
"""
