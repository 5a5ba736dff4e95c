"""Hypothesis profiles for the whole suite (docs/fuzz.md, "Property tests").

* "ci" (the default, and whenever the CI environment variable is set): derandomized, so the
  same code gives the same verdict on every run; no deadline (the machine is shared), no
  example database.
* "dev": random examples (a new draw every run, failures remembered in .hypothesis/).
* "deep": random, at least HYPOTHESIS_DEEP_EXAMPLES (default 2000) examples per property,
  overriding the smaller counts the tests declare; for a long run outside CI:
  `HYPOTHESIS_PROFILE=deep python -m pytest -q tests/lcp -m "not slow"`.

Choose with HYPOTHESIS_PROFILE=ci|dev|deep.
"""

from __future__ import annotations

import os

from hypothesis import HealthCheck, settings

DEEP_EXAMPLES = int(os.environ.get("HYPOTHESIS_DEEP_EXAMPLES", "2000"))

settings.register_profile("ci", derandomize=True, deadline=None, database=None,
                          print_blob=True)
settings.register_profile("dev", deadline=None)
settings.register_profile("deep", deadline=None, max_examples=DEEP_EXAMPLES,
                          suppress_health_check=[HealthCheck.too_slow,
                                                 HealthCheck.filter_too_much])

PROFILE = "ci" if os.environ.get("CI") else os.environ.get("HYPOTHESIS_PROFILE", "ci")
settings.load_profile(PROFILE)


def pytest_report_header(config) -> str:
    return f"hypothesis profile: {PROFILE}"


def pytest_collection_modifyitems(config, items) -> None:
    """Under "deep", raise every property's own max_examples to DEEP_EXAMPLES (a test's
    @settings(max_examples=...) would otherwise win over the profile)."""
    if PROFILE != "deep":
        return
    for item in items:
        test = getattr(item, "obj", None)
        inner = getattr(test, "_hypothesis_internal_use_settings", None)
        if inner is not None and inner.max_examples < DEEP_EXAMPLES:
            test._hypothesis_internal_use_settings = settings(
                inner, max_examples=DEEP_EXAMPLES, deadline=None, derandomize=False,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
