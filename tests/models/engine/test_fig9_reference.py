"""Fig. 9's run (rect 10 x 4, mu_pp = 0.1, mu_plane = 0.2, mu_wall = 0, gamma = 0.16 g, seed 1,
lemke + face-min-norm) against the results saved from the code before the speed work of issue
13 (tests/data/fig9_rect10x4_seed1.npz, commit b4168d3): the same events, states, forces and
mu_g to 1e-9. A speed-up (compiled pivots, a skipped selection) must not change the run.

The data were saved with the face selection's reference solvers (HiGHS, Clarabel, SVD:
lcp.face_reference), which the first two tests use. The default solvers (lcp.face_coords) give
the same run except at event 62, where the reference path's selection failed its own accuracy
check (HiGHS's vertex solved (M y + q)_A = 0 to 1.05e-11, above the limit 9.2e-12) and the run
kept Lemke's solution; the default path selects there (third test)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from rigidlcp import lcp, models
from rigidlcp.lcp import _lemke_kernel as kernel
from rigidlcp.lcp.faces import face as lcp_face

DATA = Path(__file__).parents[2] / "data"
FIELDS = ("t", "V", "omega", "omega_dot", "R", "S", "s", "s_in", "vt", "at", "mu_g",
          "dissipation", "iterations", "n_lcp")


def fig9_run():
    system = models.System(models.make_lattice("rect", 10, 4), mu_pp=0.1, mu_plane=0.2,
                           mu_wall=0.0, gamma=0.16)
    return models.simulate(system, seed=1)


def assert_matches_reference(run) -> None:
    meta = json.loads((DATA / "fig9_rect10x4_seed1.json").read_text())
    ref = np.load(DATA / "fig9_rect10x4_seed1.npz")
    assert (run.status, run.n_events) == (meta["status"], meta["n_events"])
    for name in FIELDS:
        got, want = run.array(name), ref[name]
        assert got.shape == want.shape, name
        if name in ("s", "s_in", "iterations", "n_lcp"):
            np.testing.assert_array_equal(got, want, err_msg=name)
        else:
            scale = max(1.0, float(np.abs(want).max()))
            np.testing.assert_allclose(got, want, rtol=0, atol=1e-9 * scale, err_msg=name)
    np.testing.assert_allclose(run.final.omega, ref["final_omega"], rtol=0, atol=1e-9)


REFERENCE_FAILED_AT = 62  # the event where the reference path's selection failed (docstring)


def use_face_solvers(monkeypatch, solvers: str):
    import rigidlcp.models.engine.dense as dense

    def selection(*a, **k):
        return lcp_face.face_minimum_norm(*a, solvers=solvers, **k)

    monkeypatch.setattr(dense, "face_minimum_norm", selection)


@pytest.mark.parametrize("compiled", [True, False])
def test_fig9_run_matches_the_saved_reference(compiled, monkeypatch):
    use_face_solvers(monkeypatch, "reference")
    previous = kernel.use_compiled(compiled)
    try:
        assert_matches_reference(fig9_run())
    finally:
        kernel.use_compiled(previous)


def test_fig9_run_with_the_face_point_shortcut(monkeypatch):
    """The hook the engine may use: skip face_minimum_norm where lcp.face.face_is_point proves
    the face is {z}. The run must not change (on Fig. 9 no event's face is a point: each has
    a null space of dimension 4-23, so the shortcut never fires there; it must not misfire)."""
    import rigidlcp.models.engine.dense as dense

    use_face_solvers(monkeypatch, "reference")
    original, fired = dense.face_minimum_norm, []

    def with_shortcut(problem, z, G=None, **kw):
        check = lcp_face.face_is_point(problem, z, z_side=kw.get("z_side"))
        if check.point:
            fired.append(check)
            return lcp_face.FaceResult(np.asarray(z, float), 0, 0.0, "unique")
        return original(problem, z, G, **kw)

    monkeypatch.setattr(dense, "face_minimum_norm", with_shortcut)
    assert_matches_reference(fig9_run())
    assert fired == []


def test_default_face_solvers_differ_from_the_reference_at_event_62_only(monkeypatch):
    """The default solvers' run with event 62 kept as the reference path kept it (Lemke's
    solution) is the saved run to 1e-9 in every field; at event 62 the reference path's
    selection fails its accuracy check while the default path's point is a solution to the
    limit with a lower sum R, i.e. the reference missed the selection there, nothing else."""
    import rigidlcp.models.engine.dense as dense

    calls, seen = [0], {}

    def selection(problem, z, G=None, **kw):
        event = calls[0]
        calls[0] += 1
        new = lcp_face.face_minimum_norm(problem, z, G, **kw)
        if event != REFERENCE_FAILED_AT:
            return new
        seen["new"], seen["z"], seen["problem"], seen["c"] = new, np.asarray(z), problem, kw["c"]
        seen["old"] = lcp_face.face_minimum_norm(problem, z, G, solvers="reference", **kw)
        return seen["old"]  # as the saved run: failed, the engine keeps Lemke's z

    monkeypatch.setattr(dense, "face_minimum_norm", selection)
    assert_matches_reference(fig9_run())
    new, old, z, c = seen["new"], seen["old"], seen["z"], seen["c"]
    assert old.status.startswith("failed: inaccurate face point")
    assert new.status == "selected"
    M, q = seen["problem"].M, seen["problem"].q
    scale = max(np.abs(q).max(), np.abs(z).max())
    limit = max(10.0 * lcp.complementarity_residual(z, M @ z + q), 1e-12 * scale)
    assert lcp.complementarity_residual(new.z, M @ new.z + q) <= limit
    assert c @ new.z < c @ z - 0.1  # the least total normal force, well below Lemke's
