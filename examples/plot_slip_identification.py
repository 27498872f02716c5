"""
Identifying and validating SLIP stride predictors on a synthetic monopod
========================================================================

This example re-runs the experimental study of thesis Chapter 2 on a
synthetic stand-in for the planarized monopod: single strides of the
extended spring-loaded inverted pendulum (leg mass, leg damping, flight
damping, liftoff collision) measured with 0.21 mm encoders at 500 Hz,
disturbed by a ringing boom and small stride-to-stride variations, and
processed with a zero-phase 50 Hz Butterworth filter.

Steps, as in Sections 2.4-2.5:

1. masses and vertical flight damping from vertical hops, cost (2.25);
2. horizontal flight damping by linear least squares (2.26)-(2.28);
3. leg stiffness and damping per spring and per predictor (SLIPD, AAS,
   SLIP, Geyer) on the cost (2.33), with k-fold cross-validation
   (Table 2.4);
4. identification accuracy on clean data: the same pipeline on a robot
   that is exactly the extended SLIP, with known ``k, d``;
5. one stride against the AAS and Geyer predictions (Fig. 2.5);
6. apex position error against the relative touchdown angle (Fig. 2.6).

Set ``LTP_EXAMPLES_QUICK=1`` for a reduced run (fewer experiments and
folds).
"""

import os
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from joblib import Parallel, delayed  # noqa: E402

from slip_data import CLEAN, MONOPOD, SPRINGS, generate_strides  # noqa: E402
from slip_identification import (cross_validate, fit_leg, format_table,  # noqa: E402
                                 identify_flight_damping, identify_vertical,
                                 relative_angle_study)
from slip_model import METHODS, stride_trajectory  # noqa: E402

QUICK = os.environ.get("LTP_EXAMPLES_QUICK", "0") == "1"
N_HOPS, N_STRIDES, FOLDS, N_CLEAN = (15, 40, 5, 30) if QUICK else (50, 120, 30, 60)
#: Worker processes for the fits: one in the quick run (the documentation build
#: runs beside the test suite, where more processes only compete for the cores).
N_JOBS = 1 if QUICK else -1
ORDER = ("hard", "medium", "soft", "softer")
start = time.time()
rng = np.random.default_rng(2017)

# %%
# Synthetic experiments
# ---------------------
# Vertical hops and running strides for each of the four springs.  The
# "truth" is the thesis's identified monopod (Tables 2.3 and 2.5).

hops = {s: generate_strides(s, N_HOPS, rng, vertical=True) for s in ORDER}
runs = {s: generate_strides(s, N_STRIDES, rng) for s in ORDER}
print(f"{N_HOPS} vertical hops and {N_STRIDES} strides per spring "
      f"({time.time() - start:.0f} s)")

# %%
# Masses and flight damping
# -------------------------
# The total mass ``m_b + m_l = 3.4 kg`` is taken as measured; the
# "manual" spring measurements of Table 2.5 start the search.

manual = {"softer": 2322.0, "soft": 2915.0, "medium": 4298.0, "hard": 6282.0}
vertical = identify_vertical(hops, 3.4, MONOPOD, manual)
d_h, vy0 = identify_flight_damping([runs[s] for s in ORDER])
vy0 = dict(zip(ORDER, vy0))
print("\nTable 2.3 analogue (identified / true)")
print(f"  m_b = {vertical['m_b']:.3f} / {MONOPOD.m_b} kg,  "
      f"m_l = {vertical['m_l']:.3f} / {MONOPOD.m_l} kg,  "
      f"d_v = {vertical['d_v']:.3f} / {MONOPOD.d_v} 1/s,  "
      f"d_h = {d_h:.3f} / {MONOPOD.d_h} 1/s")
model = MONOPOD.replace(m_b=vertical["m_b"], m_l=vertical["m_l"],
                        d_v=vertical["d_v"], d_h=d_h)

# %%
# Cross-validated leg identification (Table 2.4)
# ----------------------------------------------
# Every predictor fits its own leg parameters, starting from the vertical
# estimates; lossless predictors fit the stiffness only.

jobs = [(s, m) for s in ORDER for m in METHODS]
results = Parallel(n_jobs=N_JOBS)(
    delayed(cross_validate)(runs[s], model.replace(k=vertical["springs"][s][0],
                                                   d=vertical["springs"][s][1]),
                            m, folds=FOLDS, vy0=vy0[s])
    for s, m in jobs)
cv = dict(zip(jobs, results))
print(f"\nTable 2.4 analogue: {FOLDS}-fold cross-validation, percentage errors")
print(format_table(results))

print("\nTable 2.5 analogue: leg parameters k (N/m) / d (Ns/m)")
print(f"{'':<9}" + "".join(f"{s:>18}" for s in ORDER))
for m in METHODS:
    cells = [f"{cv[s, m].k.mean():8.0f} / {cv[s, m].d.mean():5.1f}"
             if m in ("SLIPD", "AAS") else f"{cv[s, m].k.mean():8.0f} /     –"
             for s in ORDER]
    print(f"{m:<9}" + "".join(f"{c:>18}" for c in cells))
print(f"{'Vertical':<9}" + "".join(
    f"{vertical['springs'][s][0]:8.0f} / {vertical['springs'][s][1]:5.1f}".rjust(18)
    for s in ORDER))
print(f"{'True':<9}" + "".join(f"{SPRINGS[s][0]:8.0f} / {SPRINGS[s][1]:5.1f}".rjust(18)
                               for s in ORDER))

# %%
# Identification accuracy on clean data
# -------------------------------------
# The study above mixes two things: how well the identification recovers
# the leg and how a predictor copes with a robot that is not exactly the
# extended SLIP (ringing boom, stride-to-stride variation).  Repeating the
# whole pipeline (vertical hops, flight damping, leg fits) on a robot that
# *is* the extended SLIP, measured with the same encoders, sampling and
# filter, isolates the first.  SLIPD recovers ``k, d`` within about 1 %.
# AAS does not reach that: fitted to these clean data it is biased by
# -2 to -7 % in ``k`` and -2 to -18 % in ``d``, growing as the spring
# softens.  This is the error of its stance approximation (small sweep,
# centrifugal term linearised at the rest length, while these legs compress
# by up to a third), not of the fit: the same fit recovers ``k, d`` to
# 1e-5 from transitions AAS itself predicts (see the tests).  The lossless
# numerical SLIP needs a stiffer leg than the truth (+8 to +11 % in the full
# run, 60 clean strides per spring; +6 to +10 % in the reduced run of the
# documentation build, 30 strides), as in Table 2.5 (+19 to +31 %).  Geyer's approximation is biased soft on its
# own, and on these data its fit stays below the truth instead of the
# thesis's +40 to +115 %.

clean_hops = {s: generate_strides(s, N_HOPS, rng, vertical=True, perturbations=CLEAN)
              for s in ORDER}
clean_runs = {s: generate_strides(s, N_CLEAN, rng, perturbations=CLEAN) for s in ORDER}
clean_vertical = identify_vertical(clean_hops, 3.4, MONOPOD, manual)
clean_d_h, clean_vy0 = identify_flight_damping([clean_runs[s] for s in ORDER])
clean_vy0 = dict(zip(ORDER, clean_vy0))
clean_model = MONOPOD.replace(m_b=clean_vertical["m_b"], m_l=clean_vertical["m_l"],
                              d_v=clean_vertical["d_v"], d_h=clean_d_h)
clean_fits = Parallel(n_jobs=N_JOBS)(
    delayed(fit_leg)(clean_runs[s], clean_model.replace(k=clean_vertical["springs"][s][0],
                                                        d=clean_vertical["springs"][s][1]),
                     m, clean_vy0[s], max_nfev=100)
    for s, m in jobs)
clean_fits = dict(zip(jobs, clean_fits))
print(f"\nClean data ({N_CLEAN} strides per spring): m_l = {clean_vertical['m_l']:.3f}, "
      f"d_v = {clean_vertical['d_v']:.3f}, d_h = {clean_d_h:.3f}")
print("fitted k (N/m) / d (Ns/m), deviation from the truth in %")
print(f"{'':<9}" + "".join(f"{s:>30}" for s in ORDER))
for m in METHODS:
    cells = []
    for s in ORDER:
        k, d, _ = clean_fits[s, m]
        k0, d0 = SPRINGS[s]
        cells.append(f"{k:5.0f} ({100 * (k / k0 - 1):+5.1f}) / " + (
            f"{d:4.1f} ({100 * (d / d0 - 1):+5.1f})" if m in ("SLIPD", "AAS") else "   –        "))
    print(f"{m:<9}" + "".join(f"{c:>30}" for c in cells))
cells = []
for s in ORDER:
    (k, d), (k0, d0) = clean_vertical["springs"][s], SPRINGS[s]
    cells.append(f"{k:5.0f} ({100 * (k / k0 - 1):+5.1f}) / {d:4.1f} ({100 * (d / d0 - 1):+5.1f})")
print(f"{'Vertical':<9}" + "".join(f"{c:>30}" for c in cells))

# %%
# One stride against the predictions (Fig. 2.5)
# ---------------------------------------------
# A hard-spring stride, starting the predictors from the measured apex with
# the regression estimate of the horizontal velocity (2.28).

data = runs["hard"]
j = int(np.argmin(np.abs(data.apex0[:, 1] - 1.0)))
stride = data.strides[j]
apex = np.array([0.0, vy0["hard"][j], data.apex0[j, 2]])
t = np.linspace(0.0, stride.apex1.t, 400)
fig, axes = plt.subplots(2, 2, figsize=(9, 6), sharex=True)
keep = (stride.t >= 0) & (stride.t <= stride.apex1.t)
labels = ("y (m)", "z (m)", "ydot (m/s)", "zdot (m/s)")
for ax, meas, label in zip(axes.flat, (stride.y, stride.z, stride.vy, stride.vz), labels):
    ax.plot(stride.t[keep], meas[keep], "b-", label="data")
    ax.set_ylabel(label)
for m, style in (("AAS", "r--"), ("Geyer", "k--")):
    fit = cv["hard", m]
    pred = stride_trajectory(apex, data.theta_td[j],
                             model.replace(k=fit.k.mean(), d=fit.d.mean()), m, t)
    for ax, series in zip(axes.flat, pred):
        ax.plot(t, series, style, label=m)
for ax in axes[1]:
    ax.set_xlabel("t (s)")
axes[0, 0].legend()
fig.suptitle("Hard spring: measured stride and predictions (cf. Fig. 2.5)")
fig.tight_layout()
fig.savefig("slip_fig2_5_stride.png", dpi=120)

# %%
# Relative touchdown angle (Fig. 2.6)
# -----------------------------------
# Held-out AAS apex position errors binned by the deviation of the
# touchdown angle from the neutral angle (2.34)-(2.35), with quadratic fits.

fig, ax = plt.subplots(figsize=(7, 4.5))
print("\nFig. 2.6 analogue: AAS held-out E_ap by relative angle (deg)")
for s, colour in zip(ORDER, ("C0", "C1", "C2", "C3")):
    fit = cv[s, "AAS"]
    study = relative_angle_study(runs[s], model.replace(k=fit.k.mean(), d=fit.d.mean()),
                                 fit.stride_test[:, 0], vy0[s], bins=5 if QUICK else 7)
    centre = np.rad2deg(study["centre"])
    ax.errorbar(centre, study["mean"], yerr=study["std"], fmt="o", color=colour,
                capsize=3, label=s)
    grid = np.linspace(study["centre"][0], study["centre"][-1], 100)
    ax.plot(np.rad2deg(grid), np.polyval(study["quadratic"], grid), color=colour)
    print(f"  {s:<7}" + " ".join(f"{c:+5.1f}:{e:4.2f}" for c, e in
                                 zip(centre, study["mean"]) if np.isfinite(e)))
ax.set_xlabel("relative touchdown angle (deg)")
ax.set_ylabel("apex position error E_ap (%)")
ax.legend()
ax.set_title("AAS prediction error vs. relative angle (cf. Fig. 2.6)")
fig.tight_layout()
fig.savefig("slip_fig2_6_relative_angle.png", dpi=120)
print(f"\ntotal time {time.time() - start:.0f} s")
