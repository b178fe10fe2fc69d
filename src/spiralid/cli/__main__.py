"""``python -m spiralid.cli``."""

from . import console

console()
