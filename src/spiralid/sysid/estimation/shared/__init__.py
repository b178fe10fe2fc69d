"""Several outputs, one denominator: the shared-denominator estimate
(``denominator``) and the subspace estimate of the shared poles
(``subspace``), its start and baseline."""
