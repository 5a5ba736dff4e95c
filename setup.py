"""Build hook for the one optional C extension (everything else is in pyproject.toml).

rigidlcp.lcp._lemke_c is Lemke's pivot loop in C (lcp/_lemke_c.c). It is `optional`: when no
C compiler is available, `pip install` still succeeds and lcp/_lemke_kernel.py runs the same
loop in numpy (docs/performance.md says why a C extension and what it gains).
"""

from setuptools import Extension, setup

setup(
    ext_modules=[
        Extension("rigidlcp.lcp._lemke_c", sources=["lcp/_lemke_c.c"], optional=True),
    ],
)
