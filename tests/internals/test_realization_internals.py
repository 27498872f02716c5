"""The structure distance of the Floquet realization: literal against corrected.

Tests of internals: they import private names (see the Developer notes).
"""

import numpy as np

import ltpcontrol as ltp
from ltpcontrol._identification.realization import _Problem
from test_realization import _scramble
from systems import mathieu


def test_literal_distance_is_not_scale_invariant():
    # the literal distance is not scale invariant: d_C shrinks with T
    sysc = mathieu()
    sysd = ltp.sample_system(sysc, sysc.period / 50, 'tustin')
    ident = _scramble(ltp.lift(sysd, nharmonics=1), 3)
    prob = _Problem.from_system(ident, 1, 50, None, 'all')
    T = np.random.default_rng(0).standard_normal((6, 6))
    lit = [prob.distance(c * T[None], literal=True)[1]['C'][0] for c in (1.0, 0.1)]
    cor = [prob.distance(c * T[None])[0][0] for c in (1.0, 0.1)]
    assert np.isclose(lit[1], 0.01 * lit[0]) and np.isclose(cor[0], cor[1])
