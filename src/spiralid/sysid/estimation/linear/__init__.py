"""The local methods of an ARX model and the spaces a search moves in:
parametrisations (``parametrizations``, the modal map in ``modal``), the
stability margin tied to the record (``margin``), Levenberg-Marquardt with a
projection (``levenberg``), output error and Steiglitz-McBride
(``outputerror``), variable projection (``varpro``, compiled kernels in
``_varpro_kernels``), the frequency-domain objective (``frequency``) and the
estimators that do not search, with the polish the searches end with
(``local_estimators``)."""
