"""Estimation of the neural state-space family (:mod:`.training`)."""
