"""Dense and sparse event paths where events have several solutions (issue 6).

With select="none" the dense path keeps the vertex its solver reaches; the sparse pivoting may
reach another one. The runs must then agree event by event up to the first event where they
differ, and there the sparse answer must be a certified solution of the same event LCP, and
verify.certify must show that the event has another solution differing in what differs
(accelerations, or forces only): a genuine non-uniqueness (hyperstatic rows, friction), not an
error of either path. Runs with unique events agree throughout (tests/models).
"""

from __future__ import annotations

import numpy as np
import pytest

from rigidlcp import models
from rigidlcp.models.engine.sparse import simulate_sparse
from rigidlcp.models.event import event_problem
from rigidlcp.verify import certify

FIG9 = dict(mu_pp=0.1, mu_plane=0.2, mu_wall=0.0, gamma=0.16)


def z_of(ep, rec):
    cand, mu = ep.candidates, ep.system.mu
    return np.concatenate([rec.R, mu[cand] * rec.R[cand] + rec.S[cand],
                           np.where(rec.s[cand] == -1, -rec.at[cand], 0.0)])


@pytest.mark.parametrize("lattice, lx, ly, mu_wall, seed", [
    ("tri", 4, 3, 0.0, 1), ("rect", 4, 3, 0.3, 1), ("tri", 3, 2, 0.0, 2),
])
def test_runs_agree_until_an_event_with_several_solutions(lattice, lx, ly, mu_wall, seed):
    system = models.System(models.make_lattice(lattice, lx, ly), **{**FIG9,
                                                                    "mu_wall": mu_wall})
    dense = models.simulate(system, seed=seed, method="lemke", select="none", max_events=200)
    sparse = simulate_sparse(system, seed=seed, max_events=200)
    first = None
    for k, (a, b) in enumerate(zip(dense.records, sparse.records)):
        assert np.array_equal(a.s_in, b.s_in), k  # the same event problem
        acc = float(np.max(np.abs(a.omega_dot - b.omega_dot)))
        frc = max(float(np.max(np.abs(a.R - b.R))), float(np.max(np.abs(a.S - b.S))))
        if acc > 1e-9 or frc > 1e-9:
            first = (k, acc > 1e-9)
            break
    if first is None:  # no event with several solutions was met: the runs agree throughout
        assert dense.n_events == sparse.n_events and dense.status == sparse.status
        return
    k, accelerations_differ = first
    ep = event_problem(system, dense.state_at(k))
    mine = certify(ep, z_of(ep, sparse.records[k]), uniqueness="none")
    assert mine.accepted, mine
    theirs = certify(ep, z_of(ep, dense.records[k]), uniqueness="milp")
    assert theirs.accepted
    if accelerations_differ:
        assert theirs.observables["accelerations"] is False, theirs
    else:
        assert theirs.observables["forces"] is False, theirs
