"""The quick gallery scripts run top to bottom and write their figures."""

import os
import runpy
import sys
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / 'examples'


def _slow(script, figure):
    return pytest.param(script, figure, marks=pytest.mark.slow)


@pytest.mark.parametrize("script, figure", [
    ('plot_mathieu_htf.py', 'mathieu_htf.png'),
    ('plot_hopper_htf.py', 'hopper_htf.png'),
    ('plot_switching_mathieu.py', 'switching_mathieu.png'),
    ('plot_analysis.py', 'analysis.png'),
    _slow('plot_pll_harmonic_stability.py', 'pll_harmonic_stability.png'),
    _slow('plot_rotor_hhc.py', 'rotor_hhc.png'),
    _slow('plot_van_der_pol_orbit.py', 'van_der_pol_orbit.png'),
    _slow('plot_clockfree_hopper.py', 'clockfree_hopper_branch.png'),
    _slow('plot_slip_running.py', 'slip_running.png'),
    _slow('plot_orbit_bifurcations.py', 'orbit_period_doubling.png'),
])
def test_gallery_script_runs(script, figure, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(sys, 'path', [str(EXAMPLES)] + sys.path)
    monkeypatch.setenv('LTP_EXAMPLES_QUICK', '1')
    runpy.run_path(str(EXAMPLES / script), run_name='__main__')
    assert (tmp_path / figure).stat().st_size > 10_000
    out = capsys.readouterr().out
    assert out.strip()


def test_demo_meets_the_thesis_figures(tmp_path, monkeypatch, capsys):
    """The README demo prints eq. 4.125 errors and Table 4.2 below the thesis's."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(sys, 'path', [str(EXAMPLES)] + sys.path)
    runpy.run_path(str(EXAMPLES / 'demo.py'), run_name='__main__')
    lines = capsys.readouterr().out.splitlines()
    rows = {}
    for line in lines:
        for label in ('thesis', 'exact sampling + refit'):
            if line.startswith(label):
                rows.setdefault(label, []).append([float(v) for v in line[len(label):].split()])
    (thesis_err, thesis_nrmse), (ours_err, ours_nrmse) = rows['thesis'], rows[
        'exact sampling + refit']
    assert all(o <= t for o, t in zip(ours_err, thesis_err))
    assert all(o <= 1e-3 for o in ours_nrmse)
    assert all(o <= t for o, t in zip(ours_nrmse, thesis_nrmse))
    assert (tmp_path / 'mathieu_htf.png').stat().st_size > 10_000


def test_mathieu_gallery_prediction_agrees():
    """The printed check of plot_mathieu_htf: HTF lines equal simulated lines."""
    import io
    import contextlib
    buf = io.StringIO()
    cwd = os.getcwd()
    with contextlib.redirect_stdout(buf):
        try:
            os.chdir(Path(__file__).parent)
            runpy.run_path(str(EXAMPLES / 'plot_mathieu_htf.py'), run_name='__main__')
        finally:
            os.chdir(cwd)
            (Path(__file__).parent / 'mathieu_htf.png').unlink(missing_ok=True)
    rel = [float(line.rsplit(' ', 1)[1]) for line in buf.getvalue().splitlines()
           if 'relative difference' in line]
    assert len(rel) == 3 and max(rel) < 1e-8
