"""Parametric system identification: data, ARX structures, the paper's cost,
estimation and validation."""

# --- core (data, arx, cost, identify) ---
# --- validation (validate, plots) ---
