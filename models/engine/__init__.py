"""The event engine (Sec. II C): one event loop with dense and sparse backends.

* `loop.py` — `run_events`: advance to the next event, solve it, record it, stop rules;
* `dense.py` — `DenseBackend`: the event LCP solved by any `lcp` method, selection among
  solutions; `sparse.py` — `SparseBackend`: warm-started pivoting on contact states on one
  sparse LU (`sparse_pivoting.py`), and `simulate_sparse`;
* `records.py` — `EventRecord`, `Run`; `simulate.py` — `simulate`, which picks the backend.
"""

from .records import EventRecord, Run
from .simulate import simulate

__all__ = ["EventRecord", "Run", "simulate"]
