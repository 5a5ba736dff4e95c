"""Certificates of solutions: residuals, uniqueness (P-matrix test, enumeration, MILP), laws."""
