"""Training NARX models: the estimators for a NARX or polynomial NARX
structure (``training``), the problem they solve (``problem``), where
training starts (``starts``), forward-regression orthogonal least squares
(``frols``), and a spiral search over the lags, hidden units and weight
decay (``choice``)."""
