"""Plots of harmonic transfer functions.

`bode_htf` follows python-control's compute-then-plot split: the requested
components ``G_k(jω)`` of each HTF are computed as
`control.FrequencyResponseData` objects (`htf_response`) and drawn by
`control.bode_plot`, so ``ct.config.defaults['freqplot.*']`` (dB, Hz, deg,
grid, ...) apply unchanged.  `htf_map_plot` shows ``|H_{n,m}(jω)|`` as an
image, the second view of an HTF.
"""

import numpy as np
import control as ct
import matplotlib.axes
import matplotlib.pyplot as plt
from control.exception import ControlArgument

from .htf import HTF, HTFData, _harmonic, default_omega
from .._core.validation import real_array
from .._core.registry import method_alias

__all__ = ['htf_response', 'bode_htf', 'htf_map_plot']


def htf_response(htfs, omega=None, harmonics=(-1, 0, 1), *, omega_limits=None,
                 omega_num=None, progress=None):
    """Components ``G_k(jω)`` of one or several HTFs as FRDs.

    Parameters
    ----------
    htfs : HTF or list of HTF
        Harmonic transfer functions (model or data).
    omega : array_like, optional
        Frequencies in rad/s.  An `HTFData` uses its own grid when omitted.
    harmonics : sequence of int
        Harmonic indices k to return (default -1, 0, 1).
    omega_limits : (float, float), optional
        Frequency range of the default grid for an `HTFModel` (default
        ``ω_p/100`` to ``10 K ω_p``, below the Nyquist frequency in
        discrete time).
    omega_num : int, optional
        Number of points of the default grid (default
        ``ltp.config.defaults['htf.omega_num']``).
    progress : bool, optional
        Progress bar over long evaluations (default
        ``ltp.config.defaults['htf.progress']``).

    Returns
    -------
    list of list of control.FrequencyResponseData
        ``resp[i][j]`` is component ``harmonics[j]`` of ``htfs[i]``.

    Examples
    --------
    >>> sys = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0)
    >>> resp = ltp.htf_response(ltp.htf(sys, 1), [1.0, 2.0])
    >>> len(resp[0]), resp[0][1].omega.shape
    (3, (2,))
    """
    htfs = _htf_list(htfs)
    harmonics = _harmonic_list(harmonics)
    out = []
    for H in htfs:
        for k in harmonics:
            _harmonic(k, H.nharmonics)
        w = omega
        if w is None and not isinstance(H, HTFData):
            w = default_omega(H, omega_limits, omega_num)
        elif w is not None:
            w = real_array(w, 'omega', ndim=1)
        # one evaluation of the central block row serves every component
        out.append(H._frds(harmonics, w, progress=progress))
    return out


@method_alias
def bode_htf(htfs, omega=None, *fmt, harmonics=None, omega_limits=None,
             omega_num=None, plot_phase=None, label=None, ax=None, title=None,
             progress=None, **kwargs):
    """Bode plot of selected HTF components ``G_k(jω)``.

    Magnitude and phase of components k (by default every component the
    HTFs have, ``-K..K`` with K the smallest `nharmonics` among them) of one
    or several HTFs on one figure, as the thesis's Figs. 3.5/3.6 and 4.2.
    Several HTFs (for example true and estimated) are overlaid with a
    legend: as in python-control, colors cycle per system (one color per
    HTF) and the components of an HTF differ by line style; a single HTF
    gets one color per component.  Phases are wrapped to [-180°, 180°)
    unless ``wrap_phase=False`` is passed (then python-control unwraps each
    component continuously from its first frequency).

    Parameters
    ----------
    htfs : HTF or list of HTF
        Harmonic transfer functions to draw.
    omega : array_like, optional
        Frequencies in rad/s (see `htf_response`).
    *fmt : str, optional
        Matplotlib format string applied to every line.
    harmonics : sequence of int, optional
        Components to draw (default: all, ``-K..K``).
    omega_limits, omega_num : optional
        Default grid for an `HTFModel` (see `htf_response`).
    plot_phase : bool, optional
        Draw the phase (default `config.defaults['freqplot.plot_phase']`).
    label : list of str, optional
        Legend entries, one per line (HTF-major order).
    ax : array of matplotlib.axes.Axes, optional
        Axes to draw into (for overlaying onto an existing plot).
    title : str, optional
        Figure title.
    progress : bool, optional
        Progress bar over long evaluations (see `htf_response`).
    **kwargs
        Passed to `control.bode_plot` (``dB``, ``Hz``, ``deg``, ``grid``,
        matplotlib line properties, ...).

    Returns
    -------
    control.ControlPlot

    Examples
    --------
    >>> sys = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0)
    >>> cplt = ltp.bode_htf(ltp.htf(sys, 1), omega_num=20)
    >>> type(cplt).__name__
    'ControlPlot'
    """
    htfs = _htf_list(htfs)
    if harmonics is None:
        K = min(H.nharmonics for H in htfs)
        harmonics = list(range(-K, K + 1))
    harmonics = _harmonic_list(harmonics)
    resp = htf_response(htfs, omega, harmonics, omega_limits=omega_limits,
                        omega_num=omega_num, progress=progress)
    frds, labels, styles = [], [], []
    for i, (H, comps) in enumerate(zip(htfs, resp)):
        for j, (k, frd) in enumerate(zip(harmonics, comps)):
            if np.all(frd.frdata == 0):
                continue            # an identically zero component has no Bode plot
            frds.append(frd)
            labels.append(f"{H.name}: G_{k}" if len(htfs) > 1 else f"G_{k}")
            styles.append((i, j))
    if not frds:
        raise ValueError("all requested HTF components are identically zero")
    if label is not None:
        labels = list(label)
        if len(labels) != len(frds):
            raise ValueError(f"label must have {len(frds)} entries, got {len(labels)}")
    if title is None:
        title = "HTF components of " + ", ".join(H.name for H in htfs)
    if label is None and frds[0].noutputs * frds[0].ninputs > 1:
        labels = None           # MIMO: python-control's labels from the FRD names (G_k)
    kwargs.setdefault('wrap_phase', True)
    cplt = ct.bode_plot(frds, None, *fmt, plot_phase=plot_phase, label=labels, ax=ax,
                        title=title, **kwargs)
    if len(htfs) > 1 and not fmt and not {'color', 'c', 'linestyle', 'ls'} & set(kwargs):
        _style_per_system(cplt, styles)
    return cplt


# line styles of the components of one HTF when several HTFs are overlaid
_LINESTYLES = ['-', '--', '-.', ':', (0, (5, 1)), (0, (3, 1, 1, 1, 1, 1)), (0, (1, 3)),
               (0, (8, 2, 2, 2)), (0, (3, 3)), (0, (6, 1, 1, 1))]


def _style_per_system(cplt, styles):
    """One color per HTF (python-control's cycle), one line style per component."""
    import matplotlib.pyplot as plt
    colors = plt.rcParams['axes.prop_cycle'].by_key().get('color', ['C0'])
    for lines in cplt.lines.flat:
        for line, (i, j) in zip(lines, styles):
            line.set_color(colors[i % len(colors)])
            line.set_linestyle(_LINESTYLES[j % len(_LINESTYLES)])
    # rebuild the legends from the restyled lines
    for ax, legend in zip(cplt.axes.flat, np.ravel(cplt.legend)
                          if cplt.legend is not None else []):
        if legend is not None:
            handles, texts = ax.get_legend_handles_labels()
            loc = legend._loc
            legend.remove()
            new = ax.legend(handles, texts, loc=loc)
            cplt.legend[np.unravel_index(list(np.ravel(cplt.legend)).index(legend),
                                         cplt.legend.shape)] = new


def htf_map_plot(htf, omega, *, dB=True, ax=None, title=None, cmap='viridis'):
    """Image of the harmonic magnitudes ``|H_{n,m}(jω)|`` at one frequency.

    Parameters
    ----------
    htf : HTF
        An `HTFModel` (or an `HTFData` with ``ω + nω_p`` on its grid).
    omega : float
        Base frequency in rad/s.
    dB : bool
        Show ``20 log10 |H|`` (default) or the magnitude.
    ax : matplotlib.axes.Axes, optional
        Axes to draw into.
    title : str, optional
        Plot title.
    cmap : str
        Matplotlib colormap.

    Returns
    -------
    control.ControlPlot

    Examples
    --------
    >>> sys = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0)
    >>> cplt = ltp.htf_map_plot(ltp.htf(sys, 2), 1.0)
    >>> cplt.axes.shape
    (1, 1)
    """
    if not isinstance(htf, HTF):
        raise ControlArgument(f"htf must be an HTF, got {type(htf).__name__}")
    omega = float(real_array(omega, 'omega', ndim=0))
    M = np.abs(htf(1j * omega))
    if dB:
        with np.errstate(divide='ignore'):
            M = 20 * np.log10(M)
        M[~np.isfinite(M)] = np.nan
    if ax is None:
        fig, ax = plt.subplots()
    elif not isinstance(ax, matplotlib.axes.Axes):
        raise ControlArgument(f"ax must be a matplotlib Axes, got {type(ax).__name__}")
    fig = ax.figure
    K = htf.nharmonics
    ext = (-K - 0.5, K + 0.5, K + 0.5, -K - 0.5)
    image = ax.imshow(M, cmap=cmap, extent=ext, interpolation='nearest')
    ax.set_xlabel("input harmonic m")
    ax.set_ylabel("output harmonic n")
    fig.colorbar(image, ax=ax, label="|H_{n,m}| [dB]" if dB else "|H_{n,m}|")
    ax.set_title(title or f"{htf.name}: |H(jω)| at ω = {omega:g} rad/s")
    return ct.ControlPlot(np.array([[[image]]], dtype=object), np.array([[ax]]), fig)


def _harmonic_list(harmonics):
    if isinstance(harmonics, (int, np.integer)) or not np.iterable(harmonics):
        raise ControlArgument(f"harmonics must be a sequence of integers, got {harmonics!r}")
    return list(harmonics)


def _htf_list(htfs):
    htfs = list(htfs) if isinstance(htfs, (list, tuple)) else [htfs]
    for H in htfs:
        if not isinstance(H, HTF):
            raise ControlArgument(f"htfs must be HTF objects, got {type(H).__name__}")
    return htfs

