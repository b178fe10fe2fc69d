"""Estimation of the neural state-space family (:mod:`.training`) and the
spiral's choice of its size (:mod:`.choice`)."""
