"""Placeholder: method module 'pivoting' (to be written)."""
