"""Fig. 9's run (rect 10 x 4, mu_pp = 0.1, mu_plane = 0.2, mu_wall = 0, gamma = 0.16 g, seed 1,
lemke + face-min-norm) against the results saved from the code before the speed work of issue
13 (tests/data/fig9_rect10x4_seed1.npz, commit b4168d3): the same events, states, forces and
mu_g to 1e-9. A speed-up (compiled pivots, a skipped selection) must not change the run."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from rigidlcp import models
from rigidlcp.lcp import _lemke_kernel as kernel
from rigidlcp.lcp import face as lcp_face

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


@pytest.mark.parametrize("compiled", [True, False])
def test_fig9_run_matches_the_saved_reference(compiled):
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
