"""The default number of chirp replicas and its alias warning.

Tests of internals: they import private names (see the Developer notes).
"""

import warnings

import pytest

import ltpcontrol as ltp
from ltpcontrol._identification.excitation import _replicas


def test_replicas_default_and_alias_warning():
    assert _replicas(None, 2, None, 'nreplicas') == 7          # K + 2K + 1
    assert _replicas(None, 2, 3, 'nreplicas') == 6
    with pytest.warns(UserWarning, match=r'components \[-2, 2\] aliased'):
        _replicas(5, 2, 3, 'nreplicas')
    with warnings.catch_warnings():
        warnings.simplefilter('error')
        assert _replicas(5, 2, None, 'nreplicas') == 5        # 2K+1 for K_p = K
    exc = ltp.chirp_replicas(1.0, None, 2.0, 0.0, 5.0, dt=0.01, nharmonics=1)
    assert exc.segments.shape == (4, 2)
    assert ltp.multisine([4.0, 8.0], 1.0, dt=0.01, nperiods=4, nharmonics=1,
                         plant_harmonics=1).inputs.shape[1] == 3
    with pytest.raises(ValueError, match='nharmonics'):
        ltp.chirp_replicas(1.0, None, 2.0, 0.0, 5.0, dt=0.01)
