"""When an answer counts: the acceptance test every route of `lcp.solve` applies (trust.py),
backward and forward errors (accuracy.py), the residual measure (residual.py), Farkas
certificates of infeasibility (farkas.py), Ruiz equilibration (scaling.py) and the friction
branch (friction.py)."""
