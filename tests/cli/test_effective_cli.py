"""`rigidlcp sweep` + `rigidlcp effective` as a new user runs them (issue 24.3): the kink rows
are explained and warned about, the plateau's exact values are recovered on a grid that
resolves it, and a re-display of the same table needs no --force."""

from __future__ import annotations

import json

import pytest

from rigidlcp.cli.main import main


@pytest.fixture(scope="module")
def readme_sweep(tmp_path_factory):
    d = tmp_path_factory.mktemp("sweep") / "sweep"
    assert main(["sweep", "--lx", "10", "--ly", "1", "--gamma", "0:0.4:9", "--out", str(d),
                 "--no-progress"]) == 0
    return d


def test_readme_sweep_kinks_are_explained_warned_and_redisplayed(readme_sweep, capsys):
    capsys.readouterr()
    assert main(["effective", str(readme_sweep)]) == 0
    first = capsys.readouterr()
    assert "'kink' = every window" in first.out and "chord" in first.out
    assert "warning: 9 of 9 points are 'kink'" in first.err
    stamp = (readme_sweep / "effective.json").stat().st_mtime_ns
    # the same command again: the table, no --force needed, nothing rewritten
    assert main(["effective", str(readme_sweep)]) == 0
    again = capsys.readouterr()
    assert again.out == first.out
    assert (readme_sweep / "effective.json").stat().st_mtime_ns == stamp
    # a different result into the same files still needs --force
    assert main(["effective", str(readme_sweep), "--window", "4"]) == 2
    assert "--force" in capsys.readouterr().err


def test_plateau_values_are_exact_on_a_grid_that_resolves_it(tmp_path, capsys):
    """All plane contacts slide and the walls are frictionless: the plane carries the weight
    m_g g, so F_g = mu_plane m_g g for every gamma on the plateau: a = 0, m_e = m_g = 10,
    mu_e = mu_plane = 0.2 (the 9-point grid's 10.1 / 0.1965 are chords across the kink)."""
    d = tmp_path / "sw"
    assert main(["sweep", "--lx", "10", "--ly", "1", "--gamma", "0.35:0.5:4", "--out", str(d),
                 "--no-progress"]) == 0
    capsys.readouterr()
    assert main(["effective", str(d), "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)[0]["rows"]
    assert len(rows) == 4
    for r in rows:
        assert r["exact"]
        assert r["m_e"] == pytest.approx(10.0, abs=1e-9)
        assert r["mu_e"] == pytest.approx(0.2, abs=1e-9)


def test_effective_titles_cite_the_paper_only_for_its_system():
    from rigidlcp.cli.sweep import is_paper_fig11

    paper = dict(lattice="rect", lx=10, ly=1, mu_pp=0.05, mu_plane=0.1, mu_wall=0.0, v0=0.0,
                 inertia=None)
    assert is_paper_fig11(paper)
    assert not is_paper_fig11(dict(paper, mu_pp=0.1))  # the README's sweep: defaults 0.1 / 0.2
    assert not is_paper_fig11(dict(paper, lx=6))
