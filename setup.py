"""Build hook for the one optional C extension (everything else is in pyproject.toml).

rigidlcp.lcp._lemke_c is Lemke's pivot loop in C (lcp/_lemke_c.c). It is `optional`: when no
C compiler is available, `pip install` still succeeds and lcp/_lemke_kernel.py runs the same
loop in numpy (docs/performance.md says why a C extension and what it gains).

The C code must round as numpy does (same pivots, same z, same residuals, bit for bit), so a
compiler that can fuse a * b + c into one fused multiply-add (GCC and Clang do by default where
the CPU has one, e.g. on aarch64) is told not to: -ffp-contract=off. MSVC does not fuse by
default.
"""

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext


class BuildExt(build_ext):
    def build_extensions(self):
        if self.compiler.compiler_type != "msvc":
            for ext in self.extensions:
                ext.extra_compile_args = [*ext.extra_compile_args, "-ffp-contract=off"]
        super().build_extensions()


setup(
    ext_modules=[
        Extension("rigidlcp.lcp._lemke_c", sources=["lcp/_lemke_c.c"], optional=True),
    ],
    cmdclass={"build_ext": BuildExt},
)
