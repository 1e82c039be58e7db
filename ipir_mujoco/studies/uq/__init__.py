"""Uncertainty propagation (the uncertainty study): the distributions of uncertain parameters and the
statistics of the estimates."""
