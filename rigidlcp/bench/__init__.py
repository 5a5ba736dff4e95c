"""The solver-comparison harness: problem sets, runners, certified results, reports.

An application built on `rigidlcp.lcp` (solvers, file formats) and `rigidlcp.verify`
(certificates); `rigidlcp bench` is its command (rigidlcp/cli/bench.py).
"""
