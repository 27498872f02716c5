"""Plots that inspect the figure: multi-trace time responses and HTF overlays."""

import matplotlib
matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

import ltpcontrol as ltp  # noqa: E402
from systems import damped_mathieu, mathieu  # noqa: E402


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close('all')


def test_multi_trace_forced_response_plots_every_trace():
    sys = mathieu()
    t = np.linspace(0, 3, 301)
    U = np.cos(np.outer([1.0, 2.0, 3.0], t))[None]
    cplt = ltp.forced_response(sys, t, U).plot()
    # one output row and one input row, three traces side by side
    assert cplt.lines.shape == (2, 3)
    for trace in range(3):
        (line,) = cplt.lines[0, trace]
        np.testing.assert_allclose(line.get_ydata(), ltp.forced_response(
            sys, t, U[:, trace]).outputs, rtol=0, atol=1e-15)


def test_bode_htf_shows_the_harmonics_the_htf_has():
    H = ltp.htf(damped_mathieu(), 3)
    cplt = ltp.bode_htf(H, omega_num=30)
    labels = [line.get_label() for line in cplt.lines[0, 0]]
    assert labels == [f"G_{k}" for k in range(-3, 4)]
    assert len(cplt.lines[1, 0]) == 7
    labels = [line.get_label() for line in ltp.bode_htf(H, omega_num=30,
                                                          harmonics=[0, 2]).lines[0, 0]]
    assert labels == ["G_0", "G_2"]


def test_overlay_colors_per_system_styles_per_component_wrapped_phase():
    H1, H2 = ltp.htf(damped_mathieu(), 3), ltp.htf(damped_mathieu(zeta=0.3), 3)
    H2.name = 'other'
    cplt = ltp.bode_htf([H1, H2], omega=np.logspace(-1, 2, 80))
    mag, phase = cplt.lines[0, 0], cplt.lines[1, 0]
    assert len(mag) == 14
    colors = [matplotlib.colors.to_hex(line.get_color()) for line in mag]
    assert len(set(colors[:7])) == 1 and len(set(colors[7:])) == 1
    assert colors[0] != colors[7]
    first = [line.get_linestyle() for line in mag[:4]]
    assert len(set(first)) == 4                       # '-', '--', '-.', ':'
    # the legend shows the restyled lines, one entry per line
    legend = [lg for lg in np.ravel(cplt.legend) if lg is not None][0]
    assert len(legend.get_texts()) == 14
    handle = legend.legend_handles[7]
    assert matplotlib.colors.to_hex(handle.get_color()) == colors[7]
    # phases wrapped to [-180, 180) degrees
    for line in phase:
        y = np.asarray(line.get_ydata())
        assert y.min() >= -180 - 1e-9 and y.max() < 180 + 1e-9
    lo, hi = cplt.axes[1, 0].get_ylim()
    assert lo > -200 and hi < 200
    # unwrapped on request: continuous from the first frequency
    cplt = ltp.bode_htf([H1, H2], omega=np.logspace(-1, 2, 80), wrap_phase=False)
    for line in cplt.lines[1, 0]:
        assert np.max(np.abs(np.diff(line.get_ydata()))) < 180
