"""Placeholder: method module 'lemke' (to be written)."""
