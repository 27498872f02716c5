"""Exact counts of the generalized Nyquist criterion for every proper loop:
the truncated contour is closed through its horizontal edges, so biproper
loops (L(∞) ≠ 0) are counted right at every truncation.  Truths: the poles
of the closed loop (python-control) and python-control's Nyquist count."""

import warnings

import numpy as np
import control as ct
import pytest
from hypothesis import assume, given, settings, strategies as st

import ltpcontrol as ltp


def _biproper(wc):
    # 5 - 12 ω_c/(s + ω_c): 1 + L = 6 (s - ω_c)/(s + ω_c), closed-loop pole +ω_c
    return ct.tf([5, 5 * wc - 12 * wc], [1, wc])


@pytest.mark.parametrize("N", [2, 3, 5, 10, 20])
def test_biproper_loop_counted_at_every_truncation(N):
    G = _biproper(100.0)
    assert ct.nyquist_response(G).count == 1
    with warnings.catch_warnings():
        warnings.simplefilter('error')              # no closure warning
        resp = ltp.nyquist_htf(ltp.ltpss(G, period=1.0), N)
    assert resp.closed_loop_unstable == 1 and not resp.stable
    assert resp.count == ct.nyquist_response(G).count
    assert resp.floquet_unstable == 1


def test_unchecked_count_warns_when_truncation_edge_is_large():
    # 20/(s + 1) with N = 1: the curve on the axis alone does not close; the count
    # (exact for the truncated loop) is flagged when it is not cross-checked
    L = ltp.ltpss(ct.tf([20], [1, 1]), period=1.0)
    with pytest.warns(UserWarning, match="truncation edge"):
        resp = ltp.nyquist_htf(L, 1, check=False)
    assert resp.stable and resp.floquet_unstable is None
    with warnings.catch_warnings():
        warnings.simplefilter('error')
        assert ltp.nyquist_htf(L, 1).stable


def _lti_loop(poles, num, d):
    """Real SISO loop with the given poles (pairs from complex entries)."""
    blocks = []
    for p in poles:
        if abs(p.imag) < 1e-9:
            blocks.append(np.array([[p.real]]))
        else:
            blocks.append(np.array([[p.real, p.imag], [-p.imag, p.real]]))
    n = sum(len(b) for b in blocks)
    A = np.zeros((n, n))
    i = 0
    for b in blocks:
        A[i:i + len(b), i:i + len(b)] = b
        i += len(b)
    B = np.ones((n, 1))
    C = np.asarray(num[:n], float)[None, :]
    return ct.ss(A, B, C, [[d]])


# fast and slow poles: a biproper loop's tail beyond the truncation is then not small
rate = st.builds(lambda sg, e: sg * 10.0 ** e, st.sampled_from([-1.0, 1.0]), st.floats(-1, 2))
pole = st.builds(complex, rate, st.one_of(st.just(0.0), st.floats(0.3, 3)))


@pytest.mark.filterwarnings("ignore:number of encirclements")     # python-control's
@settings(max_examples=20, deadline=None)
@given(poles=st.lists(pole, min_size=1, max_size=3),
       num=st.lists(st.floats(-60, 60), min_size=6, max_size=6),
       d=st.one_of(st.just(0.0), st.floats(-4, 4).filter(lambda x: abs(x) > 1e-3)))
def test_lti_loops_written_as_periodic_count_as_python_control(poles, num, d):
    G = _lti_loop(poles, num, d)
    assume(abs(1 + d) > 0.05)                                  # well posed
    assume(np.all(np.abs(ct.poles(G).real) > 1e-2))            # no pole on the axis
    assume(np.all(np.abs(ct.poles(G).imag) < 5))
    cl = np.linalg.eigvals(G.A - G.B @ G.C / (1 + d))
    assume(np.all(np.abs(cl.real) > 1e-2))                     # not at a boundary
    assume(np.all(np.abs(cl.imag) < 8))                        # inside harmonic ±1
    Z = int(np.count_nonzero(cl.real > 0))
    theirs = ct.nyquist_response(ct.tf(G)).count
    assume(theirs == Z - int(np.count_nonzero(ct.poles(G).real > 0)))   # theirs resolved
    L = ltp.ltpss(G, period=1.0)                               # ω_p = 2π
    for N in (1, 2, 3, 4, 6):
        # a coarse given contour, or the default one (coarse, refined, with points
        # around the exponents near the axis)
        omega = np.linspace(-np.pi, np.pi, 101) if N % 2 else None
        resp = ltp.nyquist_htf(L, N, omega=omega)
        assert resp.closed_loop_unstable == Z, (N, resp)
        assert resp.count == theirs


def test_margin_report_in_hz():
    G = ct.tf([4], [1, 3, 3, 1])
    m = ltp.harmonic_margins(ltp.ltpss(G, period=1.0), 5, check=False)
    gm, pm, sm, wpc, wgc, wms = ct.stability_margins(G)
    row = next(r for r in m.report(hz=True).splitlines() if r.startswith('gain upper'))
    assert abs(float(row.split()[-1]) - wpc / (2 * np.pi)) < 1e-5
    assert "[rad/s]" in m.report()


@pytest.mark.parametrize("check", [True, False])
def test_turn_within_a_narrow_band_is_counted(check):
    # L = -4δ s/(s² + 2δ s + δ² + ω0²): 1 + L is all-pass, |f| = 1 on the axis, and
    # its two turns lie within a few δ of ±ω0 (open-loop poles -δ ± jω0, closed-loop
    # poles +δ ± jω0); a uniform contour misses them, the points placed around
    # the exponents near the axis see them
    d, w0 = 1e-5, 1.3
    G = ct.tf([-4 * d, 0], [1, 2 * d, d ** 2 + w0 ** 2])
    Z = int(np.count_nonzero(ct.poles(ct.feedback(G, 1)).real > 0))
    assert Z == 2
    with warnings.catch_warnings():
        warnings.simplefilter('error')
        resp = ltp.nyquist_htf(ltp.ltpss(G, period=1.0), 3, check=check)
    assert resp.closed_loop_unstable == Z
    assert np.allclose(np.abs(resp.det), 1.0, atol=1e-9)          # all-pass: |f| = 1
