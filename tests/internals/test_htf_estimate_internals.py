"""The GCV trace of the joint HTF estimate: block sweeps against dense solves.

Tests of internals: they import private names (see the Developer notes).
"""

import numpy as np
import pytest
import scipy.sparse as sp

from ltpcontrol._identification.htf_estimate import (_inverse_diagonal_blocks, _penalty,
                                                     _solve_joint)


@pytest.mark.parametrize("nrec, nfreq, nunk, alpha", [(7, 40, 3, 0.3), (1, 129, 3, 1e4),
                                                      (3, 61, 5, 10.0), (2, 5, 1, 1.0)])
def test_gcv_trace_by_block_sweeps_equals_column_solves(nrec, nfreq, nunk, alpha):
    # tr H of the GCV search (two Schur-complement sweeps) against the
    # column-by-column solves, and the blocks against a dense inverse
    rng = np.random.default_rng(nfreq)
    phi = rng.normal(size=(nrec, nfreq, nunk)) + 1j * rng.normal(size=(nrec, nfreq, nunk))
    Yb = rng.normal(size=(nrec, nfreq, 2)) + 1j * rng.normal(size=(nrec, nfreq, 2))
    pen = _penalty(nfreq, nunk)
    g1, tr1, _ = _solve_joint(phi, Yb, alpha, pen, 2.0, True)
    g2, tr2, _ = _solve_joint(phi, Yb, alpha, pen, 2.0, False)
    np.testing.assert_allclose(g2, g1, rtol=1e-13, atol=0)
    assert abs(tr2 - tr1) <= 1e-10 * abs(tr1)
    puu = np.einsum('rfa,rfb->fab', phi.conj(), phi)
    A = sp.block_diag(list(puu)) + alpha * 2.0 * pen
    Z = np.linalg.inv(A.toarray())
    blocks = _inverse_diagonal_blocks(sp.csr_matrix(A), nfreq, nunk)
    for f in range(nfreq):
        sl = slice(f * nunk, (f + 1) * nunk)
        np.testing.assert_allclose(blocks[f], Z[sl, sl], rtol=0, atol=1e-10 * np.abs(Z).max())
