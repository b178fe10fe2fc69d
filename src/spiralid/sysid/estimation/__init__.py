"""Estimation: the paper's cost (eq. 2), the search spaces
(parametrisations), the estimators chosen by name, and `identify`."""
