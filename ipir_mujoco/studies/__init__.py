"""Studies that run the engines and judge them: compare, validate, sweeps, convergence, the L/r study."""
