"""`rigidlcp forceset`'s progress bar counts range ends, each once, whether an LP, a kept
basis or a bound attained at a checked point settled it (verify.statics.range_ends): it ends at
its total exactly, and its label says it counts ends (it counted LPs before, and a 300-disk pile
showed 2400 against 2006 LPs run)."""

from __future__ import annotations

import io

import numpy as np
import pytest
from tqdm import tqdm

from rigidlcp import models
from rigidlcp.cli.forceset import EndsBar
from rigidlcp.models import progress as progress_module
from rigidlcp.verify.statics.forceset import analyse


@pytest.mark.parametrize("jobs", [1, 2])
def test_bar_final_count_equals_its_total(monkeypatch, jobs):
    made: list = []

    def quiet_bar(**kwargs):
        kwargs["file"] = io.StringIO()
        made.append(tqdm(**kwargs))
        return made[-1]

    monkeypatch.setattr(progress_module, "new_bar", quiet_bar)
    system = models.System(models.rectangular(3, 3), mu_pp=0.3, mu_plane=0.5, mu_wall=0.2)
    bar = EndsBar()
    fs = analyse(system, progress=bar, jobs=jobs)
    assert fs.exists and len(made) == 1
    b = made[0]
    # every end once: max and min R of each contact not at R = 0 on all of P, max and min S
    # of each such frictional contact whose S is not fixed (S = 0 or S = +-mu R on all of P)
    kinds = fs.implicit
    ends = 2 * sum(k != "R=0" for k in kinds) + 2 * sum(
        mu > 0 and not k for mu, k in zip(np.asarray(system.mu), kinds, strict=True))
    assert b.n == b.total == ends > 0
    assert b.unit == "end" and "ends" in b.desc
    bar.close()
