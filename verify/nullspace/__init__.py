"""Null spaces of the contact matrix (Eqs. 2.15, 3.1, 3.2), the paper's Eqs. (3.3)/(3.4),
localized bases (Fig. 5) and exact ranks."""

from .contact import NullSpace, null_space

__all__ = ["NullSpace", "null_space"]
