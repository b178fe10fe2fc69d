"""Test-wide settings.

Hypothesis draws its examples from a fixed seed (``derandomize``), so a run
on CI explores exactly the examples a run here did: a property test cannot
pass here and fail there by luck.
"""

from hypothesis import settings

settings.register_profile("spiralid", derandomize=True, deadline=None)
settings.load_profile("spiralid")
