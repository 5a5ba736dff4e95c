"""Bad input to verify/ raises the toolkit's typed errors (lcp/errors.py, root RigidLCPError),
still ValueErrors where callers catch ValueError; an existing certify-run output is
OutputExists (a FileExistsError), as every other refused output is."""

from __future__ import annotations

import pytest
from hypothesis import given, settings

from rigidlcp import models
from rigidlcp.lcp.errors import InvalidInput, OutputExists, RigidLCPError
from rigidlcp.verify.certificates.run import _prepare
from rigidlcp.verify.nullspace.formulas import paper_formula
from rigidlcp.verify.statics.model import StaticProblem
from rigidlcp.verify.strategies import p_matrices


def test_bad_arguments_are_typed_and_still_value_errors():
    with pytest.raises(InvalidInput, match="gamma = 0"):
        StaticProblem(models.System(models.rectangular(2, 1), gamma=0.1))
    with pytest.raises(InvalidInput, match="lattice must be"):
        paper_formula("hex", 3, 3, "normal")
    assert issubclass(InvalidInput, RigidLCPError) and issubclass(InvalidInput, ValueError)


def test_a_strategy_with_a_bad_size_raises_invalid_input():
    @settings(max_examples=1, database=None)
    @given(p_matrices(0))
    def draw(M):
        pass

    with pytest.raises(InvalidInput, match="sizes must be integers >= 1"):
        draw()


def test_an_existing_certify_run_output_is_output_exists(tmp_path):
    (tmp_path / "x").write_text("")
    with pytest.raises(OutputExists, match="--resume"):
        _prepare(tmp_path, {}, resume=False, force=False, notes=[])
    with pytest.raises(InvalidInput, match="not a directory"):
        _prepare(tmp_path / "x", {}, resume=False, force=False, notes=[])
