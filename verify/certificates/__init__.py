"""Certificates of solutions: residuals, uniqueness (P-matrix test, enumeration, MILP), laws;
uniqueness decided in stages (`stages`: the face of the solution, other solvers, the MILP), for
one event or a whole run (`run`)."""

from .stages import StagedCertificate as StagedCertificate
from .stages import Verdict as Verdict
from .stages import Witness as Witness
from .stages import certify_stages as certify_stages
