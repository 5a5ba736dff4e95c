"""Statics of a packing under gravity: whether an equilibrium exists, and the set of admissible
contact forces (its dimension, the range of every force, the contacts that can slide)."""
