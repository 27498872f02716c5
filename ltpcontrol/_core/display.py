"""Text and notebook display of LTP systems, in python-control's style.

``print(sys)`` lists the signals, the period and one line per matrix; the
notebook form (``_repr_html_``) adds the equations and each matrix in
LaTeX: constant matrices in full, periodic ones as their mean plus a short
description of the variation (Fourier order, number of switching pieces),
so that long switching or sampled sequences stay readable.
"""

import numpy as np
import control as ct

__all__ = []

#: switching instants shown in full up to this count, else summarised
MAX_TIMES = 6


def describe(M, nsteps=None):
    """One-line description of a PeriodicMatrix (never the full switching list).

    Examples
    --------
    >>> from ltpcontrol._core.display import describe
    >>> describe(ltp.PeriodicMatrix.constant(np.eye(2), 1.0))
    'constant'
    >>> M = ltp.PeriodicMatrix(np.array([[[0.5]], [[1.0]], [[0.5]]]), 2 * np.pi)
    >>> describe(M), describe(M, nsteps=8)
    ('Fourier series, K = 1', 'sequence of 8 matrices per period')
    """
    if M.is_constant:
        return "constant"
    if nsteps is not None:
        return f"sequence of {nsteps} matrices per period"
    if M.nharmonics is not None:
        return f"Fourier series, K = {M.nharmonics}"
    if M.switching_times is not None:
        times = np.round(M.switching_times, 6).tolist()
        if len(times) > MAX_TIMES:
            shown = ", ".join(f"{x:g}" for x in times[:3]) + f", ..., {times[-1]:g}"
            return f"switching, {len(times)} pieces at [{shown}]"
        return f"switching at {times}"
    return "smooth function of t" if M.is_function else "combination"


def text(sys):
    """The ``print(sys)`` form.

    Examples
    --------
    >>> from ltpcontrol._core.display import text
    >>> sys = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=2.0, name='P')
    >>> text(sys) == str(sys)
    True
    >>> text(sys).splitlines()[0], text(sys).splitlines()[4]
    ('<LTPStateSpace>: P', 'period = 2')
    """
    lines = [f"<LTPStateSpace>: {sys.name}",
             f"Inputs ({sys.ninputs}): {sys.input_labels}",
             f"Outputs ({sys.noutputs}): {sys.output_labels}",
             f"States ({sys.nstates}): {sys.state_labels}",
             f"period = {sys.period:g}"]
    if sys.isdtime():
        lines.append(f"dt = {sys.dt:g} ({sys.nsteps} steps per period)")
    for label, M in (('A', sys.A), ('B', sys.B), ('C', sys.C), ('D', sys.D)):
        head = f"{label} ({M.shape[0]}x{M.shape[1]}, {describe(M, sys.nsteps)})"
        if M.is_constant and M.shape[0] * M.shape[1]:
            body = np.array2string(M(0.0), prefix=f"{label} = ")
            lines.append(f"\n{label} = {body}")
        else:
            lines.append(head)
    return "\n".join(lines)


def html(sys):
    """Notebook form: info line and LaTeX, or None when the system is too large.

    Examples
    --------
    >>> from ltpcontrol._core.display import html
    >>> sys = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=2.0)
    >>> html(sys) == sys._repr_html_(), 'T = 2' in html(sys)
    (True, True)
    >>> big = ltp.ltpss(-np.eye(20), np.ones((20, 1)), np.ones((1, 20)), 0, period=1.0)
    >>> html(big) is None
    True
    """
    if sys.nstates + max(sys.noutputs, sys.ninputs) > ct.config.defaults['statesp.latex_maxsize']:
        return None
    if sys.isdtime():
        eq = (r"x[k+1] &= A[k]\,x[k] + B[k]\,u[k], \quad y[k] = C[k]\,x[k] + D[k]\,u[k],"
              rf"\quad N = {sys.nsteps},\ \Delta t = {sys.dt:g}")
        arg = "[k]"
    else:
        eq = (r"\dot x &= A(t)\,x + B(t)\,u, \quad y = C(t)\,x + D(t)\,u,"
              rf"\quad T = {sys.period:g}")
        arg = "(t)"
    rows = [eq]
    for label, M in (('A', sys.A), ('B', sys.B), ('C', sys.C), ('D', sys.D)):
        if M.shape[0] * M.shape[1] == 0:
            continue
        if M.is_constant:
            rows.append(f"{label} &= {_latex_matrix(M(0.0))}")
        else:
            mean = (M.sample(sys.nsteps).mean(axis=0) if sys.isdtime()
                    else M.fourier(0)[0].real)
            rows.append(rf"{label}{arg} &= \bar {label} + \tilde {label}{arg}, \quad "
                        rf"\bar {label} = {_latex_matrix(mean)} \quad "
                        rf"\text{{({describe(M, sys.nsteps)})}}")
    return (sys._repr_info_(html=True) + "\n$$\n\\begin{aligned}\n"
            + " \\\\\n".join(rows) + "\n\\end{aligned}\n$$")


def _latex_matrix(M):
    fmt = ct.config.defaults['statesp.latex_num_format']
    body = r" \\ ".join(" & ".join(format(float(x), fmt) for x in row) for row in M)
    return r"\begin{bmatrix}" + body + r"\end{bmatrix}"
