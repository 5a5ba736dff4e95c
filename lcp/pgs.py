"""Placeholder: method module 'pgs' (to be written)."""
