"""What every estimation shares: :func:`~spiralid.sysid.identify` (``identify``)
and its option contract (``options``), the estimators chosen by name
(``estimators``: the table ``METHODS``), what they take and return
(``problem``), the paper's cost, eq. (2)-(3) (``cost``), the covariance of
an estimate (``uncertainty``), and the spiral over a nonlinear model's
discrete choices that ``choose_narx`` and ``choose_state_space`` share
(``choices``)."""
