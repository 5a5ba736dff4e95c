"""Certificates and the paper's claims: residuals, uniqueness, null spaces, Eq. (3.3)/(3.4)."""

# Certificates (verify/certify.py). This binds `verify.certify` to the function; import the
# module's other names with `from verify.certify import ...`.
from .certify import Certificate as Certificate  # noqa: E402
from .certify import certify as certify  # noqa: E402

# Null spaces and the paper's closed forms (verify/nullspace.py, verify/formulas.py).
from .formulas import paper_singularities as paper_singularities  # noqa: E402
from .nullspace import null_space as null_space  # noqa: E402
