"""Shared helpers of the benchmark suite: timing, result rows, table."""

import math
import os
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
for _path in (ROOT, os.path.join(ROOT, 'tests')):
    if _path not in sys.path:
        sys.path.insert(0, _path)


#: Clock of every timing: CPU time of this process by default (robust on a
#: shared machine, where other jobs inflate the wall time of whichever side
#: happens to run during a burst); ``run.py --wall`` switches to wall time.
CLOCK = {'name': 'process_time', 'fn': time.process_time}


def use_wall_clock():
    CLOCK.update(name='perf_counter', fn=time.perf_counter)


def timed(fn, *args, **kwargs):
    """Run ``fn`` once; return ``(seconds, result)`` on the suite clock."""
    clock = CLOCK['fn']
    t0 = clock()
    out = fn(*args, **kwargs)
    return clock() - t0, out


def median_time(fn, repeats, setup=None):
    """Median time of ``fn(setup())`` over `repeats` runs (setup untimed).

    Returns ``(median, times, last_result)``.
    """
    clock = CLOCK['fn']
    times, out = [], None
    for _ in range(repeats):
        arg = setup() if setup is not None else None
        t0 = clock()
        out = fn(arg) if setup is not None else fn()
        times.append(clock() - t0)
    return float(np.median(times)), [float(x) for x in times], out


def loglog_slope(x, y):
    """Least-squares slope of log(y) against log(x)."""
    return float(np.polyfit(np.log(np.asarray(x, float)), np.log(np.asarray(y, float)), 1)[0])


def row(rid, workload, *, ours, peer=None, t_ours=None, t_peer=None, metric='ratio',
        value=None, target=None, target_met=None, err_ours=None, err_peer=None,
        tol=None, checks=None, matched=None, notes='', extra=None, status='ok'):
    """One result of the suite (a plain dict, written to the JSON file as is).

    ``checks`` maps the name of every accuracy check to its outcome; the
    suite passes when all of them are True.  ``matched`` tells whether both
    sides reached the accuracy `tol`; a ratio is only claimed when they did.
    """
    if metric == 'ratio' and value is None and t_ours and t_peer:
        value = t_peer / t_ours
    return {
        'id': rid, 'workload': workload, 'ours': ours, 'peer': peer,
        't_ours': _num(t_ours), 't_peer': _num(t_peer), 'metric': metric,
        'value': _num(value), 'target': target, 'target_met': _bool(target_met),
        'err_ours': _num(err_ours), 'err_peer': _num(err_peer), 'tol': _num(tol),
        'checks': {k: bool(v) for k, v in (checks or {}).items()},
        'matched': _bool(matched), 'notes': notes, 'extra': extra or {}, 'status': status,
    }


def not_available(rid, workload, reason):
    """Row for a workload whose library function does not exist (yet)."""
    return row(rid, workload, ours='-', status='not available', notes=reason)


def _bool(x):
    return None if x is None else bool(x)


def jsonable(obj):
    """`json.dump` default for numpy scalars and arrays."""
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, np.generic):
        return obj.item()
    raise TypeError(f"not JSON serializable: {type(obj).__name__}")


def _num(x):
    if x is None:
        return None
    x = float(x)
    return x if math.isfinite(x) else None        # JSON has no inf/nan


def fmt_time(x):
    if x is None:
        return '-'
    if x >= 100:
        return f"{x:.0f}"
    if x >= 1:
        return f"{x:.2f}"
    if x >= 1e-3:
        return f"{x * 1e3:.1f}m"
    return f"{x * 1e6:.0f}u"


def fmt_err(x):
    if x is None:
        return 'lost'
    return f"{x:.0e}" if x > 0 else '0'


def table(rows):
    """Plain-text table of the rows."""
    head = ['id', 'workload', 'ours s', 'peer s', 'result', 'target', 'met',
            'accuracy ours | peer (tol)', 'checks']
    lines = []
    for r in rows:
        if r['status'] != 'ok':
            lines.append([r['id'], r['workload'], '-', '-', r['status'], r['target'] or '-',
                          '-', '-', '-'])
            continue
        if r['metric'] == 'ratio':
            result = '-' if r['value'] is None else f"{r['value']:.3g}x"
            if r['matched'] is False:
                result += '*'
        else:
            result = f"{r['metric']} {r['value']:.3g}"
        met = {True: 'yes', False: 'NO', None: '-'}[r['target_met']]
        if r['err_ours'] is None and r['tol'] is None:
            acc = '-'
        else:
            acc = fmt_err(r['err_ours'])
            if r['peer'] is not None and r['metric'] == 'ratio':
                acc += ' | ' + fmt_err(r['err_peer'])
            if r['tol'] is not None:
                acc += f" ({r['tol']:.0e})"
        checks = r['checks']
        ok = ('pass' if all(checks.values()) else 'FAIL') if checks else '-'
        lines.append([r['id'], r['workload'], fmt_time(r['t_ours']), fmt_time(r['t_peer']),
                      result, r['target'] or '-', met, acc, ok])
    widths = [max(len(str(x)) for x in col) for col in zip(head, *lines)]
    out = ['  '.join(str(x).ljust(w) for x, w in zip(head, widths))]
    out.append('  '.join('-' * w for w in widths))
    out += ['  '.join(str(x).ljust(w) for x, w in zip(line, widths)) for line in lines]
    return '\n'.join(out)
