"""Certificates and the paper's claims: residuals, uniqueness, null spaces, Eq. (3.3)/(3.4)."""

# Certificates (verify/certify.py). This binds `verify.certify` to the function; import the
# module's other names with `from verify.certify import ...`.
from .certify import Certificate as Certificate  # noqa: E402
from .certify import certify as certify  # noqa: E402
