"""verify.statics.plot: the force-set figure draws with matplotlib's supported API only (no
deprecation warning: the colormap's grey for an unknown end comes from `with_extremes`, not
the deprecated `Colormap.set_bad`)."""

from __future__ import annotations

import numpy as np
import pytest

from rigidlcp import models
from rigidlcp.verify.statics.forceset import analyse
from rigidlcp.verify.statics.plot import plot_forceset

pytest.importorskip("matplotlib")


@pytest.mark.filterwarnings("error")  # a (pending) deprecation warning fails the test
def test_forceset_figure_without_deprecated_api(tmp_path):
    # the frictionless pyramid of test_forceset.py (case 3), with friction: a set with ranges
    lat = models.packing.packing(np.array([[1.0, 1.0], [3.0, 1.0], [2.0, 1.0 + 3.0 ** 0.5]]),
                                 np.ones(3), left=0.0, right=4.0)
    fs = analyse(models.System(lat, mu_pp=0.3, mu_plane=0.3, mu_wall=0.3))
    assert fs.exists
    import matplotlib.image as mpimg

    def grey(path) -> int:  # pixels in the 0.6 grey of the colormap's "bad" colour
        img = mpimg.imread(path)
        return int(np.sum(np.all(np.abs(img[..., :3] - 0.6) < 0.003, axis=-1)))

    known = grey(plot_forceset(fs, tmp_path / "known.png"))
    fs.hi = fs.hi.copy()
    fs.hi[0] = np.nan  # an unknown end: its contact drawn grey
    assert grey(plot_forceset(fs, tmp_path / "unknown.png")) > known
