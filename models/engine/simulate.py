"""`simulate`: the event-driven evolution of a system, on the dense or the sparse backend."""

from __future__ import annotations

import os
from collections.abc import Callable

import numpy as np

from rigidlcp.lcp.errors import InvalidInput
from rigidlcp.models.dynamics import Dynamics
from rigidlcp.models.event import State, initial_state
from rigidlcp.models.system import System

from .dense import DenseBackend, closed_note, selection_note
from .loop import Limits, blas_limit, run_events
from .records import Run


def simulate(
    system: System,
    state: State | None = None,
    *,
    method: str = "lemke",
    omega: np.ndarray | None = None,
    seed: int | None = None,
    t_max: float = np.inf,
    max_events: int = 100_000,
    check_tol: float = 1e-8,
    warm_start: bool = True,
    zeno_events: int = 200,
    zeno_time: float = 1e-6,
    progress: Callable[[Run], None] | bool | None = None,
    dump_dir: str | None = None,
    select: str = "face-min-norm",
    fallback: str | None = "lemke",
    blas_threads: int | None = 1,
    selection: str | None = None,
    closed_search: bool = True,
) -> Run:
    """Evolve `system` from `state` (or from omega / a seed) event by event (Sec. II C, IV).

    method: any `lcp` method, solving each event's dense LCP (models/engine/dense.py; "pivoting"
    is warm-started from the previous event's contact states when warm_start is true), or
    "sparse-pivoting": the sparse backend (models/engine/sparse.py; select "none" only, no
    dump_dir). A dense run too large for the memory is refused first (`check_dense_memory`).
    Every solution's residual max|min(z, w)| must be <= check_tol (in units of the problem's
    scale), or the run stops with "solver_failed"; the other stop rules and their parameters
    (t_max, max_events, zeno_events, zeno_time) are models/engine/loop.py's.

    selection (or its older name select): the rule that picks the particular solution of an
    event whose solution is not unique: "face-min-norm" (default), "max-sum-R[:CAP]",
    "random:SEED", "global" or "none" (models/selection.py, `DenseBackend`). fallback: when
    `method` fails at an event (no solution, cycling, iteration limit), that event is solved
    again by this method (None: stop); each use is counted in the record. progress: called
    with the run after each event (None or False: not called). blas_threads: BLAS threads
    during the run (the event problems are small dense matrices, for which one thread is
    fastest, and much faster on a loaded machine); None leaves BLAS alone.

    closed_search (both backends): when an event's selected solution would open a contact or
    translate a disk, look for a solution of the same event keeping every contact closed and
    follow it, or prove there is none (models/engine/closed.py); run.closed lists the events
    where one was followed. It runs only where the run would otherwise stop, so a run that
    never detaches is the same bit for bit with or without it.
    """
    select = _one_rule(select, selection)
    backend = _backend(system, method, select, fallback, warm_start, dump_dir, check_tol)
    backend.closed_search = bool(closed_search)
    if state is None:
        state = initial_state(system, omega=omega, seed=seed)
    limits = Limits(t_max, max_events, check_tol, zeno_events, zeno_time)
    if progress is True or progress is False:
        progress = None if progress is False else _print_progress
    with blas_limit(blas_threads):
        run = run_events(system, state, backend, limits, progress or None)
    return selection_note(backend, closed_note(backend, run))


def _backend(system: System, method: str, select: str, fallback: str | None, warm_start: bool,
             dump_dir: str | None, check_tol: float):
    """The backend of `simulate`: sparse for "sparse-pivoting", else dense (refused first when
    its matrices cannot fit in memory)."""
    if method != "sparse-pivoting":
        check_dense_memory(system.c, f"the dense event LCP of {system.c} contacts")
    dyn = Dynamics(system)
    if method == "sparse-pivoting":
        if select != "none":
            raise ValueError("method 'sparse-pivoting' keeps the pivoting's own solution: "
                             "use select='none'")
        if dump_dir is not None:
            raise ValueError("method 'sparse-pivoting' does not dump problems (dump_dir)")
        # imported here: a dense run needs no sparse LU (scipy.sparse.linalg, ~0.1 s to load)
        from .sparse import SparseBackend

        return SparseBackend(system, dyn, warm_start=warm_start, fallback=fallback,
                             check_tol=check_tol)
    return DenseBackend(system, dyn, method=method, fallback=fallback, select=select,
                        warm_start=warm_start, dump_dir=dump_dir, check_tol=check_tol)


def _one_rule(select: str, selection: str | None) -> str:
    """The selection rule, given by its name `selection` or its older name `select`."""
    if selection is None or select in ("face-min-norm", selection):
        return select if selection is None else selection
    raise ValueError(f"select={select!r} and selection={selection!r}: give one")


def dense_bytes(contacts: int) -> int:
    """A lower bound on the memory of one dense event of an array with c = `contacts` contacts
    (bytes): W = H M^-1 H^T (2c x 2c), and the event's G (2c x n), B and M (n x n) with
    n >= c (models/event.py, Eq. 2.7)."""
    c = int(contacts)
    return 8 * (4 * c * c + 2 * c * c + 2 * c * c)


def available_bytes() -> int | None:
    """The memory the system can give now (MemAvailable, else the physical memory; None when
    unknown)."""
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):
        return None


#: What to use instead of a dense run that cannot fit in memory.
SPARSE_INSTEAD = ("use the sparse backend (--method sparse-pivoting --select none; Python: "
                  "method='sparse-pivoting', select='none')")


def check_dense_memory(contacts: int, what: str, available: int | None = None,
                       instead: str = SPARSE_INSTEAD) -> None:
    """Refuse, before anything is allocated, a dense computation whose matrices cannot fit in
    memory (InvalidInput saying `instead` what to do). `what` names the computation and the
    array; `contacts` may be a lower bound (every disk rests on at least one contact: c >= p).
    """
    need = dense_bytes(contacts)
    have = available_bytes() if available is None else available
    if have is not None and need > have:
        raise InvalidInput(f"{what}: at least {need / 2**30:.1f} GiB of memory needed, "
                           f"{have / 2**30:.1f} GiB available; {instead}")


def _print_progress(run: Run) -> None:
    """progress=True: one line per 100 events."""
    if run.n_events % 100 == 0:
        print(f"event {run.n_events}: t = {run.last.t:.6g}", flush=True)
