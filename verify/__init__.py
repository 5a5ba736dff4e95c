"""Certificates and the paper's claims: residuals, uniqueness, null spaces, Eq. (3.3)/(3.4)."""
