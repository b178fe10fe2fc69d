"""Fitting grey boxes (:class:`~spiralid.sysid.models.greybox.GreyBox`):
the cost and the search coordinates (``problem``), the methods
(``fit``) and the parameters' intervals and identifiability
(``intervals``)."""
