"""What every estimation shares: :func:`~spiralid.sysid.identify` (``identify``)
and its option contract (``options``), the estimators chosen by name
(``estimators``: the table ``METHODS``), what they take and return
(``problem``), the paper's cost, eq. (2)-(3) (``cost``), and the covariance of
an estimate (``uncertainty``)."""
