"""
Return-map eigenvalues of the simplified hopper versus spring stiffness
=======================================================================

Analogue of thesis Fig. 3.7.  For each spring stiffness k the hopper's 1 s
limit cycle is computed by shooting, and the eigenvalues of its linearised
return map are obtained in two ways:

(a) the piecewise-LTI formula (3.43), ``e^{A_1 (T − t̂)} e^{A_0 t̂}``, which
    freezes the damper switching at the orbit's switching times;
(b) the exact period-map Jacobian from the variational equations and the
    saltation matrices of the state-dependent switches.

The two agree to about 1e-9 for every k: the damping force ``c ẋ``
vanishes on the switching surface ``ẋ = 0``, so the vector field is
continuous there and every saltation matrix is the identity.  Hence (3.43)
is exact for this model, and the small discrepancy reported in the thesis
cannot come from freezing the switching times.  The complex pair becomes
real in a narrow band near k = 158 ≈ (4π)², where the unforced flight
oscillation completes two cycles per forcing period.
"""

import matplotlib

matplotlib.use('Agg')

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from hopper import hopper_orbit, hopper_plant, piecewise_lti_return_map  # noqa: E402


def sweep(stiffness):
    """Eigenvalues of (3.43) and of the exact Jacobian for each k (continuation in k)."""
    approx, exact = [], []
    guess = {}
    for k in stiffness:
        plant = hopper_plant(k=k)
        orbit = hopper_orbit(plant, **guess)
        guess = {'x0': orbit.x0, 'mode0': orbit.mode0}
        approx.append(np.sort_complex(np.linalg.eigvals(piecewise_lti_return_map(orbit, k=k))))
        exact.append(np.sort_complex(orbit.multipliers))
    return np.array(approx), np.array(exact)


def main():
    stiffness = np.unique(np.concatenate([np.linspace(120, 240, 13), np.linspace(154, 164, 11)]))
    approx, exact = sweep(stiffness)
    difference = np.abs(approx - exact).max()
    fig, (ax_re, ax_im) = plt.subplots(2, 1, sharex=True, figsize=(6, 6))
    for j in range(2):
        ax_re.plot(stiffness, exact[:, j].real, 'k-', label='exact (saltation)' if j == 0 else None)
        ax_re.plot(stiffness, approx[:, j].real, 'o', mfc='none', color='C1',
                   label='piecewise LTI (3.43)' if j == 0 else None)
        ax_im.plot(stiffness, exact[:, j].imag, 'k-')
        ax_im.plot(stiffness, approx[:, j].imag, 'o', mfc='none', color='C1')
    ax_re.set_ylabel('Re(eigenvalue)')
    ax_im.set_ylabel('Im(eigenvalue)')
    ax_im.set_xlabel('spring stiffness k [N/m]')
    ax_re.legend()
    ax_re.set_title(f'Hopper return map (max difference {difference:.1e})')
    fig.tight_layout()
    fig.savefig('hopper_return_map.png', dpi=100)
    print(f'max |eig(3.43) - eig(exact)| over the sweep: {difference:.2e}')
    real = stiffness[np.all(np.abs(exact.imag) < 1e-9, axis=1)]
    print(f'real eigenvalue pair for k in [{real.min():g}, {real.max():g}]')
    return stiffness, approx, exact


if __name__ == '__main__':
    main()
