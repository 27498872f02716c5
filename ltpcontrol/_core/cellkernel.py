"""Compiled march over the cells of a phase table (optional: numba).

`cellmarch.cell_march` marches the states of a record over the cells of a
phase table with NumPy: every quantity of every cell is an array
operation over the record.  For a few states each cell needs about a
hundred multiplications, so the cost per sample is that of some eighty
array passes, not of the arithmetic.  With numba installed (the ``fast``
extra), long records of a few states take instead this scalar loop over
the cells of the record, compiled once per environment (cached on disk):

    for every cell c (phase j = c mod N) after the first sample's:
        z = (x(e_c), a_c, σ_c),   a_c = u_k + σ_k (e_c - t_k)   (k the last sample before c)
        if sample k lies in the cell (ξ = (t_k - e_c) / h_c):
            x(t_k) = Σ_d T_d(2ξ - 1) F_{j,d} z
            f      = Σ_d T_d(2ξ - 1) K_{j,d} kink_k
            y(t_k) = C(t_k) x(t_k) + D(t_k) u_k    (C, D Fourier series or constant)
        x(e_{c+1}) = Φ_j x(e_c) + [W_j Z_j] (a_c, σ_c) + f

with the coefficients of `cell_march` (F those of the first part's
[Φ W Z] in Chebyshev polynomials of ξ, K those of the kink's part).  The
arithmetic is that of the NumPy march, in another order: the two agree to
rounding.  `march_kernel` makes the loop for given sizes (constants of
the compiled code); without numba it runs as Python, used by the tests on
small records.

The kernel is used when ``ltp.config.defaults['timeresp.compiled']`` is
true (default), numba imports, the record has at least `MIN_SAMPLES`
samples and the system at most `MAX_STATES` states (above that the
NumPy march's matrix products are efficient).
"""

import importlib.util
import warnings

import numpy as np

__all__ = []

#: the compiled march is used for records of at least this many samples ...
MIN_SAMPLES = 20_000
#: ... of systems of at most this many states
MAX_STATES = 16

#: compiled loops by sizes; False once numba failed to import or compile
_COMPILED = {}


def compiled_kernel(n, m, q, D1, p, H=0):
    """The compiled loop for these sizes (`march_kernel`), or None without numba.

    The sizes are compile-time constants of the loop (its small loops
    unroll), so every combination is compiled once per environment and
    cached on disk.

    Examples
    --------
    >>> from ltpcontrol._core.cellkernel import compiled_kernel
    >>> kernel = compiled_kernel(2, 1, 2, 7, 1, 0)
    >>> kernel is None or callable(kernel)
    True
    """
    global _COMPILED
    if _COMPILED is False:
        return None
    sizes = (int(n), int(m), int(q), int(D1), int(p), int(H))
    if sizes not in _COMPILED:
        try:
            import numba
        except ImportError:
            _COMPILED = False
            return None
        # reassociated and fused sums (the sums over columns vectorise);
        # no checks for division by zero (steps are positive)
        _COMPILED[sizes] = _guarded(numba.njit(
            cache=True, nogil=True, error_model='numpy',
            fastmath={'reassoc', 'contract'})(march_kernel(*sizes)))
    return _COMPILED[sizes]


def available():
    """Whether the compiled loop can be used (numba imports and compiled so far).

    Examples
    --------
    >>> from ltpcontrol._core.cellkernel import available
    >>> isinstance(available(), bool)
    True
    """
    return _COMPILED is not False and importlib.util.find_spec('numba') is not None


def _guarded(kernel):
    """`kernel`, returning None (and every loop disabled, with a warning) if numba fails to compile it."""
    def call(*args):
        global _COMPILED
        try:
            return kernel(*args)
        except Exception as exc:            # numba could not compile the loop here
            _COMPILED = False
            warnings.warn(f"the compiled cell march is unavailable ({type(exc).__name__}: "
                          f"{exc}); simulating with NumPy", UserWarning, stacklevel=2)
            return None
    return call


def march_kernel(n, m, q, D1, p, H=0):
    """`march_cells` for n states, m inputs, q = m (zero-order hold) or 2m
    (first-order hold) forcing columns, D1 Chebyshev orders, p output rows
    (0: outputs not written) and output matrices of H harmonics, the sizes
    fixed (a closure), as Python.

    Examples
    --------
    One state, ẋ = u on two cells of one period (Φ = 1, W = h = 0.5), a
    constant input held: the state grows as t.

    >>> from ltpcontrol._core.cellkernel import march_kernel
    >>> march_cells = march_kernel(1, 1, 1, 2, 1, 0)
    >>> Phi, WZ = np.ones((2, 1, 1)), np.full((2, 1, 1), 0.5)
    >>> F = np.zeros((2, 2, 1, 2)); F[:, 0, 0, 0] = 1.0        # Φ_f = 1
    >>> F[:, 0, 0, 1], F[:, 1, 0, 1] = 0.25, 0.25             # W_f = ℓ = (1 + T_1) / 4
    >>> K = np.zeros((2, 2, 1, 1))
    >>> t = np.array([0.0, 0.8, 1.3])
    >>> x, y = np.zeros((1, 1, 3)), np.zeros((1, 1, 3))
    >>> Cs, Ds = np.full((2, 1, 1, 1), 2.0), np.zeros((2, 1, 1, 1))   # y = 2x
    >>> march_cells(Phi, WZ, F, K, np.array([0.0, 0.5, 1.0]), 1.0, 0.0, 0.0, 0.5,
    ...             np.array([0]), np.zeros(1), t, np.ones((1, 1, 3)), np.array([[0.5]]),
    ...             x, Cs, Ds, 2 * np.pi, y)
    True
    >>> x[0, 0], y[0, 0, 1:]                                  # (y at t[0] not written)
    (array([0. , 0.8, 1.3]), array([1.6, 2.6]))
    """
    nq = n + q
    foh = q == 2 * m

    def march_cells(Phi, WZ, F, K, edges, T, offset, base, w, g, xi, t, u, x1, x, Cs, Ds, omega,
                    y):
        """States `x` and outputs `y` at the samples from the cells' data (module notes).

        The input is held between samples: first order when ``WZ`` has 2m
        columns (slopes ``σ_k = (u_{k+1} - u_k) / (t_{k+1} - t_k)``, zero after
        the last sample; the kink at a sample is the change of slope), else
        zero order (the kink is the jump ``u_k - u_{k-1}``).

        Parameters
        ----------
        Phi : ndarray (N, n, n)
            Whole cells' transitions.
        WZ : ndarray (N, n, q)
            Whole cells' W (and Z, first-order hold: q = 2m).
        F : ndarray (N, D1, n, n + q)
            Chebyshev coefficients of the first parts' [Φ W (Z)].
        K : ndarray (N, D1, n, m)
            Chebyshev coefficients of the kink's part.
        edges : ndarray (N + 1,)
        T, offset, base : float
            Period, phase of the cells' origin, number of the period of t[0].
        w : float
            Width of equal cells: a sample's cell and fraction come from
            ``r = (t - offset) / w - base N`` (cell ⌊r⌋, ξ = r - ⌊r⌋); 0: from
            `g` and `xi`.
        g : int64 ndarray (L,)
            Cell of every sample (counted from the start of period `base`).
        xi : ndarray (L,)
            Fraction of its cell before every sample.
        t : ndarray (L,)
        u : ndarray (m, R, L)
        x1 : ndarray (n, R)
            State at the start of the cell after the first sample's.
        x : ndarray (n, R, L)
            States, written at samples 1 .. L-1 (sample 0 holds x0).
        Cs, Ds : ndarray (2, H + 1, p, n), (2, H + 1, p, m)
            Output matrices as real Fourier series: ``C(t) = Σ_h Cs[0, h]
            cos hωt + Cs[1, h] sin hωt`` (and D), h = 0..H.
        omega : float
            Their fundamental ω.
        y : ndarray (p, R, L)
            Outputs ``C(t) x + D(t) u`` at the samples 1 .. L-1 (p = 0: none).

        Returns
        -------
        bool
            False when two samples fall in one cell (`x` and `y` incomplete).
        """
        N, R, L = Phi.shape[0], u.shape[1], t.shape[0]
        Td, z = np.empty(D1), np.empty(nq)
        cs, sn = np.zeros(H + 1), np.zeros(H + 1)
        cs[0] = 1.0
        xc, fk = np.empty(n), np.empty(n)
        slope, kink = np.zeros(m), np.empty(m)
        shift = base * N
        inv_w = 1.0 / w if w > 0.0 else 0.0
        if w > 0.0:
            r0 = (t[0] - offset) / w - shift
            g0 = int(np.floor(r0))
        else:
            g0 = g[0]
        for r in range(R):
            for i in range(n):
                xc[i] = x1[i, r]
            if foh:
                for l in range(m):
                    slope[l] = (u[l, r, 1] - u[l, r, 0]) / (t[1] - t[0])
            c = g0 + 1                                       # the cell after sample 0's
            ph, period = c % N, c // N                       # c = period N + ph
            start = (base + period) * T + offset             # of the period
            for k in range(1, L):
                # the sample's cell and fraction
                if w > 0.0:
                    # (a product: a sample on an edge may land on either side,
                    # with ξ = 1 or 0, which are the same instant)
                    rk = (t[k] - offset) * inv_w - shift
                    gk = int(np.floor(rk))
                    xk = rk - gk
                else:
                    gk, xk = g[k], xi[k]
                if gk < c:
                    return False                             # two samples in one cell
                kp = k - 1
                while True:
                    # the held input at the cell's start, from the last sample k - 1
                    for i in range(n):
                        z[i] = xc[i]
                        fk[i] = 0.0
                    if foh:
                        tau = start + edges[ph]
                        for l in range(m):
                            z[n + l] = u[l, r, kp] + slope[l] * (tau - t[kp])
                            z[n + m + l] = slope[l]
                    else:
                        for l in range(m):
                            z[n + l] = u[l, r, kp]
                    if c == gk:
                        # the sample's cell: the state at the sample, Σ_d T_d (F_d z),
                        # and the kink's forcing, Σ_d T_d (K_d kink) (each order's
                        # products summed in registers), and the output
                        for l in range(m):
                            if foh:
                                new = (u[l, r, k + 1] - u[l, r, k]) / (t[k + 1] - t[k]) \
                                    if k + 1 < L else 0.0
                                kink[l] = new - slope[l]
                                slope[l] = new
                            else:
                                kink[l] = u[l, r, k] - u[l, r, kp]
                        s = 2.0 * xk - 1.0
                        Td[0] = 1.0
                        if D1 > 1:
                            Td[1] = s
                        for d in range(2, D1):
                            Td[d] = 2.0 * s * Td[d - 1] - Td[d - 2]
                        for i in range(n):
                            acc, acck = 0.0, 0.0
                            for d in range(D1):
                                sx = 0.0
                                for e in range(nq):
                                    sx += F[ph, d, i, e] * z[e]
                                sk = 0.0
                                for l in range(m):
                                    sk += K[ph, d, i, l] * kink[l]
                                acc += Td[d] * sx
                                acck += Td[d] * sk
                            x[i, r, k] = acc
                            fk[i] = acck
                        if p > 0:
                            # cos hωt, sin hωt by the recurrence of the multiple angles
                            if H > 0:
                                angle = omega * t[k]
                                cs[1], sn[1] = np.cos(angle), np.sin(angle)
                                for h in range(2, H + 1):
                                    cs[h] = 2.0 * cs[1] * cs[h - 1] - cs[h - 2]
                                    sn[h] = 2.0 * cs[1] * sn[h - 1] - sn[h - 2]
                            for o in range(p):
                                acc = 0.0
                                for h in range(H + 1):
                                    a0, a1 = 0.0, 0.0
                                    for i in range(n):
                                        a0 += Cs[0, h, o, i] * x[i, r, k]
                                        a1 += Cs[1, h, o, i] * x[i, r, k]
                                    for l in range(m):
                                        a0 += Ds[0, h, o, l] * u[l, r, k]
                                        a1 += Ds[1, h, o, l] * u[l, r, k]
                                    acc += cs[h] * a0 + sn[h] * a1
                                y[o, r, k] = acc
                    if k + 1 < L or c < gk:
                        # x(e_{c+1}) (not needed after the last sample)
                        for i in range(n):
                            acc = fk[i]
                            for e in range(n):
                                acc += Phi[ph, i, e] * z[e]
                            for l in range(q):
                                acc += WZ[ph, i, l] * z[n + l]
                            xc[i] = acc
                    c += 1
                    ph += 1
                    if ph == N:
                        ph, period = 0, period + 1
                        start = (base + period) * T + offset
                    if c > gk:
                        break
        return True

    return march_cells
