"""Placeholder: method module 'enumeration' (to be written)."""
