"""What accuracy costs in time (docs/accuracy.md): the same contact problems solved across a
grid of solver settings, each compared with a converged reference, and the timing model that
predicts a solve's wall time and memory from its grid, iterations and preset."""
