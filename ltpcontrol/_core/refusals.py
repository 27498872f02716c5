"""What python-control asks of an LTI system that has no meaning for an LTP one.

One table, `REFUSED`: python-control's name -> what to use instead.  The
methods of `LTPStateSpace` (``sys.dcgain()``, ``sys(s)``) and the
python-control bridge (`ltpcontrol.interop`) raise the same errors from it.
"""

from control.exception import ControlArgument

__all__ = []

_HTF = ("ltp.htf(sys, nharmonics) (or ltp.harmonic_ss) for the harmonic transfer function; "
        "HTF.component(k, omega) or ltp.htf_response give its components")
_LTI = ("sys.to_ss() for constant matrices, sys.average(), sys.linearize(t=...) or "
        "ltp.lift(sys) for an LTI view")
_STEADY = ("the periodic steady state (ltp.forced_response over enough periods, or "
           "ltp.limit_cycle for an orbit of a nonlinear system): a forced periodic "
           "system has periodic orbits, not equilibria")
_CANON = "ltp.to_canonical or ltp.floquet_transform (a periodic change of state basis)"

#: python-control name -> what to use instead (the bridge's refusals and the
#: methods of `LTPStateSpace`: ``frequency_response``, ``dcgain``, ``sys(s)``)
REFUSED = {
    # frequency domain: an LTP system has a harmonic transfer function
    'frequency_response': _HTF,
    'bode_plot': "ltp.bode_htf(ltp.htf(sys, nharmonics))",
    'nyquist_plot': ("ltp.nyquist_htf(L, nharmonics).plot() (generalized Nyquist criterion "
                     "of a periodic loop)"),
    'nyquist_response': ("ltp.nyquist_htf(L, nharmonics) (generalized Nyquist criterion of "
                         "a periodic loop)"),
    'nichols_plot': "ltp.bode_htf(ltp.htf(sys, nharmonics))",
    'singular_values_plot': "ltp.htf_map_plot(ltp.htf(sys, nharmonics), omega)",
    'evaluation': "ltp.htf(sys, nharmonics)(s), the harmonic transfer function",
    'dcgain': "ltp.htf(sys, nharmonics)(0) (the harmonic DC gains)",
    'margin': ("ltp.stability_margins(L) (python-control's return values) or "
               "ltp.harmonic_margins(L) (upper and lower gain, phase and disk margins with "
               "their harmonics)"),
    'stability_margins': ("ltp.stability_margins(L) (python-control's return values) or "
                          "ltp.harmonic_margins(L)"),
    'disk_margins': "ltp.harmonic_margins(L) (its disk, disk_gain and disk_phase)",
    'bandwidth': _HTF,
    'describing_function_response': _HTF,
    # poles: Floquet exponents
    'damp': "ltp.floquet_exponents(sys)",
    'root_locus_map': "ltp.floquet_exponents of the closed loops",
    'root_locus_plot': "ltp.floquet_exponents of the closed loops",
    'step_info': "ct.step_info(ltp.step_response(sys, T).outputs, T)",
    # LTI representations and canonical forms
    'similarity_transform': _CANON,
    'canonical_form': _CANON,
    'reachable_form': _CANON,
    'observable_form': _CANON,
    'modal_form': _CANON,
    'ss': _LTI, 'tf': _LTI, 'ss2tf': _LTI, 'tf2ss': _LTI,
    'pole_zero_plot': "ct.pole_zero_map(sys).plot() (Floquet exponents and zeros)",
    'phase_crossover_frequencies': "ltp.floquet_multipliers or ltp.is_stable",
    'phase_plane_plot': ("ltp.forced_response or ltp.initial_response (the vector field "
                         "of an LTP system changes with time)"),
    'phase_plot': ("ltp.forced_response or ltp.initial_response (the vector field "
                   "of an LTP system changes with time)"),
    'frd': _HTF,
    'nlsys': ("the LTPStateSpace itself (it is a NonlinearIOSystem; ct.nlsys would take "
              "it for an update function)"),
    'ssdata': "sys.A, sys.B, sys.C, sys.D (periodic matrices) or sys.to_ss()",
    'tfdata': _LTI,
    'split_tf': _LTI,
    'bdschur': _CANON,
    'model_reduction': "ltp.balred (periodic balanced truncation)",
    'ispassive': "ltp.lift(sys) for an LTI view (no periodic passivity test)",
    'solve_passivity_LMI': "ltp.lift(sys) for an LTI view (no periodic passivity test)",
    'get_input_ff_index': "ltp.lift(sys) for an LTI view (no periodic passivity test)",
    'get_output_fb_index': "ltp.lift(sys) for an LTI view (no periodic passivity test)",
    # synthesis without a periodic counterpart
    'mixsyn': "ltp.lqg or ltp.lmi_statefbk (periodic H2 and H-infinity state feedback)",
    'h2syn': "ltp.lqg (H2-optimal output feedback) or ltp.lmi_statefbk(objective='h2')",
    'hinfsyn': "ltp.lmi_statefbk(objective='hinf') (periodic H-infinity state feedback)",
    'augw': "ltp.interconnect of the plant and LTI weights",
    'find_operating_point': _STEADY,
    'create_estimator_iosystem': "ltp.lqg(sys, ...) (the periodic observer-based controller)",
    'create_statefbk_iosystem': ("ltp.feedback(sys, K) with K a PeriodicMatrix gain "
                                 "(or ltp.lqg for an observer-based controller)"),
    # matrices: what to use when a matrix is a PeriodicMatrix
    'lyap': "ltp.lyap(A, Q) for the periodic Lyapunov equation",
    'dlyap': "ltp.dlyap(A, Q) with the step matrices stacked, shape (N, n, n)",
    'care': "ltp.care(A, B, Q, R) for the periodic Riccati equation",
    'dare': "ltp.dare(A, B, Q, R) with the step matrices stacked, shape (N, ., .)",
    'lqr': "ltp.lqr(sys, Q, R) with the plant as an LTPStateSpace",
    'dlqr': "ltp.dlqr(sys, Q, R) with the plant as an LTPStateSpace",
    'lqe': "ltp.lqe(sys, QN, RN) with the plant as an LTPStateSpace",
    'dlqe': "ltp.dlqe(sys, QN, RN) with the plant as an LTPStateSpace",
    'place': "ltp.place(sys, p) with the plant as an LTPStateSpace",
    'place_varga': "ltp.place(sys, p) with the plant as an LTPStateSpace",
    'place_acker': "ltp.place(sys, p) with the plant as an LTPStateSpace",
    'acker': "ltp.place(sys, p) with the plant as an LTPStateSpace",
    'ctrb': "ltp.gram(sys, 'c') or ltp.lift(sys) (the lifted LTI system's controllability)",
    'obsv': "ltp.gram(sys, 'o') or ltp.lift(sys) (the lifted LTI system's observability)",
}


def refusal(name):
    """The error for python-control's `name` (function or method) on an LTP system.

    Examples
    --------
    >>> from ltpcontrol._core.refusals import refusal
    >>> err = refusal('dcgain')
    >>> isinstance(err, ct.ControlArgument)
    True
    >>> print(err)  # doctest: +NORMALIZE_WHITESPACE
    dcgain does not apply to a linear time-periodic system (LTPStateSpace): use
    ltp.htf(sys, nharmonics)(0) (the harmonic DC gains)
    """
    return refusal_error(name, REFUSED[name])


def refusal_error(what, hint):
    """The error for `what` on an LTP system, pointing to `hint`.

    Examples
    --------
    >>> from ltpcontrol._core.refusals import refusal_error
    >>> print(refusal_error('ct.margin', 'ltp.stability_margins(L, nharmonics)'))
    ct.margin does not apply to a linear time-periodic system (LTPStateSpace): use
    ltp.stability_margins(L, nharmonics)
    """

    return ControlArgument(f"{what} does not apply to a linear time-periodic system "
                           f"(LTPStateSpace): use {hint}")
