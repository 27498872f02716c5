"""HTF maps between the abc, αβ, dq and sequence domains.

Truths: a balanced impedance is R + sL per phase in αβ and abc (closed form);
an asymmetric dq model changed to αβ equals the HTF of the state-space frame
change (`frame_transform`, an independent route); the sequence-domain HTF
couples only the mirror frequencies.
"""

import control as ct
import numpy as np
import pytest

import ltpcontrol as ltp

W1 = 2 * np.pi * 50
T1 = 2 * np.pi / W1


def test_balanced_impedance_is_diagonal_in_the_stationary_frames():
    R, L, C, N = 0.1, 2e-3, 1e-5, 3
    Zdq = ltp.rlc_impedance(R, L, C, connection='grid', period=T1, nharmonics=N, omega1=W1)
    Zp = ltp.rlc_impedance(R, L, C, connection='grid', period=T1, nharmonics=N)
    s = 0.5 + 123j
    want = np.diag(Zp(s)).repeat(2)
    Hab = ltp.frame_htf(Zdq, 'dq', 'ab', W1)(s)
    assert np.allclose(Hab, np.diag(want), atol=1e-12 * np.abs(want).max())
    Hpn = ltp.frame_htf(Zdq, 'dq', 'pn', W1)(s)
    assert np.allclose(Hpn, np.diag(want), atol=1e-12 * np.abs(want).max())
    # abc of a 3-wire (zero-sequence free) system: Z(s) (I - 1/3)
    Habc = ltp.frame_htf(Zdq, 'dq', 'abc', W1)(s)
    proj = np.eye(3) - np.ones((3, 3)) / 3
    for a in range(2 * N + 1):
        blk = Habc[3 * a:3 * a + 3, 3 * a:3 * a + 3]
        assert np.allclose(blk, np.diag(Zp(s))[a] * proj, atol=1e-12)


def _rotation_back():
    """R(θ)^T (dq -> αβ) as an exact Fourier PeriodicMatrix, θ = ω_1 t."""
    c1 = np.array([[0.5, 0.5j], [-0.5j, 0.5]])
    return ltp.PeriodicMatrix(np.stack([c1.conj(), np.zeros((2, 2)), c1]), T1)


def test_asymmetric_dq_model_in_alphabeta_equals_the_state_space_frame_change():
    Ydq = ct.ss(ct.tf([[[1.0], [0.0]], [[0.0], [2.0, 1.0]]],
                      [[[1e-3, 1.0], [1.0]], [[1.0], [1e-3, 3.0]]]))
    N = 3
    Hab = ltp.frame_htf(ltp.ltpss(Ydq, period=T1), 'dq', 'ab', W1, nharmonics=N)
    Rt = _rotation_back()
    # y_ab = R^T y_dq and u_ab = R^T u_dq: both transforms are R^T
    ss_ab = ltp.frame_transform(ltp.ltpss(Ydq, period=T1), inputs=Rt, outputs=Rt)
    ref = ltp.htf(ss_ab, N, internal_harmonics=N + 12)
    for s in (0.2 + 40j, 3.0 - 700j):
        got, want = Hab(s), ref(s)
        c = slice(2 * (N - 1), 2 * (N + 2))        # central blocks, exact in both
        assert np.allclose(got[c, c], want[c, c], atol=1e-10)
    # periodic in αβ: harmonic blocks two apart are coupled
    M = Hab(0.2 + 40j)
    assert np.abs(M[2 * N:2 * N + 2, 2 * (N - 2):2 * (N - 1)]).max() > 1e-3


def test_sequence_domain_couples_only_mirror_frequencies():
    Ydq = ct.tf([[[1.0], [0.0]], [[0.0], [2.0]]], [[[1e-3, 1.0], [1.0]], [[1.0], [1e-3, 3.0]]])
    N = 4
    M = ltp.frame_htf(ltp.LTIHTF(Ydq, T1, N), 'dq', 'pn', W1)(0.1 + 77j)
    off = 0.0
    coupled = 0.0
    for a in range(2 * N + 1):
        for b in range(2 * N + 1):
            blk = M[2 * a:2 * a + 2, 2 * b:2 * b + 2]
            if a == b:
                assert abs(blk[0, 1]) < 1e-12 and abs(blk[1, 0]) < 1e-12
            elif abs(a - b) == 2:
                coupled = max(coupled, np.abs(blk).max())
                assert abs(blk[0, 0]) < 1e-12 and abs(blk[1, 1]) < 1e-12
            else:
                off = max(off, np.abs(blk).max())
    assert off < 1e-12 and coupled > 1e-2


def test_frame_htf_refuses_bad_input():
    Z = ltp.rlc_impedance(0.1, 1e-3, period=T1, nharmonics=1, nphases=3)
    with pytest.raises(ValueError, match='frames'):
        ltp.frame_htf(Z, 'abc', 'xy', W1)
    with pytest.raises(ValueError, match='inputs'):
        ltp.frame_htf(Z, 'dq', 'ab', W1)
    with pytest.raises(ValueError, match='nonzero'):
        ltp.frame_htf(Z, 'abc', 'dq0', 0.0)
    with pytest.raises(ValueError, match='divide'):
        ltp.frame_htf(ltp.ltpss(np.zeros((0, 0)), np.zeros((0, 3)), np.zeros((3, 0)),
                                np.eye(3), period=0.3 * T1), 'abc', 'dq0', W1)
