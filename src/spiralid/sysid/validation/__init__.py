"""Validation: fit, error ranges, stability, residual correlation tests, the
frequency domain, and the figures (loaded only when drawing)."""
