"""The bench's worker process ends cleanly at the end of a run (session 30): it used to be
killed, so that what a method left to its exit handlers was not released: with QuantEcon (numba
holds a multiprocessing semaphore) every `rigidlcp bench` ended with Python's warning "There
appear to be 1 leaked semaphore objects to clean up at shutdown". A worker killed on a timeout
is still killed at once."""

from __future__ import annotations

import subprocess
import sys
import textwrap

from rigidlcp.bench.runners import WARM_UP, LocalRunner

SCRIPT = textwrap.dedent('''
    import multiprocessing as mp

    from rigidlcp import lcp

    HELD = []


    @lcp.register("holds-a-semaphore", accepts="any", description="lemke, holding a semaphore")
    def holds(M, q):
        if not HELD:  # as numba does in the worker: a semaphore known to the resource tracker
            HELD.append(mp.get_context("spawn").Semaphore(1))
        z = lcp.solve(lcp.LCP(M, q), method="lemke").z
        return lcp.Solution(z=z, w=M @ z + q, status="solved", method="holds-a-semaphore")


    if __name__ == "__main__":
        from rigidlcp.bench.harness import run_bench
        from rigidlcp.bench.problem_sets import get_set

        results = run_bench({"random-p": get_set("random-p")[:2]}, ["holds-a-semaphore"],
                            time_limit=10)
        print(sum(r.success for r in results), "of", len(results))
''')


def test_a_run_ends_its_worker_cleanly(tmp_path):
    script = tmp_path / "mine.py"
    script.write_text(SCRIPT)
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                          cwd=tmp_path, timeout=300)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "2 of 2"
    assert "leaked semaphore" not in done.stderr, done.stderr


def test_close_with_wait_lets_the_worker_exit_and_without_kills_it():
    runner = LocalRunner()
    assert runner.solve(WARM_UP, "lemke", 10.0)["kind"] == "answer"
    proc = runner.proc
    runner.close(wait=5.0)
    assert proc.exitcode == 0  # returned from its loop when the pipe closed
    runner.solve(WARM_UP, "lemke", 10.0)
    proc = runner.proc
    runner.close()  # a timeout's close: no wait
    assert proc.exitcode == -9  # SIGKILL
