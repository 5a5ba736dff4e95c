"""The arrays the C calls make by numpy's own PyArray_NewFromDescr (lcp/_numpy_abi.h, issue 23's
ninth pass) are the arrays numpy.empty made before, and no answer changes with the route.

* `_lemke_kernel.numpy_arrays` finds the route on the numpy installed (its C-API table) and
  checks arrays made by it -- type, dtype, shape, strides, flags, no base, the entries written
  through the data pointer read in C -- against numpy.empty's.
* `lcp.LCP`'s copies of M and q and a Solution's z, w and basis are such arrays; with the route
  off (numpy.empty called from C, as before) the Solutions are the same, field for field, bit
  for bit, and so are the arrays' properties.
* array_setup refuses what is not numpy's table for this ndarray type (then numpy.empty runs).
* The C call reads a plain float64 M and q's data from their array fields (no buffer request,
  session 10): `_fields_read_as_numpy` finds the fields read as numpy gives them, and with that
  route off (buffers, as before) every outcome is the same -- Solutions field for field, bit
  for bit, on every kind and size; the arrays the route declines (views, Fortran order,
  read-only, another dtype object or type, other shapes) give the same answer, tuple or error.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rigidlcp import lcp
from rigidlcp.lcp import _lemke_kernel as kernel
from rigidlcp.lcp.solvers import fast_lemke

from .test_entry_glue import same_outcome, seeded_problem
from .test_fast_lemke import assert_same_answer
from .test_speed_paths import SIZES, _problem

compiled = pytest.mark.skipif(not (kernel.enabled() and fast_lemke._solve_lcp is not None),
                              reason="the C extensions are not built or are off")


def route(on: bool) -> None:
    """Switch the route on (found and checked again) or off (numpy.empty from C)."""
    if on:
        kernel._arrays_found = None
        assert kernel.numpy_arrays()
    else:
        kernel._lemke_c.array_setup(None, np.dtype(np.float64), np.dtype(np.intp), np.ndarray)


@pytest.fixture
def restore():
    yield
    route(True)


def looks(a: np.ndarray) -> tuple:
    """What a user can see of an array besides its values."""
    return (type(a), a.dtype, a.shape, a.strides, kernel._flags(a), a.base is None)


def natural(M, q):
    """The natural call, and what its arrays look like."""
    P = lcp.LCP(M, q)
    sol = lcp.solve(P)
    return sol, [looks(a) for a in (P.M, P.q, sol.z, sol.w, sol.basis)]


@compiled
def test_the_route_is_found_and_checked():
    assert kernel.numpy_arrays()
    for shape in ((0,), (7,), (4, 5), (0, 3)):
        for integer in (False, True):
            a = kernel._lemke_c.array_probe(shape, integer)
            ref = np.empty(shape, np.intp if integer else np.float64)
            assert looks(a) == looks(ref)
            assert np.array_equal(a.ravel(), np.arange(a.size))  # written through the pointer


@compiled
@pytest.mark.parametrize("kind", ["psd", "general", "scaled", "degenerate", "ties"])
@pytest.mark.parametrize("n", (1, 2, *SIZES))
def test_the_same_answers_and_arrays_with_the_route_off(n, kind, restore):
    M, q = _problem(n, kind, 0)
    on, on_looks = natural(M, q)
    route(False)
    off, off_looks = natural(M, q)
    assert same_outcome(on, off)
    assert on_looks == off_looks
    assert on_looks[0] == looks(np.empty((n, n))) and on_looks[2] == looks(np.empty(n))
    assert on_looks[4][1] == np.dtype(np.intp)
    route(True)
    assert_same_answer(lcp.LCP(M, q))  # the C path against the general (numpy) path


@compiled
@settings(max_examples=60, deadline=None)
@given(st.integers(1, 40), st.integers(0, 2**32 - 1), st.sampled_from(["psd", "general", "q>=0"]))
def test_random_problems_with_the_route_on_and_off(n, seed, kind):
    M, q = seeded_problem(n, seed, kind)
    try:
        on, on_looks = natural(M, q)
        route(False)
        off, off_looks = natural(M, q)
    finally:
        route(True)
    assert same_outcome(on, off)
    assert on_looks == off_looks


@compiled
def test_the_copies_are_the_problems_own():
    M, q = np.eye(3) + 0.5, -np.ones(3)
    P = lcp.LCP(M, q)
    M[0, 0], q[0] = 99.0, 99.0
    assert P.M[0, 0] == 1.5 and P.q[0] == -1.0
    assert not np.shares_memory(P.M, M) and not np.shares_memory(P.q, q)
    P.M[1, 1] = 7.0  # the problem's arrays are writable, as M.copy()'s
    assert M[1, 1] == 1.5


@compiled
def test_array_setup_refuses_what_is_not_numpys_table(restore):
    f64, intp = np.dtype(np.float64), np.dtype(np.intp)
    capsule = kernel._array_capsule()
    assert capsule is not None
    assert not kernel._lemke_c.array_setup(None, f64, intp, np.ndarray)
    assert not kernel._lemke_c.array_setup(object(), f64, intp, np.ndarray)

    class Sub(np.ndarray):
        pass

    assert not kernel._lemke_c.array_setup(capsule, f64, intp, Sub)  # not the table's type
    with pytest.raises(RuntimeError):  # the route is off: nothing made by it
        kernel._lemke_c.array_probe((3,), False)
    sol, _ = natural(np.eye(2), -np.ones(2))  # numpy.empty from C: the same Solution
    route(True)
    assert same_outcome(sol, natural(np.eye(2), -np.ones(2))[0])


def fields_route(on: bool) -> None:
    assert kernel._lemke_c.array_fields_use(on) == on


def with_fields_route_and_without(call, M, q):
    """call(M, q) with the direct read of numpy's array fields on, then off (on again after)."""
    try:
        on = call(M, q)
        fields_route(False)
        return on, call(M, q)
    finally:
        fields_route(True)


def direct(M, q):
    """The C call on the arrays as given: its Solution, its tuple (as plain values and bytes),
    or the type of its error."""
    from rigidlcp.lcp.solvers.lemke import DEFAULT_TOL

    try:
        out = kernel._lemke_c.solve_lcp(M, q, DEFAULT_TOL, -1, kernel.sums_verified_upto())
    except (ValueError, TypeError, BufferError) as exc:
        return type(exc)
    if isinstance(out, tuple):
        return tuple(x.tobytes() if isinstance(x, np.ndarray) else x for x in out)
    return out


@compiled
def test_the_array_fields_are_read_as_numpy_gives_them():
    assert kernel._fields_read_as_numpy()
    a = np.arange(24.0).reshape(4, 6)[1:, ::3]
    address, nd, shape, strides, dtype, c_contiguous, writeable = kernel._lemke_c.array_fields(a)
    assert (address, nd, shape, strides) == (a.__array_interface__["data"][0], 2, (3, 2),
                                             (48, 24))
    assert dtype is a.dtype and not c_contiguous and writeable


@compiled
@pytest.mark.parametrize("kind", ["psd", "general", "scaled", "degenerate", "ties"])
@pytest.mark.parametrize("n", (1, 2, *SIZES))
def test_the_same_answers_with_the_field_route_off(n, kind):
    M, q = _problem(n, kind, 1)
    on, off = with_fields_route_and_without(natural, M, q)
    assert same_outcome(on[0], off[0]) and on[1] == off[1]


_ro = np.eye(3) + 0.5
_ro.flags.writeable = False


@compiled
@pytest.mark.parametrize("M, q", [
    (np.eye(3) + 0.5, -np.ones(3)),                               # plain: the route
    (np.asfortranarray(np.eye(3) + 0.5), -np.ones(3)),            # Fortran order
    ((np.eye(6) + 0.5)[::2, ::2], -np.ones(3)),                   # a strided view
    ((np.eye(4) + 0.5)[1:, 1:].copy(), -np.ones(4)[1:]),          # q a view at an offset
    (_ro, -np.ones(3)),                                           # read-only
    (np.eye(3) + 0.5, -np.ones((3, 1))),                          # q a column
    (np.eye(3) + 0.5, np.array(-1.0)),                            # q 0-d
    (np.eye(3) + 0.5, -np.ones(4)),                               # sizes differ
    (np.eye(3, dtype=np.float32), -np.ones(3)),                   # another float type
    (np.eye(3) + np.zeros(3, np.dtype(np.float64, metadata={"a": 1})), -np.ones(3)),
])
def test_the_arrays_the_field_route_declines_are_answered_as_before(M, q):
    on, off = with_fields_route_and_without(direct, M, q)
    assert type(on) is type(off)
    assert same_outcome(on, off) if hasattr(on, "z") else on == off
