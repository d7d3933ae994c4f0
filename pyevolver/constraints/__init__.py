"""Level-set constraints and boundaries: projection, tangent spaces, one-sided constraints."""
