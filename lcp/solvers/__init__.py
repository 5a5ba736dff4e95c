"""The methods: one module per method (with its C source where it has one), each registering
itself with `lcp.registry.register` on import.

`BUILTIN` maps each built-in method to the module of this package that registers it, in the
order `lcp.methods()` lists them; `lcp.api.get_method` imports only the module asked for (so
that e.g. lemke never loads the QP solvers). Adding a method: docs/architecture.md, "Adding a
method".
"""

#: Built-in method -> the module of lcp/solvers/ that registers it (in `lcp.methods()` order).
BUILTIN = {"enumerate": "enumeration", "lemke": "lemke", "enumerate-mlcp": "mlcp_full",
           "newton-min": "newton", "newton-fb": "newton", "nsgs": "nsgs", "pgs": "pgs",
           "pivoting": "pivoting", "qp-clarabel": "qp", "qp-osqp": "qp", "states": "states"}
