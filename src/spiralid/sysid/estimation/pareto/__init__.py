"""A Pareto front of ARX models: :func:`~spiralid.sysid.identify_pareto`
and choosing a model from the front (``identify``), one structure's search
(``search``), and which options apply to which objectives (``options``)."""
