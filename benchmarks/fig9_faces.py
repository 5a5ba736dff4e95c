"""What the face selection does at each event of Fig. 9's run (a script, not a test).

    python benchmarks/fig9_faces.py

Rect 10 x 4, mu_pp = 0.1, mu_plane = 0.2, mu_wall = 0, gamma = 0.16 g, seed 1, lemke with the
default selection (face-min-norm). At every event, with the selection's own inputs: whether
`lcp.face.face_is_point` proves the face a point (then the selection is a no-op), the face's
null-space dimension (as face_minimum_norm reports it), and how far the selected point moves
the accelerations a_t, the total plane friction (mu_g's numerator) and the forces S from the
solver's vertex; with the time of face_is_point and of face_minimum_norm.
"""

from __future__ import annotations

import os
import time

import numpy as np

from rigidlcp import models
from rigidlcp.lcp.faces import face as lcp_face
from rigidlcp.models.lattice import PLANE


def main() -> int:
    import rigidlcp.models.engine.dense as dense

    original_face, original_ep = dense.face_minimum_norm, dense.event_problem
    current, rows = {}, []

    def ep_wrap(*a, **k):
        current["ep"] = original_ep(*a, **k)
        return current["ep"]

    def face_wrap(problem, z, G=None, **kw):
        t0 = time.perf_counter()
        check = lcp_face.face_is_point(problem, z, z_side=kw.get("z_side"))
        t1 = time.perf_counter()
        r = original_face(problem, z, G, **kw)
        t2 = time.perf_counter()
        ep = current["ep"]
        plane = ep.system.lattice.j == PLANE
        before, after = ep.unpack(z), ep.unpack(r.z)
        rows.append((check.point, r.nullity, np.abs(after.a_t - before.a_t).max(),
                     abs(after.S[plane].sum() - before.S[plane].sum()),
                     np.abs(after.S - before.S).max(), t1 - t0, t2 - t1))
        return r

    dense.face_minimum_norm, dense.event_problem = face_wrap, ep_wrap
    try:
        system = models.System(models.make_lattice("rect", 10, 4), mu_pp=0.1, mu_plane=0.2,
                               mu_wall=0.0, gamma=0.16)
        run = models.simulate(system, seed=1)
    finally:
        dense.face_minimum_norm, dense.event_problem = original_face, original_ep
    R = np.array(rows, dtype=float)
    print(f"Fig. 9 run: {run.status}, {run.n_events} events; load average "
          f"{os.getloadavg()[0]:.2f} (2-core machine shared with other jobs)")
    print(f"events whose face is proved a point (selection skippable): {int(R[:, 0].sum())}")
    print(f"null-space dimension of the face: min {int(R[:, 1].min())}, median "
          f"{int(np.median(R[:, 1]))}, max {int(R[:, 1].max())}")
    for col, name in ((2, "a_t"), (3, "plane friction sum S"), (4, "S")):
        moved = R[:, col] > 1e-9
        print(f"selection moves {name} by > 1e-9 at {int(moved.sum())} events "
              f"(max {R[:, col].max():.3g})")
    print(f"median time per event: face_is_point {1e3 * np.median(R[:, 5]):.2f} ms, "
          f"face_minimum_norm {1e3 * np.median(R[:, 6]):.2f} ms")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
