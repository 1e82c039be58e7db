"""The validation job: the model ladder at 1 s (validate) and to steady state (cruise), the paper's reported
figures, the L/r study and MuJoCo's convergence."""
