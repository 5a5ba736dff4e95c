"""Force networks in indeterminate states (Sec. III C): polyhedra of admissible forces, ranges,
particular solutions."""
