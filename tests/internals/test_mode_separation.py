"""Separation of clusters of repeated multipliers by harmonic content."""

import numpy as np
import pytest

from ltpcontrol._analysis.mode_separation import (clusters, constant_part,
                                                  separate_clusters, warn_ambiguous)
import ltpcontrol as ltp


def pure_and_mixed(etas, rng):
    """Coefficients (r, mode, H) of shapes with given mean harmonics, mixed randomly."""
    H = np.arange(-2, 3)
    g = len(etas)
    c = np.zeros((g, g, len(H)), complex)
    for i, eta in enumerate(etas):
        lo = int(np.floor(eta))
        w = eta - lo                                  # share on lo + 1
        c[i, i, H == lo] = np.sqrt(1 - w)
        c[i, i, H == lo + 1] = np.sqrt(w)
    mix = np.linalg.qr(rng.standard_normal((g, g)) + 1j * rng.standard_normal((g, g)))[0]
    return np.einsum('rih,ij->rjh', c, mix), mix, H


@pytest.mark.parametrize('etas', [[-1.0, 0.0, 1.0], [-2.0, 2.0], [0.0, 1.0]])
def test_single_harmonic_shapes_are_recovered_from_any_mixture(etas):
    rng = np.random.default_rng(3)
    c, mix, H = pure_and_mixed(etas, rng)
    g = len(etas)
    p = mix.T[:, None, :].copy()                      # vectors at t = 0
    left = np.linalg.inv(p[:, 0, :].T).conj().T
    bad = separate_clusters(np.zeros(g, complex), p, left, c, H, [list(range(g))])
    assert bad == []
    share = np.sum(np.abs(c) ** 2, axis=0)
    share /= share.sum(axis=1, keepdims=True)
    assert np.allclose(np.sort(share.max(axis=1)), 1.0)
    assert sorted(H[np.argmax(share, axis=1)]) == sorted(int(e) for e in etas)
    # bi-orthonormality is kept, vectors of unit norm
    assert np.allclose(left.conj().T @ p[:, 0, :].T, np.eye(g))
    assert np.allclose(np.linalg.norm(p[:, 0, :], axis=1), 1)


def test_close_mean_harmonics_are_reported_and_warned():
    rng = np.random.default_rng(4)
    c, mix, H = pure_and_mixed([0.2, 0.45], rng)
    p = mix.T[:, None, :].copy()
    left = np.linalg.inv(p[:, 0, :].T).conj().T
    strip = np.array([1j, 1j])
    bad = separate_clusters(strip, p, left, c, H, [[0, 1]])
    assert len(bad) == 1 and np.allclose(sorted(bad[0][1]), [0.2, 0.45])
    with pytest.warns(UserWarning, match="cannot be separated"):
        warn_ambiguous(bad, strip)


def test_nearly_equal_exponents_keep_their_sum():
    rng = np.random.default_rng(5)
    c, mix, H = pure_and_mixed([-1.0, 1.0], rng)
    p = mix.T[:, None, :].copy()
    left = np.linalg.inv(p[:, 0, :].T).conj().T
    strip = np.array([0.5j - 1e-8, 0.5j + 1e-8])
    separate_clusters(strip, p, left, c, H, [[0, 1]])
    assert np.isclose(strip.sum(), 1j)


def test_clusters_compare_multipliers_on_the_circle():
    # log μ = λT: arguments 2π apart are the same multiplier
    assert clusters(np.array([1j * np.pi, -1j * np.pi + 1e-9, 0.1]), 1e-6) == [[0, 1]]
    assert clusters(np.array([0.0, 1e-3]), 1e-6) == []


def test_constant_part_tolerance():
    A = ltp.PeriodicMatrix.from_function(lambda t: np.array([[1.0 + 1e-8 * np.sin(t)]]),
                                         2 * np.pi, (1, 1))
    assert constant_part(A, 1e-7) is not None and constant_part(A, 1e-9) is None
