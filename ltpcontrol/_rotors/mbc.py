"""Multi-blade (Coleman) coordinates.

Blade b = 1..N sits at the azimuth ``ψ_b = ψ + 2π(b-1)/N``.  A blade
quantity ``q_b`` is written in multi-blade coordinates z as ``q = T(ψ) z``
with the columns of T

    1 (collective),  cos kψ_b, sin kψ_b  (cyclic, k = 1..⌊(N-1)/2⌋),
    (-1)^(b-1)  (differential, or reactionless, for even N),

orthogonal, ``T⁻¹ = diag(1/N, 2/N, ..., 2/N, 1/N) Tᵀ``.  With the rotor
speed ``Ω = ψ̇``, a first-order blade state transforms as ``x = T z``; a
second-order degree of freedom with displacement q and rate q̇ as

    q = T z,    q̇ = T ż + Ω T' z,

(``T' = dT/dψ``), so the full state is ``x = 𝒯(t) ξ`` and

    A_NR = 𝒯⁻¹ (A 𝒯 - 𝒯̇),   B_NR = 𝒯⁻¹ B T_u,   C_NR = T_y⁻¹ C 𝒯,   D_NR = T_y⁻¹ D T_u,

with ``𝒯̇`` holding ``Ω T'`` and ``Ω² T'' + Ω̇ T'`` (Bir 2008; Hansen 2003).
"""

import numbers
import warnings

import numpy as np
from control.exception import ControlArgument, ControlDimension

from .._core.periodic_matrix import PeriodicMatrix
from .._core.coerce import as_ltp
from .._core.validation import check_positive_int
from .blade_groups import blade_key, check_groups, infer_blade_groups
from .rotor_model import RotorStateSpace, sampled_matrix

__all__ = ['mbc', 'coleman_matrix']


def coleman_matrix(azimuth, nblades, derivative=0):
    """Multi-blade transformation ``T(ψ)`` (or its ψ-derivative) for N blades.

    Parameters
    ----------
    azimuth : float
        Azimuth ψ of blade 1 (rad).
    nblades : int
        Number N >= 1 of blades.
    derivative : {0, 1, 2}
        0 for T, 1 for ``dT/dψ``, 2 for ``d²T/dψ²``.

    Returns
    -------
    ndarray, shape (N, N)
        Rows: blades; columns: collective, then ``cos kψ_b, sin kψ_b`` for
        k = 1, 2, ..., then the differential coordinate ``(-1)^(b-1)`` for
        even N.

    Examples
    --------
    >>> T = ltp.coleman_matrix(0.3, 3)
    >>> bool(np.allclose(np.linalg.inv(T), np.diag([1, 2, 2]) / 3 @ T.T))
    True
    >>> ltp.coleman_matrix(0.0, 4)[:, 3]
    array([ 1., -1.,  1., -1.])
    """
    N = check_positive_int(nblades, 'nblades')
    if derivative not in (0, 1, 2):
        raise ValueError(f"derivative must be 0, 1 or 2, got {derivative!r}")
    psi = float(azimuth) + 2 * np.pi * np.arange(N) / N
    cols = [np.ones(N) if derivative == 0 else np.zeros(N)]
    for k in range(1, (N - 1) // 2 + 1):
        c, s = np.cos(k * psi), np.sin(k * psi)
        # d/dψ (cos, sin) = k (-sin, cos);  d²/dψ² = -k² (cos, sin)
        cols += [[c, -k * s, -k * k * c][derivative], [s, k * c, -k * k * s][derivative]]
    if N % 2 == 0:
        alt = (-1.0) ** np.arange(N)
        cols.append(alt if derivative == 0 else np.zeros(N))
    return np.column_stack(cols)


def _coleman_weights(N):
    """``diag(T⁻¹ T⁻ᵀ)⁻¹``-type weights: ``T⁻¹ = diag(w) Tᵀ``."""
    w = np.full(N, 2.0 / N)
    w[0] = 1.0 / N
    if N % 2 == 0:
        w[-1] = 1.0 / N
    return w


def mbc(sys, rotating=None, nblades=3, *, rates=None, rotating_inputs=None,
        rotating_outputs=None, rotor_speed=None, azimuth0=None, inverse=False, name=None):
    """Transform a rotor model to (or from) multi-blade coordinates.

    Parameters
    ----------
    sys : LTPStateSpace
        Model in the rotating frame (``inverse=False``) or in multi-blade
        coordinates (``inverse=True``); its time axis is the rotor's (blade-1
        azimuth ``ψ(t) = ψ_0 + ∫Ω``).  A `RotorStateSpace` supplies its rotor
        speed, azimuth and samples.
    rotating : sequence of sequences or int, optional
        Groups of blade states: each group lists the N states (indices or
        labels) of one blade degree of freedom, blade 1 first.  Default
        (a `RotorStateSpace`): inferred from the descriptions and
        rotating-frame flags, for ElastoDyn, BeamDyn, AeroDyn and ServoDyn
        states in any module order.  An integer is taken as `nblades`
        (``mbc(lin, 3)``).  Groups given for a model with descriptions are
        checked against them (blades 1..N in order, each rate the
        derivative of its displacement).  For a
        second-order degree of freedom, the group of displacements.  In
        multi-blade coordinates, group member j is coordinate j (collective,
        cosine, sine, ..., differential).
    nblades : int
        Number N >= 2 of blades; every group must have N members.
    rates : sequence, optional
        Same length as `rotating`: ``rates[i]`` is the group of the time
        derivatives of the displacements ``rotating[i]`` (second-order
        degree of freedom), or None for a first-order group.  Default: all
        groups first-order.
    rotating_inputs, rotating_outputs : sequence of sequences, optional
        Groups of blade inputs and outputs, transformed with ``T(ψ)``.
    rotor_speed : float, PeriodicMatrix or callable, optional
        Ω in rad/s: a constant (0 for a parked rotor: a constant
        transform at `azimuth0`), or a T-periodic 1x1 matrix (Fourier form,
        or a smooth callable) whose mean is a multiple of ``2π/T``.
        Default: that of a `RotorStateSpace`, otherwise ``2π/T`` (one
        revolution per period).
    azimuth0 : float, optional
        Blade-1 azimuth at t = 0 (default: that of a `RotorStateSpace`,
        otherwise 0).
    inverse : bool, optional
        Transform from multi-blade coordinates back to the rotating frame.
    name : str, optional
        Name of the result.

    Returns
    -------
    sysT : RotorStateSpace
        The transformed model (time-invariant, to rounding, for an
        isotropic rotor at constant speed).  Its samples, when `sys` has
        some, are the transformed samples.
    T : PeriodicMatrix
        The state transformation ``x_rotating = T(t) x_multiblade``.

    Raises
    ------
    ValueError
        If a group does not have `nblades` members, a state is in two
        groups, the rotor speed is not commensurate with the period, the
        groups contradict the descriptions (blade order, rates), the model
        has no rotating states, or it is in multi-blade coordinates already
        (``inverse=False``).

    Examples
    --------
    Three uncoupled blades with a lag spring in the rotating frame are
    three copies of one LTI system; in multi-blade coordinates the cyclic
    pair sees the rotation:

    >>> Ab = np.array([[0.0, 1.0], [-4.0, -0.2]])
    >>> A = np.kron(Ab, np.eye(3))            # states q1 q2 q3 q1' q2' q3'
    >>> sys = ltp.ltpss(A, np.zeros((6, 0)), np.zeros((0, 6)), 0, period=2 * np.pi)
    >>> nr, T = ltp.mbc(sys, [[0, 1, 2]], 3, rates=[[3, 4, 5]])
    >>> bool(nr.A.is_constant or np.allclose(nr.A(0.3), nr.A(1.1)))
    True
    >>> ev = np.sort_complex(np.linalg.eigvals(nr.A(0.0)))
    >>> bool(np.allclose(np.sort(np.abs(ev.imag)).max(),
    ...                  np.abs(np.linalg.eigvals(Ab)).max() + 1.0, atol=0.01))
    True
    """
    sys = as_ltp(sys)
    if isinstance(rotating, numbers.Integral) and not isinstance(rotating, bool):
        # mbc(sys, 3): the blade count in second place (MBC3's habit)
        nblades, rotating = rotating, None
    N = check_positive_int(nblades, 'nblades', minimum=2)
    n, m, p = sys.nstates, sys.ninputs, sys.noutputs
    T = sys.period
    rotor = isinstance(sys, RotorStateSpace)
    if rotor and sys.frame == 'multiblade' and not inverse:
        raise ValueError(f"{sys.name} is already in multi-blade coordinates (frame "
                         "'multiblade'): transform it back with inverse=True, or pass the "
                         "rotating-frame model")
    if rotor and sys.frame == 'rotating' and inverse and sys.nblades is not None:
        raise ValueError(f"{sys.name} is in the rotating frame already: inverse=True "
                         "transforms a multi-blade model back")
    if rotating is None:
        if not rotor:
            raise ControlArgument("rotating is needed unless sys is a RotorStateSpace with "
                                  "rotating-frame flags (e.g. from read_lin)")
        if rates is not None or rotating_inputs is not None or rotating_outputs is not None:
            raise ControlArgument("rates, rotating_inputs and rotating_outputs are inferred "
                                  "with the groups: give rotating too")
        rotating, rates, rotating_inputs, rotating_outputs = _infer_groups(sys, N)
    groups = _groups(rotating, N, sys.state_labels, 'rotating')
    if rates is None:
        rates = [None] * len(groups)
    elif len(rates) != len(groups):
        raise ValueError(f"rates must have one entry per group of rotating ({len(groups)}), "
                         f"got {len(rates)}")
    rate_groups = [None if r is None else _groups([r], N, sys.state_labels, 'rates')[0]
                   for r in rates]
    used = [i for g in groups for i in g] + [i for g in rate_groups if g is not None for i in g]
    if len(set(used)) != len(used):
        raise ValueError("rotating and rates must name every state at most once")
    in_groups = _groups(rotating_inputs or [], N, sys.input_labels, 'rotating_inputs')
    out_groups = _groups(rotating_outputs or [], N, sys.output_labels, 'rotating_outputs')
    if not groups and not in_groups and not out_groups:
        raise ValueError(f"{sys.name} has no rotating states, inputs or outputs (none is "
                         "flagged in the rotating frame, or rotating is empty): there is "
                         "nothing to transform to multi-blade coordinates")
    if rotor:
        # the groups must agree with the descriptions: blades 1..N in order, rates of
        # their own displacements
        check_groups(groups, rate_groups, sys.state_descriptions, 'rotating')
        check_groups(in_groups, [None] * len(in_groups), sys.input_descriptions,
                     'rotating_inputs')
        check_groups(out_groups, [None] * len(out_groups), sys.output_descriptions,
                     'rotating_outputs')
    psi0 = float(azimuth0 if azimuth0 is not None else
                 (sys.azimuth0 if rotor else 0.0))
    rotor_given = rotor_speed
    if rotor_speed is None:
        rotor_speed = sys.rotor_speed if rotor else 2 * np.pi / T
    speed = _speed(rotor_speed, T)

    w = _coleman_weights(N)
    # index blocks of every group, built once: (g, g), and for rates (r, r), (r, g)
    blocks = [(np.ix_(g, g), None if r is None else (np.ix_(r, r), np.ix_(r, g)))
              for g, r in zip(groups, rate_groups)]
    in_blocks, out_blocks = [np.ix_(g, g) for g in in_groups], [np.ix_(g, g) for g in out_groups]

    def state_transform(omega, domega, psi):
        """𝒯, 𝒯⁻¹ and 𝒯̇ at one instant (T⁻¹ = diag(w) Tᵀ)."""
        P, Pinv, dP = np.eye(n), np.eye(n), np.zeros((n, n))
        T0 = coleman_matrix(psi, N)
        T0inv = w[:, None] * T0.T
        T1, T2 = coleman_matrix(psi, N, 1), coleman_matrix(psi, N, 2)
        # [[T, 0], [Ω T', T]]⁻¹ = [[T⁻¹, 0], [-Ω T⁻¹ T' T⁻¹, T⁻¹]]
        lower, lower_inv = omega * T1, -omega * T0inv @ T1 @ T0inv
        second = omega ** 2 * T2 + domega * T1
        for gg, rates_ in blocks:
            P[gg], Pinv[gg], dP[gg] = T0, T0inv, lower
            if rates_ is not None:
                rr, rg = rates_
                P[rr], Pinv[rr], dP[rr] = T0, T0inv, lower
                P[rg], Pinv[rg], dP[rg] = lower, lower_inv, second
        return P, Pinv, dP

    def signal_transform(size, sblocks, psi):
        P, Pinv = np.eye(size), np.eye(size)
        if sblocks:
            T0 = coleman_matrix(psi, N)
            T0inv = w[:, None] * T0.T
            for gg in sblocks:
                P[gg], Pinv[gg] = T0, T0inv
        return P, Pinv

    def transformed(t, mats, which=(0, 1, 2, 3), at_speed=None):
        """The transformed matrices `which` (0: A, 1: B, 2: C, 3: D) at time t."""
        omega, domega, psi = speed(t, psi0)
        if at_speed is not None:
            omega, domega = at_speed
        P, Pinv, dP = state_transform(omega, domega, psi)
        (Pu, Puinv), (Py, Pyinv) = signal_transform(m, in_blocks, psi), \
            signal_transform(p, out_blocks, psi)
        if inverse:
            # z = 𝒯⁻¹ x: the forward formulas with 𝒯⁻¹, d(𝒯⁻¹)/dt = -𝒯⁻¹ 𝒯̇ 𝒯⁻¹
            P, Pinv, dP = Pinv, P, -Pinv @ dP @ Pinv
            Pu, Puinv, Py, Pyinv = Puinv, Pu, Pyinv, Py
        out = []
        for j in which:
            M = mats[j](t) if callable(mats[j]) else mats[j]
            if j == 0:
                out.append(Pinv @ (M @ P - dP))
            elif j == 1:
                out.append(Pinv @ M @ Pu)
            elif j == 2:
                out.append(Pyinv @ M @ P)
            else:
                out.append(Pyinv @ M @ Pu)
        return out

    def matrix(index, shape):
        def f(t):
            return transformed(float(t), (sys.A, sys.B, sys.C, sys.D), (index,))[0]
        return PeriodicMatrix.from_function(f, T, shape, check=False)

    data = sys.rotor_data() if rotor else {}
    interpolation = data.get('interpolation', 'fourier')
    if interpolation is None:
        mats = None
    else:
        mats = [matrix(0, (n, n)), matrix(1, (n, m)), matrix(2, (p, n)), matrix(3, (p, m))]
        # a rotor model whose transform is exactly constant keeps constant matrices
        # (at 33 irregular instants: a trigonometric polynomial of degree <= 16
        # that takes one value at all of them is constant)
        probe = T * np.mod(0.1234 + 0.6180339887 * np.arange(33), 1.0)
        at_probe = [transformed(t, (sys.A, sys.B, sys.C, sys.D)) for t in probe]
        for j, M in enumerate(mats):
            vals = np.array([out[j] for out in at_probe])
            if np.all(np.abs(vals - vals[0]) <= 1e-13 * max(1.0, np.abs(vals).max(initial=0.0))):
                mats[j] = PeriodicMatrix.constant(vals[0], T)
    samples = None
    if rotor and sys.samples is not None:
        omega = sys.rotor_speed
        times = np.mod((np.asarray(sys.azimuths) - psi0) / omega, T) if omega else \
            np.zeros(len(sys.azimuths))
        samples = [[], [], [], []]
        # the samples' own Ω and Ω̇ (operating point), as MBC3 takes them
        own = getattr(sys, 'sample_speeds', None)
        acc = getattr(sys, 'sample_accelerations', None)
        use_own = rotor_given is None and own is not None and acc is not None and \
            len(own) == len(times) and sys.rotor_speed > 0
        for s, t in enumerate(times):
            out = transformed(t, [M[s] for M in sys.samples],
                              at_speed=(own[s], acc[s]) if use_own else None)
            for j in range(4):
                samples[j].append(out[j])
        samples = tuple(np.array(M).reshape((len(times),) + sys.samples[j].shape[1:])
                        for j, M in enumerate(samples))
        if mats is None:
            mats = [sampled_matrix(M, sys.azimuths, psi0, T, None, nm)
                    for M, nm in zip(samples, 'ABCD')]
    P = PeriodicMatrix.from_function(
        lambda t: state_transform(*speed(float(t), psi0))[0], T, (n, n), check=False)
    if inverse:
        Pf = P
        P = PeriodicMatrix.from_function(lambda t: np.linalg.inv(Pf(t)), T, (n, n),
                                         check=False)
    data.update(rotor_speed=_speed_mean(rotor_speed, T), azimuth0=psi0,
                samples=samples, nblades=N, frame='rotating' if inverse else 'multiblade')
    if samples is None:
        data['azimuths'] = data.get('azimuths') if rotor and sys.samples is not None else None
    suffix = '$rotating' if inverse else '$mbc'
    out = RotorStateSpace(*mats, T, rotor=data, name=name or sys.name + suffix,
                          inputs=sys.input_labels, outputs=sys.output_labels,
                          states=_state_names(sys.state_labels, groups, rate_groups, N,
                                              inverse))
    return out, P


def _speed_mean(rotor_speed, T):
    """Mean rotor speed of a constant or periodic speed."""
    if isinstance(rotor_speed, (numbers.Real, np.number)):
        return float(rotor_speed)
    c, K = _speed_series(rotor_speed, T)
    return float(c[K].real)


def _speed_series(rotor_speed, T):
    Om = rotor_speed if isinstance(rotor_speed, PeriodicMatrix) else \
        PeriodicMatrix.from_function(lambda t: np.atleast_2d(rotor_speed(t)), T, (1, 1))
    if Om.shape != (1, 1):
        raise ControlDimension(f"rotor_speed must be 1x1, got shape {Om.shape}")
    K = Om.nharmonics if Om.nharmonics is not None else 32
    return Om.with_period(T).fourier(K)[:, 0, 0], K


def _speed(rotor_speed, T):
    """``(Ω(t), Ω̇(t), ψ(t) - ψ_0)`` as a function of t and ψ_0."""
    wp = 2 * np.pi / T
    if isinstance(rotor_speed, (numbers.Real, np.number)) and not isinstance(rotor_speed, bool):
        Om = float(rotor_speed)
        if Om == 0:
            # a parked rotor: the transform is constant, at the azimuth ψ_0
            return lambda t, psi0: (0.0, 0.0, psi0)
        if not Om > 0:
            raise ValueError(f"rotor_speed must be positive (or 0 for a parked rotor), "
                             f"got {rotor_speed!r}")
        _check_revolutions(Om, T)
        return lambda t, psi0: (Om, 0.0, psi0 + Om * t)
    if not (isinstance(rotor_speed, PeriodicMatrix) or callable(rotor_speed)):
        raise ControlArgument("rotor_speed must be a number, a PeriodicMatrix or a callable, "
                              f"got {type(rotor_speed).__name__}")
    c, K = _speed_series(rotor_speed, T)
    mean = c[K].real
    _check_revolutions(mean, T)
    ks = np.arange(-K, K + 1)
    nz = ks != 0

    def at(t, psi0):
        e = np.exp(1j * ks * wp * t)
        om = float(np.real(c @ e))
        dom = float(np.real((1j * ks * wp * c) @ e))
        # ψ = ψ_0 + Ω_0 t + Σ_{k≠0} Ω_k (e^{jkω t} - 1)/(jkω)
        psi = psi0 + mean * t + float(np.real(np.sum(c[nz] * (e[nz] - 1) / (1j * ks[nz] * wp))))
        return om, dom, psi
    return at


def _check_revolutions(mean, T):
    revs = mean * T / (2 * np.pi)
    if not revs > 0.5 or abs(revs - round(revs)) > 1e-9 * max(1.0, revs):
        raise ValueError(f"the rotor turns {revs:.6g} revolutions per period: the mean rotor "
                         "speed must be a positive multiple of 2π/period")


def _infer_groups(sys, N):
    """Blade groups from a rotor model's flags and descriptions (any module order)."""
    flags, order = np.asarray(sys.rotating_states, bool), np.asarray(sys.derivative_order)
    desc = sys.state_descriptions
    if np.any(flags & (order == 0)):
        raise ValueError("the derivative order of rotating states is unknown (e.g. "
                         f"{desc[int(np.flatnonzero(flags & (order == 0))[0])]!r}): give "
                         "rotating (and rates) explicitly")
    groups, rates, left = infer_blade_groups(desc, flags, order, N, 'states')
    if left:
        # descriptions without a common pattern: OpenFAST's order of the states
        try:
            groups, rates = _positional_groups(flags, order, desc, N)
        except ValueError as exc:
            raise ValueError(f"{len(left)} rotating states form no group of nblades = {N} "
                             f"blades by their descriptions ({[desc[i] for i in left][:6]}) "
                             f"nor by their order ({exc}); give rotating (and rates) "
                             "explicitly") from None
    ins = _signal_groups(sys.rotating_inputs, sys.input_descriptions, N, 'inputs')
    outs = _signal_groups(sys.rotating_outputs, sys.output_descriptions, N, 'outputs')
    return groups, rates, ins, outs


def _positional_groups(flags, order, desc, N):
    """Consecutive blade groups in OpenFAST's state order (displacements, rates, first order)."""
    n2 = int(np.count_nonzero(order == 2))
    if n2 % 2 or not np.all(order[:n2] == 2):
        raise ValueError("the second-order states do not come first, displacements then "
                         "rates")
    half = n2 // 2
    if np.any(flags[:half] != flags[half:n2]):
        raise ValueError("the rotating-frame flags of the displacements and of their rates "
                         "differ")

    def consecutive(indices, what):
        if len(indices) % N:
            raise ValueError(f"{len(indices)} rotating {what} cannot be split into groups of "
                             f"nblades = {N}: wrong blade count")
        groups = [[int(i) for i in indices[k:k + N]] for k in range(0, len(indices), N)]
        for g in groups:
            blades = [blade_key(desc[i], loose=False)[1] for i in g]
            if all(b is not None for b in blades) and blades != list(range(1, N + 1)):
                raise ValueError(f"rotating {what} {[desc[i] for i in g]} describe blades "
                                 f"{blades}, not 1..{N}: wrong blade count or order")
        return groups

    disp = consecutive(np.flatnonzero(flags[:half]), 'displacements')
    first = consecutive(n2 + np.flatnonzero(flags[n2:]), 'first-order states')
    return disp + first, [[i + half for i in g] for g in disp] + [None] * len(first)


def _signal_groups(flags, descriptions, N, what):
    """Blade groups of rotating inputs or outputs, matched by their descriptions.

    Flagged items that form no complete group stay in the rotating frame,
    with a warning naming them.
    """
    groups, _, left = infer_blade_groups(descriptions, flags, None, N, what)
    if left:
        warnings.warn(f"{len(left)} rotating {what} form no group of {N} blades "
                      f"({[descriptions[i] for i in left][:4]}); they are left in the "
                      "rotating frame", UserWarning, stacklevel=4)
    return groups


def _groups(spec, N, labels, what):
    """Groups of indices, each of N members."""
    out = []
    try:
        items = list(spec)
    except TypeError:
        raise ControlArgument(f"{what} must be a sequence of groups of {N} members") from None
    for g in items:
        if isinstance(g, (str, numbers.Integral)):
            raise ControlArgument(f"{what} must be a sequence of groups (one per degree of "
                                  f"freedom, each of {N} members), got {spec!r}")
        idx = []
        for item in g:
            if isinstance(item, str):
                if item not in labels:
                    raise ValueError(f"{what}: unknown label {item!r}")
                idx.append(labels.index(item))
            elif isinstance(item, numbers.Integral) and not isinstance(item, bool):
                if not 0 <= item < len(labels):
                    raise ValueError(f"{what}: index {item} out of range 0..{len(labels) - 1}")
                idx.append(int(item))
            else:
                raise ControlArgument(f"{what}: members must be indices or labels, got "
                                      f"{item!r}")
        if len(idx) != N:
            raise ValueError(f"{what}: every group must have nblades = {N} members, got "
                             f"{len(idx)} in {list(g)!r}")
        if len(set(idx)) != N:
            raise ValueError(f"{what}: a group names the same member twice: {list(g)!r}")
        out.append(idx)
    flat = [i for g in out for i in g]
    if len(set(flat)) != len(flat):
        raise ValueError(f"{what}: a member belongs to two groups")
    return out


def _state_names(labels, groups, rate_groups, N, inverse):
    names = list(labels)
    if inverse:
        return names
    coords = ['0'] + [f'{cs}{k}' for k in range(1, (N - 1) // 2 + 1) for cs in 'cs'] + \
        (['d'] if N % 2 == 0 else [])
    for g, r in zip(groups, rate_groups):
        for grp in (g, r) if r is not None else (g,):
            base = labels[grp[0]]
            for j, i in enumerate(grp):
                names[i] = f'{base}_{coords[j]}'
    return names
