"""What limits the hopper leg's HTF route: noise, estimator bias or the model?

The leg of ``ident_leg_paths.py`` (periodic stiffness and damping, period
0.5 s) identified with K harmonics (default 2) from 2K_h + 4 phase-shifted
chirp replicas (0-12 Hz, 20 s each) → `estimate_htf` with its defaults
(K_h = 3K + 1 harmonics, the band they reach) → `identify_ltp`.  Each row prints the
fresh-record NRMSE (filtered noise, cut-off 2 ω_p, 60 periods):

* ``noise-free``: the floor of the estimator and of the K-harmonic
  structure (a plant with periodic A(t) has infinitely many harmonics in
  Floquet form; at K = 2 this floor, 0.017 here and 0.013 from noise-free
  lifted sine data, is what the 30 dB records reach: the noise does not
  limit them, the structure does; with K = 3 the noise-free floor is
  0.0078 on this route and 0.0053 from lifted sine data, and 30 dB records
  reach 0.0054-0.0062 on this route);
* ``30 dB``, ``40 dB``, ``20 dB``: how the error scales with the noise
  (proportional to it when the noise limits);
* ``30 dB, 2x longer chirps``: twice the data at the same noise;
* ``30 dB, ML``: `refine='ml'` (the maximum-likelihood fit on the HTF
  components weighted by their ``std``) and the spread of the fresh
  prediction over models drawn from its parameter covariance
  (`sample_models`): the prediction error any efficient estimator leaves
  at this noise level and amount of data (the Cramér-Rao spread).

Run ``python examples/ident_leg_htf_floor.py [K]`` (several minutes on one core).
"""

import sys
import warnings

import numpy as np

import ltpcontrol as ltp

sys.path.insert(0, __file__.rsplit('/', 1)[0])
from ident_leg_paths import DT, T, fresh, leg  # noqa: E402

K = int(sys.argv[1]) if len(sys.argv) > 1 else 2


def identify(plant, snr, seed=0, duration=20.0, refine=None):
    Kh = 3 * K + 1
    exc = ltp.chirp_replicas(T, 2 * Kh + 4, duration, 0.0, 12.0, dt=DT, gap=4.0)
    y = ltp.forced_response(plant, exc.time, exc.inputs).outputs
    if snr is not None:
        sigma = np.sqrt(np.mean(y ** 2) / 10 ** (snr / 10))
        y = y + sigma * np.random.default_rng(seed).standard_normal(y.shape)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        H = ltp.estimate_htf((exc.time, exc.inputs, y), T, segments=exc.segments)
        model, info = ltp.identify_ltp(H, T, 3, K, refine=refine, return_info=True)
    return model, info


def main():
    plant = leg()
    rows = [('noise-free', None, 0, 20.0), ('40 dB', 40, 0, 20.0), ('30 dB', 30, 0, 20.0),
            ('20 dB', 20, 0, 20.0), ('30 dB, 2x longer chirps', 30, 0, 40.0)]
    for label, snr, seed, duration in rows:
        model, info = identify(plant, snr, seed, duration)
        print(f"{label:26s} success={info.success!s:5s} holdout={info.holdout_nrmse:.3g} "
              f"fresh={fresh(model, plant):.3g}", flush=True)
    model, info = identify(plant, 30, 0, refine='ml')
    base = fresh(model, plant)
    ref = info.refinement
    print(f"{'30 dB, ML':26s} success={info.success!s:5s} holdout={info.holdout_nrmse:.3g} "
          f"fresh={base:.3g}", flush=True)
    if ref is not None and ref.cov is not None and np.all(np.isfinite(ref.cov)):
        # spread of the fresh prediction over models the data do not rule out
        draws = ltp.sample_models(ref, 24, seed=1)
        spread = [fresh(m, model) for m in draws]
        print(f"{'':26s} prediction spread over 24 models drawn from the ML covariance: "
              f"RMS NRMSE {np.sqrt(np.mean(np.square(spread))):.3g} (min {min(spread):.3g}, "
              f"max {max(spread):.3g})", flush=True)


if __name__ == '__main__':
    main()
