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

#: python-control names that have no LTP meaning as called -> what to use instead
REFUSED = {
    'frequency_response': _HTF,
    'bode_plot': "ltp.bode_htf(ltp.htf(sys, nharmonics))",
    'nyquist_plot': ("ltp.nyquist_htf(L, nharmonics).plot() (generalized Nyquist criterion "
                     "of a periodic loop)"),
    'nyquist_response': ("ltp.nyquist_htf(L, nharmonics) (generalized Nyquist criterion of "
                         "a periodic loop)"),
    'nichols_plot': "ltp.bode_htf(ltp.htf(sys, nharmonics))",
    'singular_values_response': _HTF,
    'singular_values_plot': "ltp.htf_map_plot(ltp.htf(sys, nharmonics), omega)",
    'evalfr': "ltp.htf(sys, nharmonics)(s)",
    'dcgain': "ltp.htf(sys, nharmonics)(0) (the harmonic DC gains)",
    'margin': ("ltp.stability_margins(L) (python-control's return values) or "
               "ltp.harmonic_margins(L) (upper and lower gain, phase and disk margins with "
               "their harmonics)"),
    'stability_margins': ("ltp.stability_margins(L) (python-control's return values) or "
                          "ltp.harmonic_margins(L)"),
    'disk_margins': "ltp.harmonic_margins(L) (its disk, disk_gain and disk_phase)",
    'bandwidth': _HTF,
    'damp': "ltp.floquet_exponents(sys)",
    'pole_zero_map': "ltp.floquet_exponents(sys)",
    'pole_zero_plot': "ltp.floquet_exponents(sys)",
    'root_locus_map': "ltp.floquet_exponents of the closed loops",
    'root_locus_plot': "ltp.floquet_exponents of the closed loops",
    'step_info': "ct.step_info(ltp.step_response(sys, T).outputs, T)",
    'similarity_transform': "ltp.floquet_transform or ltp.to_canonical",
    'canonical_form': "ltp.to_canonical",
    'ss': _LTI,
    'tf': _LTI,
    'ss2tf': _LTI,
    'mixsyn': "ltpcontrol's synthesis functions",
    'find_operating_point': _STEADY,
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
    """The error for `what` on an LTP system, pointing to `hint`."""
    return ControlArgument(f"{what} does not apply to a linear time-periodic system "
                           f"(LTPStateSpace): use {hint}")
