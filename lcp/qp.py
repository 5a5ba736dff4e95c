"""Placeholder: method module 'qp' (to be written)."""
