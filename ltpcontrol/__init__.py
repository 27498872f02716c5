"""ltpcontrol: linear time-periodic systems in the idiom of python-control.

The conventions (Fourier scaling, harmonic order, HTF blocks, Tustin
scaling) are stated once on the Conventions page of the documentation.
Examples assume::

    import numpy as np
    import control as ct
    import ltpcontrol as ltp
"""

from ._core.periodic_matrix import PeriodicMatrix
from ._core.ltpsys import LTPStateSpace, ltpss, series, parallel, feedback, append, negate
from ._core.interconnect import interconnect
from ._core.timeresp import forced_response, step_response, initial_response, impulse_response
from ._core.frames import (clarke_matrix, park_matrix, frame_transform, park, clarke,
                           sequence_components)
from ._core.floquet import (monodromy, floquet_multipliers, floquet_exponents, is_stable,
                       floquet_transform)
from ._frequency.htf import HTF, HTFModel, HTFData, htf
from ._frequency.htfplot import htf_response, bode_htf, htf_map_plot
from ._core.discretize import sample_system, d2c
from ._core.lifting import lift
from ._orbits.hybrid import simulate_hybrid, saltation_matrix
from ._orbits.hybrid_plant import HybridMode, HybridPlant
from ._orbits.orbits import PeriodicOrbit, periodic_orbit, period_map, linearize_orbit
from ._orbits.autonomous import limit_cycle, poincare_map
from ._orbits.continuation import Bifurcation, OrbitBranch, orbit_continuation
from ._identification.excitation import Excitation, chirp_replicas, multisine, sine_experiments
from ._identification.htf_estimate import estimate_htf, HTFEstimateInfo
from ._identification.htf_fit import HTFFit, HTFFitInfo, DelayEstimate, fit_htf, estimate_delays
from ._core.metrics import e_rms, nrmse
from ._identification.fdsubspace import fdsubspace, FDSubspaceInfo
from ._identification.hybrid_ls import hybrid_ls, HybridLSResult
from ._identification.realization import floquet_realization, FloquetRealization
from ._identification.canonical import to_canonical, matrix_errors, MatrixErrors
from ._identification.canonical import compare_ltp, LTPComparison
from ._identification.structure import select_structure, StructureSelection
from ._identification.ltp_subspace import lifted_frequency_response, identify_ltp, LTPSubspaceInfo
from ._identification.arx import identify_arx, ARXInfo
from ._orbits.closed_loop import ClosedLoopOrbit, closed_loop_response, closed_loop_orbit
from ._analysis.lyapunov import lyap, dlyap, gram
from ._analysis.norms import norm
from ._analysis.floquet_modes import floquet_modes, FloquetModes
from ._rotors.rotor_model import RotorStateSpace
from ._rotors.mbc import mbc, coleman_matrix
from ._rotors.read_lin import read_lin
from ._rotors.campbell import campbell, CampbellDiagram
from ._rotors.campbell_lin import campbell_lin
from ._rotors.mode_labels import mode_labels
from ._analysis.zeros import zeros
from ._frequency.harmonic_ss import harmonic_ss
from ._frequency.harmonic_modes import harmonic_modes, HarmonicModes
from ._frequency.nyquist import nyquist_htf, HarmonicNyquistResponse
from ._frequency.margins import harmonic_margins, stability_margins, HarmonicMargins, MarginPoint
from ._frequency.loop_functions import (sensitivity_htf, complementary_sensitivity_htf,
                                        siso_equivalent, harmonic_admittance,
                                        harmonic_impedance)
from ._analysis.riccati import care, dare
from ._analysis.design import lqr, dlqr, lqe, dlqe, lqg
from ._analysis.place import place
from ._analysis.hhc import hhc_tmatrix, hhc_controller
from ._analysis.lmi import lmi_statefbk, LMIDesign
from ._analysis.reduction import hsvd, balred, minreal
from ._identification.refine import refine_ltp, RefineInfo
from ._identification.montecarlo import monte_carlo, MonteCarloResult
from ._identification.scenarios import sample_models
from .storage import save, load
from ._core.tvsystem import DiscreteLTPSystem, dltpss
from ._core import tvresponse as _tv_response  # noqa: F401  (registers the overrides)
from ._core.lifting_forms import unlift
from ._core.multirate import sample_multirate
from ._analysis.multirate_loop import lifted_margins
from ._analysis.output_feedback import ofstab, oflqr, OutputFeedbackResult
from ._analysis.hinf import hinfnorm
from ._analysis.hinf_statefbk import hinf_statefbk, HinfStateFeedbackResult
from ._analysis.lyapchol import lyapchol, dlyapchol
from ._analysis.finite_horizon import care_finite, lyap_finite, h2norm_finite
from ._analysis.sylvester import sylvester, dsylvester
from ._identification.validate import validate_ltp, LTPValidation
from ._identification.joint_io import joint_io_htf

__version__ = "0.1.0"

from ._delays.ltpdsys import LTPDelayStateSpace, ltpdss
from ._delays.monodromy import delay_monodromy, DelayMonodromy
from ._delays import analysis as _delay_analysis  # noqa: F401  (registers the overrides)
from ._delays.htf import DelayHTF
from ._delays.connect import Delay, delay
from ._delays.margins import delay_margin
from ._delays import nyquist as _delay_nyquist  # noqa: F401  (registers the overrides)
from ._delays import timeresp as _delay_timeresp  # noqa: F401  (registers the overrides)
from ._delays.chart import stability_chart, StabilityChart, StabilityChartError
from ._frequency.impedance import LTIHTF, rlc_impedance
from ._frequency.products import harmonic_product
from ._frequency.measured_loop import (impedance_nyquist, impedance_margins,
                                       SampledNyquistResponse)
from ._analysis.sampled_loop import sampled_loop, lifted_nyquist, LiftedNyquistResponse
from ._frequency.coupling import frame_htf, FrameHTF

#: Alias of `sample_system`, as in python-control.
c2d = sample_system

__all__ = [
    # systems and periodic matrices
    'PeriodicMatrix', 'LTPStateSpace', 'ltpss',
    'series', 'parallel', 'feedback', 'append', 'negate',
    'interconnect',
    # time responses
    'forced_response', 'step_response', 'initial_response', 'impulse_response',
    # Floquet theory
    'monodromy', 'floquet_multipliers', 'floquet_exponents', 'is_stable',
    'floquet_transform',
    # frequency domain
    'HTF', 'HTFModel', 'HTFData', 'htf', 'htf_response', 'bode_htf', 'htf_map_plot',
    # three-phase frames
    'clarke_matrix', 'park_matrix', 'frame_transform', 'park', 'clarke',
    'sequence_components',
    # harmonic stability of periodic loops
    'nyquist_htf', 'HarmonicNyquistResponse', 'harmonic_margins', 'stability_margins',
    'HarmonicMargins', 'MarginPoint', 'sensitivity_htf', 'complementary_sensitivity_htf',
    'siso_equivalent', 'harmonic_admittance', 'harmonic_impedance',
    'hhc_tmatrix', 'hhc_controller',
    'sample_system', 'c2d', 'd2c', 'lift',
    # rhythmic plants and their orbits
    'HybridMode', 'HybridPlant', 'simulate_hybrid', 'saltation_matrix',
    'PeriodicOrbit', 'periodic_orbit', 'period_map', 'linearize_orbit',
    'limit_cycle', 'poincare_map', 'Bifurcation', 'OrbitBranch', 'orbit_continuation',
    # identification
    'Excitation', 'chirp_replicas', 'multisine', 'sine_experiments',
    'estimate_htf', 'HTFEstimateInfo', 'HTFFit', 'HTFFitInfo', 'DelayEstimate', 'fit_htf', 'estimate_delays',
    'e_rms', 'nrmse',
    'fdsubspace', 'FDSubspaceInfo', 'hybrid_ls', 'HybridLSResult',
    'floquet_realization', 'FloquetRealization', 'to_canonical', 'matrix_errors',
    'MatrixErrors', 'lifted_frequency_response', 'identify_ltp', 'LTPSubspaceInfo',
    'compare_ltp', 'LTPComparison', 'select_structure', 'StructureSelection',
    'identify_arx', 'ARXInfo',
    # feedback around orbits of hybrid plants
    'ClosedLoopOrbit', 'closed_loop_response', 'closed_loop_orbit',
    # analysis: Lyapunov equations, gramians, zeros, norms
    'lyap', 'dlyap', 'gram', 'norm', 'zeros', 'harmonic_ss',
    # control design
    'care', 'dare', 'lqr', 'dlqr', 'lqe', 'dlqe', 'lqg', 'place',
    'lmi_statefbk', 'LMIDesign', 'hsvd', 'balred', 'minreal',
    # noisy data and Monte-Carlo studies
    'refine_ltp', 'RefineInfo', 'monte_carlo', 'MonteCarloResult',
    'sample_models',
    # rotors and wind turbines
    'floquet_modes', 'FloquetModes', 'RotorStateSpace', 'mbc', 'coleman_matrix', 'read_lin',
    'campbell', 'CampbellDiagram',
    'campbell_lin', 'mode_labels',
    # files
    'save', 'load',
    # periodic systems with delays
    'LTPDelayStateSpace', 'ltpdss', 'delay_monodromy', 'DelayMonodromy', 'DelayHTF',
    'Delay', 'delay', 'delay_margin',
    'stability_chart', 'StabilityChart', 'StabilityChartError',
    # discrete periodic systems with time-varying dimensions, lifted forms
    'DiscreteLTPSystem', 'dltpss', 'unlift', 'sample_multirate', 'lifted_margins',
    # harmonic stability
    'harmonic_modes', 'HarmonicModes',
    # periodic design beyond state feedback
    'ofstab', 'oflqr', 'OutputFeedbackResult', 'hinfnorm',
    'care_finite', 'lyap_finite', 'h2norm_finite', 'sylvester', 'dsylvester',
    # validation of identified models on time records
    'validate_ltp', 'LTPValidation',
    # impedance-based stability: network impedances, products, measured loops
    'LTIHTF', 'rlc_impedance', 'harmonic_product', 'impedance_nyquist',
    'impedance_margins', 'SampledNyquistResponse', 'frame_htf', 'FrameHTF',
    # sampled-data loops around continuous periodic plants
    'sampled_loop', 'lifted_nyquist', 'LiftedNyquistResponse',
    # periodic H∞ state feedback, factored Lyapunov solutions
    'hinf_statefbk', 'HinfStateFeedbackResult', 'lyapchol', 'dlyapchol',
    # the plant from closed-loop records
    'joint_io_htf',
]

# the python-control bridge (see interop): on unless ltp.config says otherwise
from . import config  # noqa: E402
from . import interop  # noqa: E402
if config.defaults['interop.enabled']:
    interop.enable()
