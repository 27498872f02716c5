"""The rotor gallery's printed results against independent simulations."""

import re
import runpy
import sys
from pathlib import Path

import numpy as np
import pytest

from test_rotors import flap_growth_ivp, growth_ivp, principal_rule_ivp

EXAMPLES = Path(__file__).resolve().parents[1] / 'examples'


def run(script, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(sys, 'path', [str(EXAMPLES)] + sys.path)
    monkeypatch.setenv('LTP_EXAMPLES_QUICK', '1')
    runpy.run_path(str(EXAMPLES / script), run_name='__main__')
    return capsys.readouterr().out


@pytest.mark.slow
def test_flapping_blade_gallery_matches_simulation(tmp_path, monkeypatch, capsys):
    out = run('plot_flapping_blade.py', tmp_path, monkeypatch, capsys)
    assert (tmp_path / 'flapping_blade.png').stat().st_size > 10_000
    boundary = float(re.search(r'boundary: mu = (\S+)', out).group(1))
    # the printed boundary (6 decimals) is where the simulated monodromy turns unstable
    assert flap_growth_ivp(boundary - 2e-6) < 0 < flap_growth_ivp(boundary + 2e-6)
    rows = [line.split() for line in out.splitlines() if re.match(r'\s+0\.[012]\s', line)]
    assert len(rows) == 3
    for row in rows:
        mu, freq, damped, zeta = (float(v) for v in row[:4])
        truth = principal_rule_ivp(mu)
        lam = truth[np.argmax(truth.imag)]
        assert abs(freq - abs(lam)) < 2e-6 and abs(damped - lam.imag) < 2e-6
        assert abs(zeta + lam.real / abs(lam)) < 2e-6


@pytest.mark.slow
def test_ground_resonance_gallery_matches_simulation(tmp_path, monkeypatch, capsys):
    out = run('plot_ground_resonance.py', tmp_path, monkeypatch, capsys)
    assert (tmp_path / 'ground_resonance.png').stat().st_size > 10_000
    m = re.search(r'Floquet: +unstable for (\S+) < Omega < (\S+) rad/s, peak growth (\S+) '
                  r'1/s at (\S+) rad/s', out)
    lo, hi, peak, at = (float(v) for v in m.groups())
    assert abs(growth_ivp(lo)) < 1e-4 and abs(growth_ivp(hi)) < 1e-4
    assert abs(growth_ivp(at) - peak) < 1e-4
    m = re.search(r'averaging: +unstable for (\S+) < Omega < (\S+) rad/s, peak growth (\S+)',
                  out)
    assert [round(float(v), 2) for v in m.groups()] == [25.93, 30.60, 0.08]
