"""ltpcontrol: linear time-periodic systems in the idiom of python-control.

The conventions (Fourier scaling, harmonic order, HTF blocks, Tustin
scaling) are stated once on the Conventions page of the documentation.
Examples assume::

    import numpy as np
    import control as ct
    import ltpcontrol as ltp
"""

from ._periodic_matrix import PeriodicMatrix
from ._ltpsys import LTPStateSpace, ltpss, series, parallel, feedback, append, negate
from ._timeresp import forced_response, step_response, initial_response, impulse_response
from ._htf import HTF, htf
from ._htfplot import htf_response, bode_htf, htf_map_plot
from ._fdsubspace import fdsubspace, FDSubspaceInfo
from ._hybrid_ls import hybrid_ls, HybridLSResult

__version__ = "0.1.0"

__all__ = [
    'PeriodicMatrix', 'LTPStateSpace', 'ltpss',
    'series', 'parallel', 'feedback', 'append', 'negate',
    'forced_response', 'step_response', 'initial_response', 'impulse_response',
    'HTF', 'htf', 'htf_response', 'bode_htf', 'htf_map_plot',
    'fdsubspace', 'FDSubspaceInfo', 'hybrid_ls', 'HybridLSResult',
]
