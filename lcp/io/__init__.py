"""File formats: the toolkit's own .npz (lcp.problem.load / save) and Siconos's text formats."""
