"""rigidlcp.bench.problem_sets and lcp.io.siconos: every set holds problems of its promised class,
checked independently of the constructions (minors, eigenvalues, LP certificates); the Siconos
reader and writer round-trip and agree with Siconos's own reader when it is installed."""

from __future__ import annotations

import itertools
import json
import subprocess
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import linprog

from rigidlcp import lcp, models
from rigidlcp.bench.problem_sets import (
    P_KINDS,
    get_set,
    infeasible_lcp,
    list_sets,
    load_folder,
    murty_lcp,
    random_p_matrix,
)
from rigidlcp.lcp.io.siconos import read_siconos_lcp, write_siconos_lcp
from rigidlcp.verify import certify

SYSTEM_PYTHON = "/usr/bin/python3"
SMALL = (1, 2, 3, 5, 8)


def all_minors_positive(M: np.ndarray) -> bool:
    n = M.shape[0]
    for k in range(1, n + 1):
        for alpha in itertools.combinations(range(n), k):
            if np.linalg.det(M[np.ix_(alpha, alpha)]) <= 0:
                return False
    return True


def sampled_minors_positive(M: np.ndarray, rng: np.random.Generator, count: int = 300) -> bool:
    """Random principal minors (every size), by the sign of slogdet."""
    n = M.shape[0]
    for _ in range(count):
        alpha = np.flatnonzero(rng.uniform(size=n) < rng.uniform(0.05, 1.0))
        if alpha.size == 0:
            continue
        sign, _ = np.linalg.slogdet(M[np.ix_(alpha, alpha)])
        if sign <= 0:
            return False
    return True


def farkas_certificate(M: np.ndarray, q: np.ndarray) -> np.ndarray | None:
    """y >= 0 with M'y <= 0 and q'y <= -1 (an LP), or None when there is none."""
    n = q.size
    A = np.vstack([M.T, q[None, :]])
    b = np.concatenate([np.zeros(n), [-1.0]])
    res = linprog(np.zeros(n), A_ub=A, b_ub=b, bounds=[(0, None)] * n, method="highs")
    return res.x if res.status == 0 else None


def lcp_feasible(M: np.ndarray, q: np.ndarray) -> bool:
    """Is {z >= 0 : M z + q >= 0} non-empty? (an LP)"""
    n = q.size
    res = linprog(np.zeros(n), A_ub=-M, b_ub=q, bounds=[(0, None)] * n, method="highs")
    return res.status == 0


# --- generated sets -------------------------------------------------------------------------

def test_every_named_set_is_listed_with_a_class():
    names = {s.name for s in list_sets()}
    assert {"random-p", "random-psd", "singular-psd", "degenerate", "murty", "infeasible",
            "events-rect", "events-tri"} <= names
    for s in list_sets():
        assert s.expected in ("solution", "infeasible") and s.problem_class


def test_sets_are_reproducible_from_their_seed():
    a, b = get_set("random-p", seed=3), get_set("random-p", seed=3)
    c = get_set("random-p", seed=4)
    assert all(np.array_equal(x.M, y.M) and np.array_equal(x.q, y.q) for x, y in zip(a, b))
    assert not all(np.array_equal(x.M, y.M) for x, y in zip(a, c))


@pytest.mark.parametrize("kind", P_KINDS)
def test_random_p_matrices_have_positive_principal_minors(kind):
    for n in SMALL:
        for seed in range(5):
            M = random_p_matrix(n, np.random.default_rng([seed, n]), kind)
            assert all_minors_positive(M), (kind, n, seed)


def test_random_p_set_small_sizes_all_minors_and_default_set_sampled_minors():
    for p in get_set("random-p", sizes=SMALL, per_size=4):
        assert p.meta["class"] == "P-matrix" and all_minors_positive(p.M), p.name
    rng = np.random.default_rng(0)
    kinds = set()
    for p in get_set("random-p"):
        kinds.add(p.meta["kind"])
        ok = all_minors_positive(p.M) if p.n <= 8 else sampled_minors_positive(p.M, rng)
        assert ok, p.name
    assert kinds == set(P_KINDS)


def test_triangular_kind_reaches_p_matrices_that_are_not_positive_definite():
    found = [np.linalg.eigvalsh(M + M.T)[0] < 0 for M in
             (random_p_matrix(6, np.random.default_rng(s), "triangular") for s in range(20))]
    assert any(found)


def test_random_psd_is_symmetric_positive_definite():
    for p in get_set("random-psd"):
        assert np.array_equal(p.M, p.M.T)
        assert np.linalg.eigvalsh(p.M)[0] >= 0.1 - 1e-10 * np.abs(p.M).max(), p.name


def test_singular_psd_is_singular_psd_and_solved_by_its_planted_z():
    for p in get_set("singular-psd"):
        lam = np.linalg.eigvalsh(p.M)
        scale = max(1.0, abs(lam[-1]))
        assert np.array_equal(p.M, p.M.T)
        assert lam[0] >= -1e-12 * scale
        assert np.linalg.matrix_rank(p.M, tol=1e-10 * scale) < p.n, p.name
        z = np.array(p.meta["planted_z"])
        assert lcp.complementarity_residual(z, p.M @ z + p.q) <= 1e-12 * scale


def test_degenerate_set_has_degenerate_solutions_and_duplicated_rows():
    for p in get_set("degenerate"):
        z = np.array(p.meta["planted_z"])
        w = p.M @ z + p.q
        scale = max(1.0, np.abs(p.M).max(), np.abs(p.q).max())
        assert lcp.complementarity_residual(z, w) <= 1e-12 * scale
        assert np.any((z == 0) & (np.abs(w) <= 1e-12 * scale)), p.name  # a degenerate pair
        assert p.meta["duplicated"]
        for i, j in p.meta["duplicated"]:
            assert np.array_equal(p.M[i], p.M[j]) and np.array_equal(p.M[:, i], p.M[:, j])
        assert np.linalg.matrix_rank(p.M) < p.n  # duplicated rows: singular, so not P


def test_murty_set_is_murtys_example():
    problems = get_set("murty")
    assert [p.n for p in problems] == [4, 6, 8, 10, 12, 14, 16]
    for p in problems:
        n = p.n
        for i, j in itertools.product(range(n), range(n)):
            assert p.M[i, j] == (1.0 if i == j else 2.0 if i > j else 0.0)
        expected = [-sum(2.0 ** (n - k) for k in range(i + 1)) for i in range(n)]
        assert p.q.tolist() == expected
    for n in (2, 4, 6):
        assert all_minors_positive(murty_lcp(n).M)
        assert lcp.solve(murty_lcp(n), method="lemke", equilibrate=False).iterations == 2**n


def test_infeasible_set_is_copositive_plus_and_proved_infeasible_by_an_lp():
    problems = get_set("infeasible")
    assert problems
    for p in problems:
        assert p.meta["expected"] == "infeasible"
        S = p.M + p.M.T
        assert np.linalg.eigvalsh(S)[0] >= -1e-10 * max(1.0, np.abs(S).max()), p.name
        y = farkas_certificate(p.M, p.q)
        assert y is not None, p.name  # found by the LP, not taken from the construction
        assert not lcp_feasible(p.M, p.q), p.name


def test_the_farkas_check_can_fail():
    # A solvable problem has no certificate, and a non-copositive M is caught by eigenvalues.
    p = get_set("random-psd", sizes=(5,), per_size=1)[0]
    assert farkas_certificate(p.M, p.q) is None and lcp_feasible(p.M, p.q)
    indefinite = np.array([[0.0, 1.0], [1.0, 0.0]])
    assert np.linalg.eigvalsh(indefinite + indefinite.T)[0] < 0
    # ... and a certificate is not an artefact of the construction's q: flipping q'y's sign
    # (q -> q + 2 |q'y| y / |y|^2 makes q'y > 0) leaves none.
    p = infeasible_lcp(4, np.random.default_rng(0))
    y = np.array(p.meta["farkas_y"])
    q = p.q + 2 * abs(p.q @ y) * y / (y @ y)
    assert farkas_certificate(p.M, q) is None or np.linalg.matrix_rank(p.M) < 3


# --- event sets -----------------------------------------------------------------------------

def test_event_sets_are_real_event_lcps(tmp_path):
    sizes = ((2, 2), (3, 2))
    for lattice in ("rect", "tri"):
        problems = get_set(f"events-{lattice}", sizes=sizes, per_run=3, cache_dir=tmp_path)
        assert len(problems) == 6
        for p in problems:
            lat = models.make_lattice(lattice, p.meta["lx"], p.meta["ly"])
            c, k = int(p.meta["c"]), int(p.meta["k"])
            assert c == lat.c == p.meta["contacts"] and p.n == c + 2 * k
            # rows of 2 mu R - tau: [2 mu P, -I, 0] (Eq. 2.7 in the LCP form)
            assert np.array_equal(p.M[c + k:, c:c + k], -np.eye(k))
            assert np.all(p.M[c + k:, c + k:] == 0)
            sol = lcp.solve(p, method="lemke")
            assert certify(p, sol, uniqueness="none").accepted, p.name


def test_event_harvest_is_cached(tmp_path, monkeypatch):
    first = get_set("events-rect", sizes=((2, 2),), per_run=2, cache_dir=tmp_path)

    def boom(*args, **kwargs):
        raise AssertionError("the harvest ran again")

    monkeypatch.setattr(models, "simulate", boom)
    again = get_set("events-rect", sizes=((2, 2),), per_run=2, cache_dir=tmp_path)
    assert [p.name for p in first] == [p.name for p in again]
    assert all(np.array_equal(a.M, b.M) for a, b in zip(first, again))


# --- folders and the Siconos format ---------------------------------------------------------

def test_a_folder_is_a_set_of_npz_and_siconos_files(tmp_path):
    rng = np.random.default_rng(1)
    a = lcp.LCP(random_p_matrix(3, rng), rng.standard_normal(3))
    b = lcp.LCP(random_p_matrix(4, rng), rng.standard_normal(4))
    a.save(tmp_path / "a.npz")
    write_siconos_lcp(b, tmp_path / "b.dat")
    mlcp = lcp.MLCP(np.diag([2.0, 4.0]), -np.eye(2), np.eye(2), np.eye(2), [1.0, -2.0],
                    [0.5, -1.0])
    mlcp.save(tmp_path / "c.npz")
    (tmp_path / "notes.txt").write_text("ignored")
    problems = get_set(str(tmp_path))
    assert [p.name for p in problems] == [f"{tmp_path.name}/{x}" for x in "abc"]
    assert np.array_equal(problems[0].M, a.M) and np.array_equal(problems[1].q, b.q)
    # an MLCP enters as itself (issue 12: its A may be singular; the methods decide)
    assert isinstance(problems[2], lcp.MLCP) and np.array_equal(problems[2].B, mlcp.B)
    empty = tmp_path / "empty"
    empty.mkdir()
    with pytest.raises(ValueError, match="no \\*.npz"):
        load_folder(empty)
    with pytest.raises(ValueError, match="unknown problem set"):
        get_set("no-such-set")


@pytest.mark.parametrize("blocks", [None, [2, 3, 1], [6]])
def test_siconos_writer_round_trips(tmp_path, blocks):
    rng = np.random.default_rng(7)
    M = rng.standard_normal((6, 6)) * 10.0 ** rng.integers(-5, 5, (6, 6))
    M[0:2, 2:5] = 0.0  # a zero block: not stored in sparse-block form
    p = lcp.LCP(M, rng.standard_normal(6))
    back = read_siconos_lcp(write_siconos_lcp(p, tmp_path / "p.dat", blocks=blocks))
    assert np.array_equal(back.M, p.M) and np.array_equal(back.q, p.q)  # bit for bit
    assert back.meta["storage"] == ("dense" if blocks is None else "sparse-block")


def test_siconos_reader_reads_the_documented_layout(tmp_path):
    # Dense: a line per *column* of M; free text after q is ignored.
    (tmp_path / "d.dat").write_text("2\n0\n2\n2\n2\t2\n1 3\n2 4\n-1 -2\n\nA remark.\n")
    d = read_siconos_lcp(tmp_path / "d.dat")
    assert d.M.tolist() == [[1, 2], [3, 4]] and d.q.tolist() == [-1, -2]
    # Sparse block: 3 x 3 with blocks {0,1} x {0,1} and {2} x {2}; block row 1 lists 1 block.
    text = "3\n1\n3\n3\n2\n2\n2\n2 3\n2 3\n3\n2\n0 1 2\n0 1\n0\n4 1 2 5\n1\n9\n7 8 9\n"
    (tmp_path / "b.dat").write_text(text)
    b = read_siconos_lcp(tmp_path / "b.dat")
    assert b.M.tolist() == [[4, 2, 0], [1, 5, 0], [0, 0, 9]] and b.q.tolist() == [7, 8, 9]


@pytest.mark.parametrize("text, match", [
    ("2\n0\n2\n2\n2\t2\n1 3\n2 4\n-1\n", "line 8: the file ends after 1 of the 2 numbers of q"),
    ("2\n0\n3\n3\n3\t3\n", "line 2: M is 3 x 3, the problem's size needs 2 x 2"),
    ("2\n2\n2\n2\n", "line 4: the file ends where the sparse origin of M"),
    ("2\n0\n2\n2\n2\t2\n1 x\n2 4\n-1 -2\n", "line 6: 'x' where the entries of M"),
    ("2\n7\n2\n2\n", "line 2: unknown storage type 7"),
])
def test_siconos_reader_names_what_is_wrong(tmp_path, text, match):
    (tmp_path / "bad.dat").write_text(text)
    with pytest.raises(lcp.InvalidProblem, match=match):
        read_siconos_lcp(tmp_path / "bad.dat")


def _siconos_reader_available() -> bool:
    if not Path(SYSTEM_PYTHON).exists():
        return False
    out = subprocess.run([SYSTEM_PYTHON, "-c", "import siconos.numerics"],
                         capture_output=True, check=False)
    return out.returncode == 0


READ_WITH_SICONOS = """
import json, sys
import numpy as np
import siconos.numerics as sn
n = int(sys.argv[2])
p = sn.LCP(np.eye(n), np.zeros(n))
sn.linearComplementarity_newFromFilename(p, sys.argv[1])
m = p.M
if isinstance(m, np.ndarray):
    M = m
else:
    M = np.array([[sn.SBM_get_value(m, i, j) for j in range(n)] for i in range(n)])
print(json.dumps({"M": np.asarray(M).tolist(), "q": np.asarray(p.q).tolist()}))
"""


@pytest.mark.skipif(not _siconos_reader_available(),
                    reason="the system interpreter has no siconos.numerics")
@pytest.mark.parametrize("blocks", [None, [2, 3]])
def test_siconos_own_reader_reads_what_we_write(tmp_path, blocks):
    rng = np.random.default_rng(3)
    M = rng.standard_normal((5, 5))
    M[0:2, 2:5] = 0.0
    p = lcp.LCP(M, rng.standard_normal(5))
    path = write_siconos_lcp(p, tmp_path / "p.dat", blocks=blocks)
    out = subprocess.run([SYSTEM_PYTHON, "-c", READ_WITH_SICONOS, str(path), "5"],
                         capture_output=True, text=True, check=True)
    got = json.loads(out.stdout)
    assert np.array_equal(np.array(got["M"]), M) and np.array_equal(np.array(got["q"]), p.q)


def test_infeasible_set_is_proved_infeasible_exactly():
    """The "infeasible" set is built from integers, so its y proves infeasibility in the stored
    doubles (M^T y = 0 and q^T y < 0 exactly), and lcp.solve's answer is "infeasible" with a
    certificate checked in exact rationals (a float-built set had solvable members)."""
    for p in get_set("infeasible", sizes=(4, 16), per_size=2):
        y = np.array(p.meta["farkas_y"])
        assert np.all(y >= 0) and not np.any(p.M.T @ y) and p.q @ y < 0
        assert np.all(p.M == np.round(p.M)) and np.all(p.q == np.round(p.q))
        sol = lcp.solve(p)
        assert sol.status == "infeasible" and sol.info["farkas_exact"] is True, sol.message
