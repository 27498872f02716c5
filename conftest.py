"""Shared pytest configuration: doctest namespace and plotting hygiene."""

import matplotlib

matplotlib.use("Agg")

import control as ct  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402


@pytest.fixture(autouse=True)
def _doctest_namespace(doctest_namespace):
    """Make ``np``, ``ct`` and ``ltp`` available to every docstring example."""
    import ltpcontrol

    doctest_namespace["np"] = np
    doctest_namespace["ct"] = ct
    doctest_namespace["ltp"] = ltpcontrol


@pytest.fixture(autouse=True)
def _close_figures():
    """Close all matplotlib figures after each test."""
    import matplotlib.pyplot as plt

    yield
    plt.close("all")
