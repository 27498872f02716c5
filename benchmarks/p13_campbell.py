"""P13: a Campbell diagram from OpenFAST linearization files.

Workload: the 16-state isotropic turbine of the gallery (tower fore-aft and
side-side, flap and edge of three blades) linearized at 8 rotor speeds
(quick mode 3; 4 printed decimals) x 36 azimuths, written as ``.lin`` files (10 digits) in one
folder per operating point; the files are written once, untimed.

* ours: ``campbell_lin(folder, method='floquet')`` — reading, blade groups
  from the descriptions, multi-blade transform, Floquet modes of the
  periodic multi-blade model (solved by ``eig`` when it is time-invariant
  to the data's precision), tracking by mode shape and labels.
* also: ``campbell_lin(folder)`` (averaging, with tracking and labels).
* peer: MBC averaging as MBC3 and its ports compute it — per operating
  point ``read_lin``, ``mbc``, the mean of the multi-blade matrices over the
  azimuths and ``numpy.linalg.eigvals``; no tracking, no labels.

Accuracy: the exponents of every operating point against the eigenvalues
of the multi-blade model transformed by hand (exact), 1e-7 absolute.
Target: ours at most 3x the peer.
"""

import pathlib
import sys
import tempfile

import numpy as np

from _common import median_time, row

import ltpcontrol as ltp

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))
from examples.rotor_models import turbine_mbc_A, write_turbine_study  # noqa: E402

TOL = 1e-7
FULL = dict(speeds=np.round(np.linspace(0.4, 1.3, 8), 2), repeats=3)
QUICK = dict(speeds=np.round(np.linspace(0.4, 1.3, 3), 2), repeats=1)


def peer(root):
    out = []
    for folder in sorted(root.iterdir()):
        nr, _ = ltp.mbc(ltp.read_lin(folder), 3)
        out.append(np.linalg.eigvals(nr.average(method='samples').A))
    return out


def error(exponents, speeds):
    return float(max(np.abs(np.linalg.eigvals(turbine_mbc_A(Om)) - lam).min()
                     for ev, Om in zip(exponents, speeds)
                     for lam in ev))


def run(quick=False, log=print):
    cfg = QUICK if quick else FULL
    speeds = cfg['speeds']
    log(f"P13: Campbell diagram of a 16-state turbine, {len(speeds)} rotor speeds x 36 "
        "azimuths from .lin files")
    with tempfile.TemporaryDirectory() as tmp:
        root = pathlib.Path(tmp)
        write_turbine_study(root, speeds)
        t_peer, ptimes, pev = median_time(lambda: peer(root), cfg['repeats'])
        t_flo, ftimes, flo = median_time(lambda: ltp.campbell_lin(root, method='floquet'),
                                         cfg['repeats'])
        t_avg, atimes, avg = median_time(lambda: ltp.campbell_lin(root), cfg['repeats'])
    err_peer = error(pev, speeds)
    rows = []
    for label, t, cd in (('floquet', t_flo, flo), ('average', t_avg, avg)):
        err = error(cd.exponents, cd.values)
        ratio = t / t_peer
        rows.append(row(
            f'P13-{label}', f'16-state turbine, {len(speeds)} rotor speeds x 36 azimuths '
            '(.lin files)', ours=f"campbell_lin(folder, method='{label}')",
            peer='read_lin + mbc + azimuth average + eigvals per operating point (MBC3)',
            t_ours=t, t_peer=t_peer, metric='slowdown', value=ratio,
            target='<= 3x MBC averaging', target_met=ratio <= 3, err_ours=err,
            err_peer=err_peer, tol=TOL,
            checks={'ours <= tol': err <= TOL, 'peer <= tol': err_peer <= TOL},
            matched=err <= TOL and err_peer <= TOL,
            notes='ours adds tracking by mode shape and labels',
            extra=dict(times=ftimes if label == 'floquet' else atimes, peer_times=ptimes)))
    return rows
