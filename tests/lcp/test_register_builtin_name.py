"""A method of one's own under a built-in name (session 30): `@lcp.register("lemke", ...)`
replaced rigidlcp's lemke silently when it was already loaded, and was itself replaced
silently when it was not (built-ins load on first use), so that a solver comparison of "my
lemke" against rigidlcp's compared rigidlcp's with itself, or every default solve used the
user's. A built-in name is now refused unless `replace=True`, which keeps the replacement."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import numpy as np
import pytest

from rigidlcp import lcp
from rigidlcp.lcp import api
from rigidlcp.lcp.errors import InvalidInput


def test_a_builtin_name_is_refused_and_the_builtin_kept():
    before = api._REGISTRY.get("pgs")
    with pytest.raises(InvalidInput, match="'pgs' is one of rigidlcp's methods: register "
                                           "yours under another name"):
        @lcp.register("pgs", accepts="any", description="mine")
        def mine(M, q):
            return lcp.Solution(z=np.zeros(q.size), w=q.copy(), status="solved", method="pgs")
    assert api._REGISTRY.get("pgs") is before
    assert lcp.get_method("pgs").func.__module__ == "rigidlcp.lcp.solvers.pgs"


SCRIPT = textwrap.dedent('''
    import numpy as np
    from rigidlcp import lcp

    # before any built-in is loaded (a fresh process): replace=True must survive their loading
    @lcp.register("pgs", accepts="any", description="my pgs", replace=True)
    def mine(M, q):
        return lcp.Solution(z=np.zeros(q.size), w=q.copy(), status="failed", method="pgs")

    lcp.methods()  # loads every built-in
    info = lcp.get_method("pgs")
    answer = lcp.solve(lcp.LCP(np.eye(2), -np.ones(2)), method="pgs")
    print(info.description, "|", answer.status)
''')


def test_replace_true_keeps_the_replacement_when_the_builtins_load_later():
    done = subprocess.run([sys.executable, "-c", SCRIPT], capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "my pgs | failed"
