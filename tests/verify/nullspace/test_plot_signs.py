"""The null-space figure shows the sign of S wherever S != 0, also where R != 0 (issue 24.7:
segments coloured by R alone hid it)."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.quiver import Quiver  # noqa: E402

from rigidlcp import models  # noqa: E402
from rigidlcp.verify.nullspace.plot import _draw_vector  # noqa: E402


def test_s_arrows_point_along_sign_of_s_even_where_r_is_nonzero():
    system = models.System(models.rectangular(3, 2), mu_pp=0.3, mu_plane=0.3, mu_wall=0.3,
                           gamma=0.0)
    c = system.c
    R, S = np.zeros(c), np.zeros(c)
    R[:3] = 1.0
    S[:3] = [0.5, -0.5, 0.25]  # R and S both nonzero
    S[5] = -1.0  # S alone
    fig, ax = plt.subplots()
    _draw_vector(ax, system, R, S, "v")
    quivers = [a for a in ax.get_children() if isinstance(a, Quiver)]
    assert len(quivers) == 1
    q = quivers[0]
    assert q.N == 4
    lat = system.lattice
    drawn = np.column_stack([q.U, q.V])
    for k, alpha in enumerate((0, 1, 2, 5)):
        # the arrow is S t: along +t for S > 0, along -t for S < 0
        assert np.sign(drawn[k] @ lat.t[alpha]) == np.sign(S[alpha])
    plt.close(fig)
