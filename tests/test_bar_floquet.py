"""Floquet exponents of a real OpenFAST model: the 44-state BAR_URC_EDBD.1.lin after mbc.

ElastoDyn + BeamDyn (openfast_toolbox test data, see tests/data/README.md):
the multi-blade model has ‖A‖ ≈ 5e6 and exponents down to -1.5e4 rad/s at a
rotor speed of 0.83 rad/s.  The file's rotating-frame matrix, taken as
independent of the azimuth and turning at the file's rotor speed, is seen
through the periodic multi-blade transform, so the exact exponents are the
eigenvalues of the file's A modulo jΩ (the benchmark P14-BAR times it).
"""

from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import linear_sum_assignment

import ltpcontrol as ltp

DATA = Path(__file__).parent / 'data'


@pytest.mark.slow
def test_bar_exponents_equal_the_eigenvalues_of_the_rotating_frame_matrix():
    lin = ltp.read_lin(DATA / 'BAR_URC_EDBD.1.lin')
    A = np.asarray(lin.samples[0][0])
    n = A.shape[0]
    Omega = lin.rotor_speed
    rot = ltp.ltpss(A, np.zeros((n, 0)), np.zeros((0, n)), np.zeros((0, 0)),
                    period=2 * np.pi / Omega)
    # BeamDyn node 2 of each blade: 6 displacements and their rates
    rotating = [[8 + j, 20 + j, 32 + j] for j in range(6)]
    rates = [[14 + j, 26 + j, 38 + j] for j in range(6)]
    nr, _ = ltp.mbc(rot, rotating, 3, rates=rates, rotor_speed=Omega)
    assert not nr.A.is_constant
    lam = ltp.floquet_exponents(nr)
    truth = np.linalg.eigvals(A)
    scale = np.abs(truth.real).max()
    assert scale > 1e4                                   # the stiff part is there
    # pair exponents and eigenvalues: real parts, imaginary parts modulo Ω
    dre = np.abs(truth.real[:, None] - lam.real[None, :])
    dim = np.abs(np.angle(np.exp(2j * np.pi * (truth.imag[:, None] - lam.imag[None, :])
                                 / Omega))) * Omega / (2 * np.pi)
    cost = dre + dim
    rows, cols = linear_sum_assignment(cost)
    assert len(rows) == n
    assert dre[rows, cols].max() <= 1e-8 * scale
    assert dim[rows, cols].max() <= 1e-8 * scale
