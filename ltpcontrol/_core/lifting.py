"""Lifting of discrete-time LTP systems to LTI systems.

Frequency lifting (thesis Section 4.2.4, corrected as in items 1-2 of the
"Notes on the thesis" page).  With the
DT Fourier coefficients ``M_l = (1/N) Σ_k M[k] w^{-lk}``, ``w = e^{j2π/N}``,
and harmonics n (ascending), the harmonic balance of ``x[k+1] = A[k]x[k] +
B[k]u[k]`` for ``u[k] = z^k Σ_m U_m w^{mk}`` gives

    z w^n X_n = Σ_m A_{(n-m) mod N} X_m + Σ_m B_{(n-m) mod N} U_m,
    Y_n = Σ_m C_{(n-m) mod N} X_m + Σ_m D_{(n-m) mod N} U_m,

so ``z 𝒳 = Λ^{-1} 𝒜 𝒳 + Λ^{-1} ℬ 𝒰``, ``𝒴 = 𝒞 𝒳 + 𝒟 𝒰`` with block-circulant
Toeplitz matrices and ``Λ = blkdiag(w^n I)`` (eqs. 4.69-4.73), whose
transfer function is the DT HTF ``H(z) = 𝒞 (zΛ - 𝒜)^{-1} ℬ + 𝒟``.

Real form (thesis Section 4.2.5, notes items 3-4): the unitary ``V`` with
block columns ``c_0 = e_0``, ``c_n = (e_n + e_{-n})/√2``, ``s_n = j(e_n -
e_{-n})/√2`` (and ``c_{N/2} = e_{N/2}`` for the self-conjugate Nyquist
harmonic of even N) pairs ``X_{-n}`` with ``X_n`` as the exchange corners of
eq. (4.74) do; ``V^H (.) V`` of every lifted matrix is real.  Per pair, the
thesis's ``T_u`` is ``diag(1/√2, -√2) V^H``; the unitary scaling keeps norms
and singular values.

Time lifting (Meyer-Burrus): ``x_L[p] = x[pN]``, ``u_L[p] = [u[pN]; ...;
u[pN+N-1]]`` and likewise ``y_L``.
"""

import numpy as np
import control as ct
from control.exception import ControlArgument

from .coerce import as_ltp
from .validation import check_positive_int
from .tvsystem import DiscreteLTPSystem
from .lifting_forms import lift_form

__all__ = ['lift']


def lift(sysd, *, method='frequency', real=True, nharmonics=None, name=None, start=0,
         sparse=False):
    """Lift a discrete-time LTP system to an equivalent LTI system.

    Parameters
    ----------
    sysd : LTPStateSpace
        Discrete-time LTP system with period N steps.
    method : {'frequency', 'time', 'stacked', 'cyclic'}
        'frequency' (default): harmonic (frequency-domain) lifting, thesis
        eqs. (4.65)-(4.76); the result runs at the sampling time of `sysd`
        and maps the modulated Fourier coefficients ``U_m`` of the input to
        those of the output (module notes).  'time': Meyer-Burrus (standard)
        lifting; the result runs once per period (``dt = period``) and maps
        the N stacked input samples of a period to the N stacked output
        samples.  'stacked': the Grasselli-Longhi descriptor form, the
        tuple ``(A, E, B, C, D)`` of ``E z[p+1] = A z[p] + B U[p]`` with the
        states of a period stacked; 'cyclic': Flamm's cyclic form, an LTI
        system at the base rate whose state holds ``x[k]`` in block
        ``k mod N`` (see `unlift` for both).  A
        `DiscreteLTPSystem` (dimensions varying with k) takes the three
        time-domain forms.
    real : bool
        Frequency lifting only.  True (default): return the real-valued
        form ``V^H (.) V`` as a `control.StateSpace`.  False: return the
        complex matrices.  Ignored by 'time' (always real).
    nharmonics : int, optional
        Frequency lifting only: keep the harmonics -K..K (``2K+1 <= N``,
        thesis Remark 8).  By default all N harmonics are kept: -N/2..N/2-1
        for even N and -(N-1)/2..(N-1)/2 for odd N; the model is then exact.
        A truncated model neglects the coupling with the dropped harmonics.
    name : str, optional
        Name of the result (default: the name of `sysd` with '$lifted').
    start : int, optional
        Step ``k0`` in 0..N-1 at which the lifted periods begin: the result
        lifts the shifted system ``A[k0 + k], B[k0 + k], ...`` (time
        lifting: ``x_L[p] = x[pN + k0]``).  Default 0.
    sparse : bool, optional
        'stacked' and 'cyclic' only: return scipy.sparse matrices (long
        periods).

    Returns
    -------
    control.StateSpace
        With ``real=True`` or ``method='time'``.  Frequency lifting: state,
        input and output vectors ordered harmonic-major, signal names
        ``'<label>_c<n>'`` (cosine part, real coordinate of ``c_n``) and
        ``'<label>_s<n>'`` (sine part); its frequency response at ``z`` is
        ``V_y^H H(z) V_u``.  Time lifting: names ``'<label>@<k>'`` for step
        k of the period.
    A, B, C, D : ndarray of complex
        With ``real=False``: the matrices of ``z 𝒳 = A 𝒳 + B 𝒰, 𝒴 = C 𝒳 +
        D 𝒰`` in the harmonic order given above, so ``H(z) = C (zI -
        A)^{-1} B + D`` is the DT HTF (block (n, m) for the n-th output and
        m-th input harmonic).

    Raises
    ------
    ValueError
        If `sysd` is continuous-time, `method` is unknown, `nharmonics` is
        too large or is given with method 'time'.
    ControlArgument
        If `sysd` is not an `LTPStateSpace` or `real` is not a bool.
    TypeError
        For unknown keyword arguments.

    Notes
    -----
    For odd N every harmonic but 0 has a conjugate partner and the real
    form has the same size as the complex one; for even N the Nyquist
    harmonic N/2 (= -N/2) is self-conjugate and forms one real coordinate
    of its own (:ref:`thesis-notes`, item 4), so no extra ``U_{N/2}`` row is
    added.  The lifting is the one of [Uyanik2019]_ (thesis Section 4.2.4),
    with the corrections of items 1-3 of that page.

    Examples
    --------
    >>> B = np.array([[[1.0]], [[0.5]], [[0.0]], [[0.5]]])     # N = 4
    >>> sysd = ltp.ltpss([[0.5]], B, [[1.0]], 0, period=1.0, dt=0.25, name='p')
    >>> L = ltp.lift(sysd)
    >>> L.nstates, L.dt, L.input_labels
    (4, 0.25, ['u[0]_c0', 'u[0]_c1', 'u[0]_s1', 'u[0]_c2'])
    >>> Lt = ltp.lift(sysd, method='time')
    >>> Lt.shape, Lt.dt
    ((4, 4), 1.0)
    >>> ltp.lift(sysd, method='time', start=1).B[0, 0]     # Φ(5, 2) B[1]
    np.float64(0.0625)
    """
    if method in ('stacked', 'cyclic') or isinstance(sysd, DiscreteLTPSystem):
        return lift_form(sysd, method, start=start, sparse=sparse, name=name,
                         nharmonics=nharmonics)
    sysd = as_ltp(sysd, 'sysd', discrete=True)
    if method not in ('frequency', 'time'):
        raise ValueError("method must be 'frequency', 'time', 'stacked' or 'cyclic', "
                         f"got {method!r}")
    if sparse:
        raise ValueError("sparse applies to the 'stacked' and 'cyclic' forms only")
    if not isinstance(real, (bool, np.bool_)):
        raise ControlArgument(f"real must be True or False, got {real!r}")
    N = sysd.nsteps
    start = check_positive_int(start, 'start', minimum=0)
    if start >= N:
        raise ValueError(f"start={start} must be a step of the period, 0..{N - 1}")
    if name is None:
        name = sysd.name + '$lifted'
    samples = [np.roll(M.sample(N), -start, axis=0) for M in (sysd.A, sysd.B, sysd.C, sysd.D)]
    if method == 'time':
        if nharmonics is not None:
            raise ValueError("nharmonics only applies to method='frequency'")
        mats = _time_lift(*samples)
        return ct.ss(*mats, sysd.period, name=name,
                     inputs=_step_labels(sysd.input_labels, N),
                     outputs=_step_labels(sysd.output_labels, N),
                     states=list(sysd.state_labels))
    harmonics = _harmonics(N, nharmonics)
    consts = [M.is_constant for M in (sysd.A, sysd.B, sysd.C, sysd.D)]
    A, B, C, D = _frequency_lift(samples, harmonics, consts)
    if not real:
        return A, B, C, D
    V, tags = _real_basis(harmonics, N)
    Vx, Vu, Vy = (np.kron(V, np.eye(k)) for k in
                  (sysd.nstates, sysd.ninputs, sysd.noutputs))
    Ar = (Vx.conj().T @ A @ Vx).real
    Br = (Vx.conj().T @ B @ Vu).real
    Cr = (Vy.conj().T @ C @ Vx).real
    Dr = (Vy.conj().T @ D @ Vu).real
    return ct.ss(Ar, Br, Cr, Dr, sysd.dt, name=name,
                 inputs=_harmonic_labels(sysd.input_labels, tags),
                 outputs=_harmonic_labels(sysd.output_labels, tags),
                 states=_harmonic_labels(sysd.state_labels, tags))


#
# Private helpers
#

def _frequency_lift(samples, harmonics, constant=(False,) * 4):
    """Complex matrices of the discrete harmonic state space (module notes).

    The one construction of ``z 𝒳 = Λ^{-1}𝒜 𝒳 + Λ^{-1}ℬ 𝒰``, ``𝒴 = 𝒞 𝒳 + 𝒟 𝒰``,
    shared by `lift` and the discrete-time `htf`.

    Parameters
    ----------
    samples : sequence of 4 ndarray, shapes (N, ., .)
        ``A[k], B[k], C[k], D[k]`` over one period of N steps.
    harmonics : ndarray of int
        Harmonic indices, ascending (`_full_harmonics` for the exact model).
    constant : sequence of 4 bool
        Which of the matrices are constant (block diagonal Toeplitz).

    Returns
    -------
    A, B, C, D : ndarray of complex
        ``Λ^{-1}𝒜, Λ^{-1}ℬ, 𝒞, 𝒟`` with ``Λ = blkdiag(w^n I)``.
    """
    N = samples[0].shape[0]
    A, B, C, D = (_toeplitz(S, harmonics, N, const) for S, const in zip(samples, constant))
    winv = np.repeat(np.exp(-2j * np.pi * harmonics / N), samples[0].shape[1])[:, np.newaxis]
    return winv * A, winv * B, C, D


def _full_harmonics(N):
    """All N harmonics, ascending: -N/2..N/2-1 (even N), -(N-1)/2..(N-1)/2 (odd N)."""
    return np.arange(-(N // 2), N - N // 2)


def _harmonics(N, nharmonics):
    """Harmonic indices kept by the frequency lifting, ascending."""
    if nharmonics is None:
        return _full_harmonics(N)
    K = check_positive_int(nharmonics, 'nharmonics', minimum=0)
    if 2 * K + 1 > N:
        raise ValueError(f"nharmonics={K} needs 2K+1 <= N = {N} distinct harmonics; "
                         "use nharmonics=None for the full lifting")
    return np.arange(-K, K + 1)


def _toeplitz(samples, harmonics, N, constant):
    """Block-circulant Toeplitz matrix with blocks ``M_{(n-m) mod N}``."""
    H = len(harmonics)
    rows, cols = samples.shape[1:]
    if constant:
        return np.kron(np.eye(H), samples[0]).astype(complex)
    F = np.fft.fft(samples, axis=0) / N          # M_l = (1/N) Σ_k M[k] w^{-lk}
    blocks = F[(harmonics[:, None] - harmonics[None, :]) % N]
    return blocks.transpose(0, 2, 1, 3).reshape(H * rows, H * cols)


def _real_basis(harmonics, N):
    """Unitary V (columns c_0, c_1, s_1, ...) and the tags of its columns."""
    pos = {int(n) % N: i for i, n in enumerate(harmonics)}
    V = np.zeros((len(harmonics), len(harmonics)), complex)
    tags, col = [], 0
    for n in range(int(np.abs(harmonics).max()) + 1):
        i, j = pos[n % N], pos[(-n) % N]
        if i == j:                           # n = 0 or the Nyquist harmonic N/2
            V[i, col] = 1.0
            tags.append(f'c{n}')
            col += 1
            continue
        V[[i, j], col] = 1 / np.sqrt(2)      # c_n = (e_n + e_{-n})/√2
        V[[i, j], col + 1] = 1j / np.sqrt(2), -1j / np.sqrt(2)   # s_n = j(e_n - e_{-n})/√2
        tags += [f'c{n}', f's{n}']
        col += 2
    return V, tags


def _time_lift(A, B, C, D):
    """Meyer-Burrus lifting over one period of ``x[k+1] = A[k]x[k] + B[k]u[k]``."""
    N, n, m = B.shape
    p = C.shape[1]
    CL = np.empty((N, p, n))
    DL = np.zeros((N, p, N, m))
    DL[np.arange(N), :, np.arange(N), :] = D
    Phi = np.eye(n)                  # Φ(k, 0)
    G = np.zeros((N, n, m))          # G[j] = Φ(k, j+1) B[j] for j < k
    for k in range(N):
        CL[k] = C[k] @ Phi
        # D_L(k, j) = C[k] Φ(k, j+1) B[j], j < k
        DL[k, :, :k, :] = np.einsum('ij,bjl->ibl', C[k], G[:k])
        Phi = A[k] @ Phi
        G[:k] = A[k] @ G[:k]
        G[k] = B[k]
    # A_L = Φ(N, 0),  B_L = [Φ(N, 1)B[0], ..., B[N-1]]
    BL = G.transpose(1, 0, 2).reshape(n, N * m)
    return Phi, BL, CL.reshape(N * p, n), DL.reshape(N * p, N * m)


def _harmonic_labels(labels, tags):
    return [f'{label}_{tag}' for tag in tags for label in labels]


def _step_labels(labels, N):
    return [f'{label}@{k}' for k in range(N) for label in labels]
