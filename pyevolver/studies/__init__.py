"""Study scripts that reproduce the figures of shared/papers/pl-methods-biomembranes."""
