"""Certificates and the paper's claims: residuals, uniqueness, null spaces, Eq. (3.3)/(3.4).

Subpackages by job: `certificates` (certify, uniqueness, laws), `nullspace` (null spaces of the
contact matrix, the paper's formulas, loops, exact ranks), `forces` (force polyhedra, ranges,
particular solutions); `strategies` holds hypothesis strategies for users' property tests.
`rigidlcp.verify.certify` is the function; import the module's other names with
`from verify.certify import ...`.
"""

from .certificates.certify import Certificate as Certificate
from .certificates.certify import certify as certify
from .nullspace.contact import null_space as null_space
from .nullspace.formulas import paper_singularities as paper_singularities
