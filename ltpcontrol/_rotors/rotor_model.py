"""Rotor models: an LTP system with its rotor data and azimuth samples.

The time axis is the rotor's: the blade-1 azimuth is ``ψ(t) = ψ_0 + Ω t``
(constant speed) and the period ``T = 2π/Ω`` is one revolution.  A model
read from linearizations at azimuths ``ψ_s`` keeps those samples, so that
the peers' azimuth average ``(1/S) Σ_s A(ψ_s)`` can be formed even when the
samples are too few, or too irregular, to define a periodic model.
"""

import numpy as np
import control as ct
from control.exception import ControlArgument

from .._core.ltpsys import LTPStateSpace
from .._core.periodic_matrix import PeriodicMatrix

__all__ = ['RotorStateSpace']


class RotorStateSpace(LTPStateSpace):
    """LTP system of a rotor, with its azimuth samples and state descriptions.

    Created by `read_lin` and `mbc`; it is an `LTPStateSpace` in every
    respect (its time axis is the rotor's, ``ψ(t) = azimuth0 + Ω t``, and its
    period one revolution), with the rotor data kept as attributes.

    Parameters
    ----------
    A, B, C, D : PeriodicMatrix
        System matrices.
    period : float
        One revolution ``2π/Ω``.
    rotor : dict
        Rotor data: the keys of the attributes below.
    **kwargs
        ``name``, ``inputs``, ``outputs``, ``states``.

    Attributes
    ----------
    rotor_speed : float
        Ω in rad/s.
    azimuth0 : float
        Azimuth of blade 1 at t = 0 (rad).
    azimuths : ndarray or None
        Azimuths (rad) of the samples the model was built from.
    samples : tuple of ndarray or None
        ``(A, B, C, D)`` at those azimuths, each of shape ``(S, rows, cols)``.
    interpolation : {'fourier', 'hold', None}
        How the matrices between the samples are formed; None when no
        periodic model could be formed (the matrices then raise
        `ValueError` when evaluated).
    nblades : int or None
        Number of blades.
    frame : {'rotating', 'multiblade'}
        Coordinates of the blade states.
    state_descriptions, input_descriptions, output_descriptions : list of str
        Descriptions of the states, inputs and outputs.
    rotating_states, rotating_inputs, rotating_outputs : ndarray of bool
        Rotating-frame flags.
    derivative_order : ndarray of int
        Per state: 2 for a displacement or rate of a second-order degree
        of freedom, 1 for a first-order state (0 when unknown).
    wind_speed : float or None
        Wind speed of the operating point (m/s).
    sample_speeds, sample_accelerations : ndarray or None
        Ω and Ω̇ at each sample, from the operating point of the generator
        azimuth and drivetrain states as MBC3 takes them (`mbc` transforms
        the samples with them).
    precision : float or None
        Relative precision of the data the model was read from (half a unit
        of the last printed digit); `floquet_modes` takes a model whose
        matrices vary by less than 20 times it as time-invariant.

    Examples
    --------
    >>> A = ltp.PeriodicMatrix.constant([[-1.0]], 2 * np.pi)
    >>> rot = ltp.RotorStateSpace(A, np.zeros((1, 0)), np.zeros((0, 1)),
    ...                           np.zeros((0, 0)), 2 * np.pi, rotor={'rotor_speed': 1.0})
    >>> rot.rotor_speed, rot.frame
    (1.0, 'rotating')
    >>> rot
    <RotorStateSpace sys[...]: 1 states, rotating frame, rotor speed 1 rad/s, period=6.28319>
    """

    _KEYS = ('rotor_speed', 'azimuth0', 'azimuths', 'samples', 'interpolation', 'nblades',
             'frame', 'state_descriptions', 'input_descriptions', 'output_descriptions',
             'rotating_states', 'rotating_inputs', 'rotating_outputs', 'derivative_order',
             'wind_speed', 'precision', 'sample_speeds', 'sample_accelerations')

    def __init__(self, A, B, C, D, period, *, rotor=None, **kwargs):
        super().__init__(A, B, C, D, period, **kwargs)
        rotor = dict(rotor or {})
        unknown = set(rotor) - set(self._KEYS)
        if unknown:
            raise ControlArgument(f"rotor has unknown keys {sorted(unknown)}")
        n, m, p = self.nstates, self.ninputs, self.noutputs
        defaults = dict(rotor_speed=2 * np.pi / period, azimuth0=0.0, azimuths=None,
                        samples=None, interpolation='fourier', nblades=None,
                        frame='rotating', state_descriptions=list(self.state_labels),
                        input_descriptions=list(self.input_labels),
                        output_descriptions=list(self.output_labels),
                        rotating_states=np.zeros(n, bool), rotating_inputs=np.zeros(m, bool),
                        rotating_outputs=np.zeros(p, bool),
                        derivative_order=np.zeros(n, int), wind_speed=None, precision=None,
                        sample_speeds=None, sample_accelerations=None)
        defaults.update(rotor)
        for key, value in defaults.items():
            setattr(self, key, value)

    def _repr_info_(self, html=False):
        speed = f", rotor speed {self.rotor_speed:.4g} rad/s"
        samples = f", {len(self.azimuths)} azimuths" if self.azimuths is not None else ""
        text = (f"<RotorStateSpace {self.name}: {self.nstates} states, {self.frame} frame"
                f"{speed}{samples}, period={self.period:g}>")
        return text if not html else text.replace('<', '&lt;').replace('>', '&gt;')

    def rotor_data(self):
        """The rotor data as a dict (for building a derived model).

        Examples
        --------
        >>> A = ltp.PeriodicMatrix.constant([[-1.0]], 1.0)
        >>> rot = ltp.RotorStateSpace(A, np.zeros((1, 0)), np.zeros((0, 1)),
        ...                           np.zeros((0, 0)), 1.0)
        >>> rot.rotor_data()['frame']
        'rotating'
        """
        return {key: getattr(self, key) for key in self._KEYS}

    def average(self, *, method='fourier', **kwargs):
        """Azimuth-averaged LTI system.

        Parameters
        ----------
        method : {'fourier', 'samples'}
            'fourier' (default): the mean over the period of the periodic
            matrices, ``A_0 = (1/T)∮A(t)dt``.  'samples': the arithmetic mean
            of the matrices at the azimuths the model was built from, as
            MBC3 and its ports compute it (equal to 'fourier' for uniform
            samples of a model band-limited below half their number).
        **kwargs
            Keywords of the `control.StateSpace` (``name``, ...).

        Returns
        -------
        control.StateSpace
            A model without inputs (outputs) gets one input (output) named
            ``'none'`` with zero gains, as `control.StateSpace` needs one.

        Raises
        ------
        ValueError
            For ``method='samples'`` on a model without samples, or
            ``method='fourier'`` on one whose periodic model could not be
            formed.

        Examples
        --------
        >>> A = ltp.PeriodicMatrix.from_samples([[[1.0]], [[3.0]]], 1.0, kind='hold')
        >>> rot = ltp.RotorStateSpace(A, np.zeros((1, 0)), np.zeros((0, 1)),
        ...                           np.zeros((0, 0)), 1.0)
        >>> rot.average().A
        array([[2.]])
        """
        if method == 'fourier':
            if self.interpolation is None:
                raise ValueError("the model has no periodic matrices (its azimuth samples "
                                 "are not uniform and complete); use method='samples'")
            mats = [M.fourier(0)[0].real.reshape(M.shape) for M in (self.A, self.B, self.C,
                                                                    self.D)]
        elif method == 'samples':
            if self.samples is None:
                raise ValueError("the model was not built from azimuth samples; use "
                                 "method='fourier'")
            mats = [M.mean(axis=0) for M in self.samples]
        else:
            raise ValueError(f"method must be 'fourier' or 'samples', got {method!r}")
        kwargs.setdefault('name', self.name + '$averaged')
        for key in ('inputs', 'outputs', 'states'):
            kwargs.setdefault(key, list(getattr(self, key[:-1] + '_labels')))
        # control.StateSpace needs an input and an output: stand-ins of zero gain
        A, B, C, D = mats
        if B.shape[1] == 0:
            B, D, kwargs['inputs'] = np.zeros((A.shape[0], 1)), np.zeros((C.shape[0], 1)), \
                ['none']
        if C.shape[0] == 0:
            C, D, kwargs['outputs'] = np.zeros((1, A.shape[0])), np.zeros((1, B.shape[1])), \
                ['none']
        return ct.ss(A, B, C, D, self.dt, **kwargs)


def sampled_matrix(samples, azimuths, azimuth0, period, interpolation, name):
    """Periodic matrix of uniform azimuth samples, or one that refuses evaluation.

    `interpolation` 'fourier' (trigonometric interpolant) or 'hold'; None
    gives a matrix whose evaluation raises `ValueError` naming `name`.

    Examples
    --------
    >>> from ltpcontrol._rotors.rotor_model import sampled_matrix
    >>> psi = np.arange(4) * np.pi / 2
    >>> M = sampled_matrix(np.cos(psi)[:, None, None], psi, 0.0, 1.0, 'fourier', 'A')
    >>> float(M(0.125)[0, 0]).__round__(12)
    0.707106781187
    """
    samples = np.asarray(samples, float)
    if interpolation is None:
        def refuse(t):
            if len(azimuths) == 1:
                raise ValueError(f"{name}(t) is not available: a linearization at a single "
                                 "azimuth of a turning rotor defines no periodic model (a "
                                 "constant one would assume rotating-frame matrices "
                                 "independent of the azimuth); use mbc and "
                                 "average(method='samples'), exact for an isotropic rotor")
            raise ValueError(f"{name}(t) is not available: the model's {len(azimuths)} "
                             "azimuth samples are not uniform and complete, so no periodic "
                             "model can be formed (use average(method='samples'))")
        return PeriodicMatrix.from_function(refuse, period, samples.shape[1:], check=False)
    if np.all(samples == samples[0]):
        return PeriodicMatrix.constant(samples[0], period)
    return PeriodicMatrix.from_samples(samples, period, kind=interpolation)
