"""Model structures: ARX transfer functions, their polynomials, and the
identified model that carries a structure with how it was estimated."""
