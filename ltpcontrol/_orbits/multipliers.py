"""Floquet multipliers of an orbit from the product form of its return map.

The Jacobian of the period (or return) map of a hybrid orbit is the product

    Φ = Φ_{K-1} ... S_j ... Φ_1 Φ_0

of transition matrices of short intervals (each restarted from the identity
before its condition number exceeds ``c``) and saltation matrices
of the events.  Its eigenvalues come from `product_eigenvalues` (QR sweeps
over the factors), so a multiplier of 1e-38 next to the phase multiplier 1
keeps its relative accuracy; formed as one matrix, it would be lost below
about 1e-16.

Error estimate.  Liouville's formula gives the product of all multipliers
independently of the factors' eigen-structure,

    Σ_i log|μ_i| = ∮ tr ∂f/∂x dt + Σ_j log|det S_j|,

with the trace integrated alongside the variational equations.  The
mismatch between both sides (the integration error of the factors in
volume), plus ``rtol |∮ tr ∂f/∂x dt|``, plus the estimated error of the QR
sweeps is reported as the estimated relative error of every multiplier.
Without the trace integral, the a-priori bound ``K c rtol`` (K factors,
each accurate to about ``c rtol`` relative to its smallest singular value)
replaces the first two terms.
"""

from dataclasses import dataclass

import numpy as np

from .._core.periodic_schur import product_eigenvalues

__all__ = []

#: singular values of a factor below this (relative) are zero
_RANK_TOL = 1e-13
#: multipliers this close to 1 are candidates for the phase multiplier
_PHASE_NEAR = 1e-3


@dataclass(frozen=True)
class OrbitMultipliers:
    """Multipliers of one return map, in product form (internal record).

    ``log_moduli`` and ``arguments`` are sorted by decreasing modulus;
    ``phase`` is the index of the phase multiplier (None for forced orbits).
    """

    log_moduli: np.ndarray
    arguments: np.ndarray
    phase: object
    error: float

    @property
    def values(self):
        """The multipliers (real dtype when all are real; 0 below 1e-308)."""
        return _as_values(self.log_moduli, self.arguments)

    @property
    def stability(self):
        """The multipliers that decide (orbital) stability."""
        keep = np.ones(len(self.log_moduli), bool)
        if self.phase is not None:
            keep[self.phase] = False
        return _as_values(self.log_moduli[keep], self.arguments[keep])

    @property
    def stability_log_moduli(self):
        keep = np.ones(len(self.log_moduli), bool)
        if self.phase is not None:
            keep[self.phase] = False
        return self.log_moduli[keep]


def _as_values(logmod, arg):
    with np.errstate(under='ignore', over='ignore', invalid='ignore'):
        real = (arg == 0) | (arg == np.pi)
        if np.all(real):
            return np.where(arg == 0, 1.0, -1.0) * np.exp(logmod)
        mu = np.exp(logmod) * np.exp(1j * arg)
        mu[real] = np.where(arg[real] == 0, 1.0, -1.0) * np.exp(logmod[real])
    return mu


def product_multipliers(factors, *, rtol, restart, trace_integral=None, saltations=(),
                        phase_direction=None, monodromy=None):
    """Multipliers of the product of `factors` with an error estimate.

    Parameters
    ----------
    factors : sequence of ndarray
        Transition and saltation matrices, first to last.
    rtol : float
        Relative tolerance of the integration of the transition factors.
    restart : float
        Bound ``c`` on the singular values of each transition factor.
    trace_integral : float, optional
        ``∮ tr ∂f/∂x dt`` over the period (Liouville check).
    saltations : sequence of ndarray
        The saltation matrices among the factors (Liouville check).
    phase_direction : ndarray, optional
        Autonomous orbits: the vector field at the start, eigenvector of the
        phase multiplier.
    monodromy : ndarray, optional
        The formed product, used only to tell the phase multiplier from
        other multipliers equal to 1 by its eigenvector.

    Returns
    -------
    OrbitMultipliers

    Examples
    --------
    Factors whose product has the eigenvalues 1 and 1e-200:

    >>> from ltpcontrol._orbits.multipliers import product_multipliers
    >>> F = [np.diag([1.0, 1e-5])] * 40
    >>> m = product_multipliers(F, rtol=1e-12, restart=1e5)
    >>> np.round(m.log_moduli / np.log(10), 12) + 0.0, m.values
    (array([   0., -200.]), array([1.e+000, 1.e-200]))
    """
    n = len(factors[0])
    if n == 0:
        return OrbitMultipliers(np.zeros(0), np.zeros(0), None, 0.0)
    # transition factors are well conditioned: a numerically singular factor
    # is a saltation matrix that removes dimensions (exact zero multipliers)
    logmod, arg, qr_error = product_eigenvalues(factors, error=True, rank_tol=_RANK_TOL)
    scale = 1 + np.abs(logmod[np.isfinite(logmod)]).max(initial=0.0)
    error = qr_error * scale
    if trace_integral is None:
        # no Liouville check: the a-priori bound of the factors' errors
        error += len(factors) * restart * rtol
    else:
        error += rtol * abs(trace_integral)
        # Liouville: Σ log|μ| = ∮ tr A dt + Σ log|det S|
        dets = np.array([abs(np.linalg.det(S)) for S in saltations])
        if np.all(dets > 0) and np.all(np.isfinite(logmod)):
            volume = trace_integral + np.sum(np.log(dets))
            error += abs(np.sum(logmod) - volume)
    phase = None
    if phase_direction is not None:
        phase = _phase_index(logmod, arg, phase_direction, monodromy)
    return OrbitMultipliers(logmod, arg, phase, float(error))


def _phase_index(logmod, arg, direction, monodromy):
    """Index of the multiplier of the flow direction (``Φ f = f``).

    The multiplier nearest 1; when several lie near 1 (a conserved
    quantity), the one whose eigenvector of the formed monodromy is best
    aligned with the vector field.
    """
    dist = np.hypot(logmod, np.angle(np.exp(1j * arg)))
    near = np.flatnonzero(dist < _PHASE_NEAR)
    if near.size <= 1 or monodromy is None:
        return int(np.argmin(dist))
    vals, vecs = np.linalg.eig(monodromy)
    unit = direction / np.linalg.norm(direction)
    align = np.abs(vecs.conj().T @ unit) / np.linalg.norm(vecs, axis=0)
    target = vals[int(np.argmax(align))]
    mu = np.exp(logmod[near]) * np.exp(1j * arg[near])
    return int(near[np.argmin(np.abs(mu - target))])
