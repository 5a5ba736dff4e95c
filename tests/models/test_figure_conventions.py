"""Figures a new user read wrong (issue 24.7): symlog time axes labelled as such with one linear
threshold, no paper figure number on a run that is not the paper's, the force key within the
figure, the time-stepper's records and dissipated energy from t = 0."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from rigidlcp import models  # noqa: E402
from rigidlcp.models.plot import TIME_LINTHRESH, draw_forces, time_axis  # noqa: E402


def test_time_axes_share_one_threshold_and_say_symlog():
    labels, thresholds = [], []
    for first in (1e-2, 1e-4):  # two figures whose first events differ by two decades
        fig, ax = plt.subplots()
        ax.plot([0.0, first, 10.0], [0, 1, 2])
        time_axis(ax, np.array([0.0, first, 10.0]))
        assert ax.get_xscale() == "symlog"
        thresholds.append(ax.xaxis.get_transform().linthresh)
        labels.append(ax.get_xlabel())
        plt.close(fig)
    assert thresholds == [TIME_LINTHRESH, TIME_LINTHRESH]
    assert all("symlog" in x and "log scale" not in x for x in labels)
    fig, ax = plt.subplots()
    time_axis(ax, np.array([0.0, 0.01, 0.05]))  # too short for a log axis: linear, said plainly
    assert ax.get_xscale() == "linear" and "symlog" not in ax.get_xlabel()
    plt.close(fig)


def test_force_key_fits_a_narrow_figure():
    system = models.System(models.rectangular(3, 2), mu_pp=0.1, mu_plane=0.2, mu_wall=0.0,
                           gamma=0.1)
    fig, ax = plt.subplots(figsize=(3, 2))
    draw_forces(ax, system, np.linspace(-1, 1, system.c), signed=True, name="S")
    assert ax.get_legend()._ncols <= 3  # five entries on one row were clipped (Fig. 8c)
    plt.close(fig)


def test_plot_run_titles_cite_no_paper_figure(tmp_path):
    system = models.System(models.rectangular(3, 2), mu_pp=0.1, mu_plane=0.2, mu_wall=0.0,
                           gamma=0.1)
    run = models.simulate(system, seed=1, progress=None)
    titles = []
    real = plt.Axes.set_title

    def spy(self, label, *args, **kwargs):
        titles.append(str(label))
        return real(self, label, *args, **kwargs)

    plt.Axes.set_title = spy
    try:
        models.plot.plot_run(run, tmp_path)
    finally:
        plt.Axes.set_title = real
    assert titles and not [t for t in titles if "Fig." in t], titles


def test_timestepper_records_and_energy_start_at_t0():
    from rigidlcp.models.timestepping import moreau_jean

    system = models.System(models.rectangular(4, 2), mu_pp=0.1, mu_plane=0.2, mu_wall=0.0,
                           gamma=0.1)
    state = models.initial_state(system, seed=1)
    run = moreau_jean(system, state, h=1e-3, t_max=0.2)
    first = run.records[0]
    assert first.t == state.t == 0.0
    assert np.array_equal(first.omega, state.omega)
    assert run.summary()["dissipated_energy_interval"][0] == 0.0
