"""What a problem and an answer are: LCP, MLCP (problem.py), the 2D friction-contact problem
(friction.py) and the result type Solution (solution.py). Files: lcp/io/."""
