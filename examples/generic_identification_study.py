"""Identification of generic LTP plants: model error versus harmonics K.

Thirty seeded random stable single-input plants (`random_ltp_plants.random_ltp`)
with n_p = 2, 3, 4 states, one or two outputs and harmonics up to 2 in A(t),
B(t) and C(t), and thirty with two inputs and two outputs, are identified by
`ltpcontrol.identify_ltp` from their exact (noise-free) lifted frequency
response on 120 lines in (0, 3 ω_p), for K = 1..4, once with the default
refit (``refit_harmonics='auto'``: B(t) gets K or K + 1 harmonics, chosen by
the data) and once with B(t) of K harmonics (``refit_harmonics=K``).  Each
model is compared with its plant by `ltpcontrol.compare_ltp` (HTF blocks
with harmonics -1..1 at 37 unseen frequencies in (0, 2 ω_p), and Floquet
exponents modulo jω_p).  A plant whose A(t) is periodic has infinitely many
harmonics in Floquet form, so a K-harmonic model has a truncation error;
the table shows it decaying geometrically with K, and the input harmonics
K + 1 removing most of the truncation bias of the exponents.

Run ``python examples/generic_identification_study.py`` (about ten minutes;
``LTP_EXAMPLES_QUICK=1`` uses 6 plants of each kind).
"""

import os
import time
import warnings

import numpy as np

import ltpcontrol as ltp
from random_ltp_plants import design_lines, lifted_data, random_ltp

T, DT = 1.0, 1 / 64
LINES = design_lines(T, 120)
UNSEEN = design_lines(T, 37, wmax_factor=2.0, offset=0.61)
NSEEDS = 2 if os.environ.get('LTP_EXAMPLES_QUICK') else 10
#: (K, refit_harmonics) per column
SETTINGS = [(K, H) for K in (1, 2, 3, 4) for H in (K, 'auto')]


def study(ninputs=1):
    """HTF error, exponent error, B harmonics and run time, shape (plants, settings, 4)."""
    errors = []
    for seed in range(NSEEDS):
        for n, ny in ((2, 1), (3, 2), (4, 1)) if ninputs == 1 else ((2, 2), (3, 2), (4, 2)):
            plant = random_ltp(seed, n, ny, ninputs=ninputs)
            row = []
            for K, H in SETTINGS:
                data = lifted_data(plant, K, LINES, DT)
                start = time.process_time()
                with warnings.catch_warnings():
                    warnings.simplefilter('ignore')
                    model = ltp.identify_ltp(data, T, n, K, refit_harmonics=H)
                elapsed = time.process_time() - start
                cmp = ltp.compare_ltp(model, plant, UNSEEN, 1)
                row.append((cmp.htf_error, cmp.exponent_error, model.B.nharmonics, elapsed))
            errors.append(row)
    return np.array(errors)


if __name__ == '__main__':
    for m in (1, 2):
        err = study(m)
        print(f"{len(err)} plants with {m} input(s) (n_p = 2-4, harmonics <= 2 in A, B, C), "
              "noise-free data")
        print(f"{'K':>2} {'H':>5} {'HTF median':>11} {'HTF max':>9} {'exp. median':>12} "
              f"{'exp. max':>9} {'exp. <= 1e-3':>13} {'H = K+1':>8} {'time':>6}")
        for j, (K, H) in enumerate(SETTINGS):
            h, e, nb, sec = err[:, j].T
            print(f"{K:>2} {H:>5} {np.median(h):11.1e} {h.max():9.1e} {np.median(e):12.1e} "
                  f"{e.max():9.1e} {int(np.sum(e <= 1e-3)):>10}/{len(e)} "
                  f"{int(np.sum(nb > K)):>5}/{len(e)} {sec.sum():6.1f}")
