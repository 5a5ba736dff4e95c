"""Build hook for the optional C extensions (everything else is in pyproject.toml).

rigidlcp.lcp._lemke_c is Lemke's pivot loop in C (lcp/_lemke_c.c; also the residual measure of
lcp/acceptance/residual.py, so it stays at the root of lcp/), rigidlcp.lcp.acceptance._accuracy_c
the backward / forward errors of an LCP answer (lcp/acceptance/_accuracy_c.c),
rigidlcp.lcp.solvers._pivot_c the block steps of method `pivoting` for lcp.solve's fast path
(lcp/solvers/_pivot_c.c). Each is built next to the module that loads it. All are
`optional`: when no C compiler is available, `pip install` still succeeds and the numpy code
runs instead (docs/performance.md says why a C extension and what it gains).

The C code must round as numpy does (same pivots, same z, same residuals, bit for bit), so a
compiler that can fuse a * b + c into one fused multiply-add (GCC and Clang do by default where
the CPU has one, e.g. on aarch64) is told not to: -ffp-contract=off. MSVC does not fuse by
default.
"""

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext


def _accepts(compiler, flag: str) -> bool:
    """Does the C compiler accept `flag`? (A one-line file compiled with it.)"""
    import os
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        src = os.path.join(tmp, "flag.c")
        with open(src, "w") as fh:
            fh.write("int main(void) { return 0; }\n")
        try:
            compiler.compile([src], output_dir=tmp, extra_postargs=[flag])
        except Exception:  # noqa: BLE001 - any failure means "not accepted"
            return False
    return True


class BuildExt(build_ext):
    def build_extensions(self):
        if self.compiler.compiler_type != "msvc":
            flags = ["-ffp-contract=off"]
            # Loops on 32-byte boundaries: the vectorized update of Lemke's dictionary ran
            # 1.35x slower at n = 100 when an unrelated change moved its loop across a 64-byte
            # line (AMD EPYC); the numbers do not depend on it. Skipped by a compiler without it.
            if _accepts(self.compiler, "-falign-loops=32"):
                flags.append("-falign-loops=32")
            for ext in self.extensions:
                ext.extra_compile_args = [*ext.extra_compile_args, *flags]
        super().build_extensions()


setup(
    ext_modules=[
        Extension("rigidlcp.lcp._lemke_c", sources=["lcp/_lemke_c.c"], optional=True,
                  depends=["lcp/_lemke_run.h", "lcp/_lemke_update.h", "lcp/_lemke_py.h",
                           "lcp/_lemke_problem.h", "lcp/_lemke_measure.h",
                           "lcp/_lemke_solution.h", "lcp/_solve_entry.h",
                           "lcp/_batch_solutions.h", "lcp/_balanced.h", "lcp/_blas.h",
                           "lcp/_buffer.h", "lcp/_numpy_abi.h",
                           "lcp/acceptance/_accuracy_core.h", "lcp/acceptance/_bound_core.h",
                           "lcp/acceptance/_lu_core.h", "lcp/acceptance/_inverse_core.h"]),
        Extension("rigidlcp.lcp.solvers._pivot_c", sources=["lcp/solvers/_pivot_c.c"],
                  optional=True, depends=["lcp/_balanced.h", "lcp/_buffer.h"]),
        Extension("rigidlcp.lcp.acceptance._accuracy_c",
                  sources=["lcp/acceptance/_accuracy_c.c"], optional=True,
                  depends=["lcp/acceptance/_accuracy_core.h", "lcp/acceptance/_bound_core.h",
                           "lcp/acceptance/_lu_core.h", "lcp/acceptance/_inverse_core.h"]),
    ],
    cmdclass={"build_ext": BuildExt},
)
