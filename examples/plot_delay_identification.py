"""
Input and measurement delays from harmonic transfer functions
=============================================================

Analogue of thesis §3.6.4 (Table 3.1, Figs. 3.8-3.9).

With an input delay τ_u and a measurement delay τ_y the harmonic transfer
functions between the actual input and output are (eq. 3.45)

``H_m(jω) = G_m(jω) e^{−j[(ω − mω_p) τ_u + ω τ_y]}``:

magnitudes are unchanged (3.46), and the phase of ``G_0`` only sees the
total delay, while every harmonic ``m ≠ 0`` adds the offset ``m ω_p τ_u``
that separates the two delays (3.47).  The procedure of the thesis:

1. simulate the hybrid hopper of §3.4 (not its LTP model) under the
   nine-chirp experiment of §3.4.3, for each of the nine delay pairs of
   Table 3.1 (τ_u ∈ {0, 40, 80} ms, τ_y ∈ {0, 50, 100} ms): the plant is
   driven by ``u(t − τ_u)`` and the output record is ``x(t − τ_y) − x̄``;
2. estimate ``Ĥ_m`` from the undelayed input and the delayed output;
3. fit k and c of the LTP model (3.39) to the magnitudes of all nine
   estimates at once (the mean of the nine magnitude responses, which gives
   the same least-squares minimiser as stacking them);
4. estimate the delays from the phases of ``Ĥ_0`` (total only), ``Ĥ_{-1}``
   and ``Ĥ_1`` separately, minimising the magnitude-weighted phase error
   (3.49)-(3.50) with `ltpcontrol.estimate_delays`.

Each input delay needs its own simulation; a measurement delay is a shift of
the sampled output by a whole number of samples (50 ms = 9 samples).

Set ``LTP_EXAMPLES_QUICK=1`` for a reduced run (shorter chirps).
"""

import time

import matplotlib

matplotlib.use('Agg')

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import ltpcontrol as ltp  # noqa: E402
from hopper import HOPPER_PARAMS, PERIOD, hopper_plant  # noqa: E402
from plot_hopper_htf_identification import (BAND, DESIGN, DT, N_JOBS, QUICK,  # noqa: E402
                                            QUICK_DESIGN, chirp_experiment, estimate,
                                            fit_parameters, limit_cycle, model_htf,
                                            switching_times)

#: Delays of Table 3.1 (seconds).
INPUT_DELAYS = (0.0, 0.040, 0.080)
OUTPUT_DELAYS = (0.0, 0.050, 0.100)

#: Table 3.1 of the thesis, per experiment: τ̂_{u+y} from G_0, (τ̂_u, τ̂_y) from
#: G_{-1} and from G_1, in ms.
THESIS_TABLE = [
    (0.0, (0.0, 1.6), (0.0, 0.0)), (49.9, (0.0, 51.6), (0.0, 47.5)),
    (99.9, (0.0, 101.6), (0.0, 97.5)), (40.0, (41.1, 0.0), (38.0, 0.0)),
    (90.1, (41.7, 49.7), (41.2, 47.6)), (140.1, (41.9, 99.5), (41.2, 95.1)),
    (80.1, (81.7, 0.5), (76.7, 2.9)), (130.1, (81.8, 50.4), (76.8, 52.4)),
    (180.1, (82.1, 100.2), (76.9, 102.7)),
]


def delay_output(exc, y, output_delay):
    """Measured output ``y(t) = ȳ(t − τ_y)`` of each record (whole samples)."""
    shift = output_delay / DT
    s = int(round(shift))
    if abs(shift - s) > 1e-9:
        raise ValueError(f"output delay {output_delay} s is not a multiple of dt = {DT} s")
    out = np.zeros_like(y)
    for a, b in exc.segments:
        # the record starts on the limit cycle: ȳ = 0 before it
        out[a + s:b] = y[a:b - s]
    return out


def delay_experiments(design=DESIGN, n_jobs=N_JOBS):
    """Estimated HTFs of the nine delayed experiments of Table 3.1.

    Returns a list of ``((τ_u, τ_y), HTF)`` in the order of the table and the
    switching instants of the nominal cycle.
    """
    plant = hopper_plant()
    cycle = limit_cycle(plant)
    estimates = []
    for tau_u in INPUT_DELAYS:
        exc, y = chirp_experiment(plant, cycle, design, input_delay=tau_u, n_jobs=n_jobs)
        for tau_y in OUTPUT_DELAYS:
            H = estimate(exc, delay_output(exc, y, tau_y))
            estimates.append(((tau_u, tau_y), H))
    return estimates, switching_times(cycle[2])


def magnitude_fit(estimates, switching):
    """Fit k, c to the mean magnitude of all estimates (delays do not change it, 3.46)."""
    omega = estimates[0][1].omega
    mags = np.mean([np.abs(H.components()[1]) for _, H in estimates], axis=0)
    return fit_parameters(ltp.HTFData(mags, omega, PERIOD), switching, magnitude_only=True)


def estimate_all_delays(estimates, reference):
    """Delays from ``Ĥ_0`` (total), ``Ĥ_{-1}``, ``Ĥ_1`` and all three together.

    Returns an array of shape (9, 7) in seconds: true τ_u, τ_y, then the G_0
    total, (τ_u, τ_y) from G_{-1}, (τ_u, τ_y) from G_1; and the combined
    (-1, 0, 1) estimates, shape (9, 2).
    """
    rows, combined = [], []
    for (tau_u, tau_y), H in estimates:
        d0 = ltp.estimate_delays(H, reference, harmonics=[0], omega_limits=BAND)
        dm = ltp.estimate_delays(H, reference, harmonics=[-1], omega_limits=BAND)
        dp = ltp.estimate_delays(H, reference, harmonics=[1], omega_limits=BAND)
        da = ltp.estimate_delays(H, reference, harmonics=[-1, 0, 1], omega_limits=BAND)
        rows.append([tau_u, tau_y, d0.total_delay, dm.input_delay, dm.output_delay,
                     dp.input_delay, dp.output_delay])
        combined.append([da.input_delay, da.output_delay])
    return np.array(rows), np.array(combined)


def _pe(estimate, truth):
    """Percentage error, or the absolute error in ms for a zero delay."""
    if truth == 0:
        return f"({1e3 * estimate:+.2f})"
    return f"{100 * abs(estimate - truth) / truth:.2f}%"


def format_table(rows, combined):
    """Table 3.1 with our estimates (ms), percentage errors and the thesis's values.

    For a zero true delay the absolute error in ms is shown in parentheses.
    """
    lines = ["Exp  τu  τy |  G_0 τ̂u+y   PE    | G_-1 τ̂u   PE     τ̂y    PE     "
             "| G_1 τ̂u    PE     τ̂y    PE     | all τ̂u  τ̂y",
             "-" * 131]
    for i, (row, comb, thesis) in enumerate(zip(rows, combined, THESIS_TABLE)):
        tu, ty, tot, um, ym, up, yp = row
        lines.append(
            f"#{i + 1}  {1e3 * tu:3.0f} {1e3 * ty:3.0f} | {1e3 * tot:7.2f} {_pe(tot, tu + ty):>9} "
            f"| {1e3 * um:6.2f} {_pe(um, tu):>8} {1e3 * ym:7.2f} {_pe(ym, ty):>8} "
            f"| {1e3 * up:6.2f} {_pe(up, tu):>8} {1e3 * yp:7.2f} {_pe(yp, ty):>8} "
            f"| {1e3 * comb[0]:6.2f} {1e3 * comb[1]:6.2f}")
        g0, gm, gp = thesis
        lines.append(
            f"   thesis    | {g0:7.1f} {_pe(g0 / 1e3, tu + ty):>9} "
            f"| {gm[0]:6.1f} {_pe(gm[0] / 1e3, tu):>8} {gm[1]:7.1f} {_pe(gm[1] / 1e3, ty):>8} "
            f"| {gp[0]:6.1f} {_pe(gp[0] / 1e3, tu):>8} {gp[1]:7.1f} {_pe(gp[1] / 1e3, ty):>8} |")
    return "\n".join(lines)


def relative_errors(rows):
    """Errors of all delay estimates relative to the truth.

    Relative to the true delay where it is nonzero; for a zero true delay
    relative to the smallest nonzero delay of the table (40 ms).
    """
    truth = np.column_stack([rows[:, 0] + rows[:, 1], rows[:, 0], rows[:, 1],
                             rows[:, 0], rows[:, 1]])
    est = rows[:, 2:]
    scale = np.where(truth > 0, truth, min(d for d in INPUT_DELAYS + OUTPUT_DELAYS if d > 0))
    return np.abs(est - truth) / scale


def main():
    start = time.time()
    design = QUICK_DESIGN if QUICK else DESIGN
    estimates, switching = delay_experiments(design)
    print(f"nine delayed experiments simulated and estimated ({time.time() - start:.0f} s)")
    fit = magnitude_fit(estimates, switching)
    k_hat, c_hat = fit.params
    print(f"magnitude-only fit over all nine experiments: k = {k_hat:.3f} "
          f"(true {HOPPER_PARAMS['k']:g}), c = {c_hat:.4f} (true {HOPPER_PARAMS['c']:g}); "
          "thesis: 200 and 2.12")
    reference = model_htf(fit.params, switching, estimates[0][1].nharmonics)
    reference.name = 'parametric (undelayed)'
    rows, combined = estimate_all_delays(estimates, reference)
    print("\nTable 3.1: delay estimates [ms] and percentage errors")
    print(format_table(rows, combined))
    err = relative_errors(rows)
    print(f"\nlargest error: {100 * err.max():.2f} % (relative to the true delay, or to "
          "40 ms for a zero delay)")

    # Figs. 3.8-3.9: magnitudes and phases of experiment #9 (τ_u = 80, τ_y = 100 ms)
    (tau_u, tau_y), H = estimates[-1]
    omega, G = H.components()
    _, G_ref = reference.components(omega)
    K = H.nharmonics
    ks = np.array([-1, 0, 1])
    comp = np.exp(1j * ((omega[None, :] - ks[:, None] * 2 * np.pi / PERIOD) * rows[-1, 3]
                        + omega[None, :] * rows[-1, 4]))
    fig, axes = plt.subplots(2, 3, figsize=(12, 6), sharex=True)
    for j, kh in enumerate(ks):
        g, r = G[kh + K, 0, 0], G_ref[kh + K, 0, 0]
        axes[0, j].semilogy(omega, np.abs(r), 'b--', label='parametric fit')
        axes[0, j].semilogy(omega, np.abs(g), 'k.', ms=3, label='estimated (delayed)')
        axes[0, j].set_title(f'|G_{kh:+d}|')
        axes[1, j].plot(omega, np.degrees(np.unwrap(np.angle(r))), 'b--', label='parametric fit')
        axes[1, j].plot(omega, np.degrees(np.unwrap(np.angle(g))), 'k.', ms=3,
                        label='estimated (delayed)')
        axes[1, j].plot(omega, np.degrees(np.unwrap(np.angle(g * comp[j]))), 'g-', lw=1,
                        label='estimated, delays compensated (G_-1)')
        axes[1, j].set_xlabel('frequency [rad/s]')
    axes[0, 0].legend(fontsize=8)
    axes[1, 0].legend(fontsize=8)
    axes[1, 0].set_ylabel('phase [deg]')
    fig.suptitle(f'Hopper HTF with τ_u = {1e3 * tau_u:.0f} ms, τ_y = {1e3 * tau_y:.0f} ms')
    fig.tight_layout()
    fig.savefig('hopper_delay_htf.png', dpi=100)
    print(f"\ntotal {time.time() - start:.0f} s")
    return rows, combined, fit


if __name__ == '__main__':
    main()
