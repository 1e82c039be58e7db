"""Searches of the design space through the sweep's evaluations: optimization, Sobol sensitivity indices,
calibration to a measured run."""
