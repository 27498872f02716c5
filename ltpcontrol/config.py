"""Default settings of ltpcontrol, in the style of `control.config`.

``ltp.config.defaults`` is a dictionary of dotted keys ``'module.param'``:

``htf.max_memory`` : float, default 1e9
    Bound in bytes on the working memory of one HTF evaluation.  `htf`,
    `bode_htf` and `htf_response` split the frequency axis into chunks
    that fit; a request whose fixed part (the harmonic state space and its
    factorisation) does not fit is refused with the estimated size.
``htf.omega_num`` : int, default 500
    Number of points of the default frequency grid of a model HTF
    (`htf_response`, `bode_htf`, `HTF.components`).
``htf.progress`` : bool, default False
    Show a progress bar over the frequency chunks of long evaluations.
``interop.enabled`` : bool, default True
    python-control's entry points called on an LTP system give ltpcontrol's
    answer or a clear error (``ltpcontrol.interop``).  False turns the
    installed dispatchers into pass-throughs; `ltpcontrol.interop.disable`
    removes them.  The environment variable ``LTPCONTROL_INTEROP=0`` sets
    the default to False (read when ltpcontrol is imported).
``period.max_multiple`` : int, default 100
    Largest integer ``q`` accepted in a common period ``T = q T_1 = p T_2``
    when systems of different periods are combined.
``period.rtol`` : float, default 1e-9
    Relative tolerance of the rational period ratio ``T_1/T_2 = p/q``.
``timeresp.compiled`` : bool, default True
    `forced_response` on long grids whose phases never repeat (at least
    20 000 samples, at most 16 states) marches with a compiled kernel when
    numba is installed (``pip install ltpcontrol[fast]``).  The kernel is
    compiled at its first use for the system's sizes and cached on disk (a
    few seconds, once per environment and sizes).  False: always the NumPy
    march (same results to rounding).

Examples
--------
>>> ltp.config.defaults['htf.max_memory']
1000000000.0
>>> with ltp.config.defaults_context({'htf.max_memory': 2e9}):
...     ltp.config.defaults['htf.max_memory']
2000000000.0
"""

import contextlib
import os

__all__ = ['defaults', 'set_defaults', 'reset_defaults', 'defaults_context']

_DEFAULTS = {
    'htf.max_memory': 1e9,
    'htf.omega_num': 500,
    'htf.progress': False,
    'interop.enabled': os.environ.get('LTPCONTROL_INTEROP', '1').strip() not in ('0', 'false',
                                                                              'False'),
    'period.max_multiple': 100,
    'period.rtol': 1e-9,
    'timeresp.compiled': True,
}

#: Current settings (see the module docstring for the keys).
defaults = dict(_DEFAULTS)


def set_defaults(module, **keywords):
    """Set default values of the keys ``module.<keyword>``.

    Parameters
    ----------
    module : str
        Key prefix, e.g. ``'htf'``.
    **keywords
        New values; unknown keys raise `TypeError`, as in
        `control.set_defaults`.

    Examples
    --------
    >>> ltp.config.set_defaults('htf', max_memory=5e8)
    >>> ltp.config.defaults['htf.max_memory']
    500000000.0
    >>> ltp.config.reset_defaults()
    """
    for key, value in keywords.items():
        name = f"{module}.{key}"
        if name not in defaults:
            raise TypeError(f"unrecognized keyword: {name}")
        defaults[name] = value


def reset_defaults():
    """Restore the default values of every key.

    Examples
    --------
    >>> ltp.config.reset_defaults()
    >>> ltp.config.defaults['htf.progress']
    False
    """
    defaults.clear()
    defaults.update(_DEFAULTS)


@contextlib.contextmanager
def defaults_context(values):
    """Temporarily change settings; the previous values return on exit.

    Parameters
    ----------
    values : dict
        Keys and values to set inside the ``with`` block.

    Examples
    --------
    >>> with ltp.config.defaults_context({'htf.progress': True}):
    ...     ltp.config.defaults['htf.progress']
    True
    """
    unknown = set(values) - set(defaults)
    if unknown:
        raise TypeError(f"unrecognized keyword(s): {sorted(unknown)}")
    saved = {key: defaults[key] for key in values}
    defaults.update(values)
    try:
        yield
    finally:
        defaults.update(saved)


def _get(key, value=None):
    """Explicit argument if given, else the current default."""
    return defaults[key] if value is None else value
