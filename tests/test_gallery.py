"""The README demo and the printed check of the Mathieu gallery script.

Every gallery script (``examples/plot_*.py``) runs top to bottom in the
documentation build (quick mode), which fails on any error, so they are not
run a second time here.
"""

import os
import runpy
import sys
from pathlib import Path

EXAMPLES = Path(__file__).resolve().parents[1] / 'examples'


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
