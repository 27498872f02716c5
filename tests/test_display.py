"""print and notebook display of LTP systems."""

import control as ct
import numpy as np

import ltpcontrol as ltp


def _switching(npieces=39):
    times = np.linspace(0, 1, npieces + 1)[:-1]
    A = ltp.PeriodicMatrix.switching([-(k + 1) * np.eye(2) for k in range(npieces)], times, 1.0)
    return ltp.ltpss(A, [[1.0], [0.0]], [[1.0, 0.0]], 0, period=1.0, name='sw')


def test_print_summarises_long_switching_and_sampled_systems():
    text = str(_switching())
    assert "switching, 39 pieces at [0, 0.025641, 0.051282, ..., 0.974359]" in text
    assert len(text) < 400
    sampled = str(_switching().sample(0.01))
    assert "sequence of 100 matrices per period" in sampled
    assert "dt = 0.01 (100 steps per period)" in sampled
    assert len(sampled) < 500
    assert "switching at [0.0, 0.5]" in str(_switching(2))      # short lists in full
    assert "B = [[1.]" in text                                  # constant matrices in full


def test_notebook_display_follows_python_control():
    sys = ltp.ltpss([[0.0, 1.0], [-1.0, -0.2]],
                    lambda t: np.array([[0.0], [1 + np.cos(2 * np.pi * t)]]), [[1, 0]], 0,
                    period=1.0, name='m')
    out = sys._repr_html_()
    assert out.startswith("&lt;LTPStateSpace m: ['u[0]'] -&gt; ['y[0]'], period=1&gt;")
    assert r"\dot x &= A(t)\,x + B(t)\,u" in out
    assert r"A &= \begin{bmatrix}0 & 1 \\ -1 & -0.2\end{bmatrix}" in out
    # the mean of B(t) is shown exactly, with its description
    assert r"\bar B = \begin{bmatrix}0 \\ 1\end{bmatrix}" in out
    assert "smooth function of t" in out
    assert sys._repr_markdown_() == out
    # as python-control's StateSpace: no separate LaTeX form, None when too large
    assert sys._repr_latex_() is None and ct.rss(2)._repr_latex_() is None
    with ct.config.defaults({'statesp.latex_maxsize': 2}):
        assert sys._repr_html_() is None
    d = _switching().sample(0.25)._repr_html_()
    assert r"x[k+1] &= A[k]\,x[k]" in d and "N = 4" in d
