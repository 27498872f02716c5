"""Run the project's checks side by side and report each one's output.

The checks are independent commands (the test suite, the documentation
build, ...); they run in parallel, at most as many at a time as the
machine has cores, longest first; the test suite itself is spread over the
cores by pytest-xdist when it is installed (it is in the ``test`` extra).  Each check's output is printed whole
when it ends, and the script exits non-zero when any check fails.

    python tools/check.py            # every check
    python tools/check.py tests docs # the named checks only
"""

import os
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor, as_completed

PYTHON = sys.executable
BIN = os.path.dirname(PYTHON)


def cores():
    """Cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:                                  # not on Linux
        return os.cpu_count() or 1


def test_command():
    """pytest, spread over the cores by pytest-xdist when it is installed.

    Test files are kept whole on one worker (``--dist loadfile``), so that a
    module's fixtures are computed once; the documentation build shares the
    cores with the workers.
    """
    command = [PYTHON, '-m', 'pytest']
    try:
        import xdist  # noqa: F401
    except ImportError:
        return command
    return command + ['-n', str(cores()), '--dist', 'loadfile']


#: name -> command (started in this order)
CHECKS = {
    'imports': [PYTHON, 'tools/import_graph.py'],
    'tests': test_command(),
    'docs': [os.path.join(BIN, 'sphinx-build'), '-W', '-q', '-b', 'html', 'docs',
             'docs/_build/html'],
}


#: one BLAS thread per check: checks already run side by side on the cores
SINGLE_THREAD = {name: '1' for name in ('OMP_NUM_THREADS', 'OPENBLAS_NUM_THREADS',
                                        'MKL_NUM_THREADS')}


def run(name, command, env):
    """Run one check; its exit code, duration and output."""
    start = time.perf_counter()
    with tempfile.TemporaryFile('w+') as out:
        code = subprocess.call(command, stdout=out, stderr=subprocess.STDOUT, env=env)
        out.seek(0)
        return name, code, time.perf_counter() - start, out.read()


def main(names):
    unknown = sorted(set(names) - set(CHECKS))
    if unknown:
        sys.exit(f"unknown check(s) {unknown}; the checks are {list(CHECKS)}")
    chosen = {n: c for n, c in CHECKS.items() if not names or n in names}
    failed = []
    results = {}
    workers = max(1, min(cores(), len(chosen)))
    env = dict(os.environ, **(SINGLE_THREAD if workers > 1 else {}))
    # the checks start dozens of Python processes (test workers, subprocess
    # tests, parallel jobs, the documentation build) that import the package
    # from its source tree: its bytecode is written once and reused, even where
    # the environment asks Python not to write bytecode (a second per process)
    env.pop('PYTHONDONTWRITEBYTECODE', None)
    with ThreadPoolExecutor(max_workers=workers) as pool:
        jobs = [pool.submit(run, n, c, env) for n, c in chosen.items()]
        for job in as_completed(jobs):
            name, code, seconds, output = job.result()
            results[name] = (code, seconds, output)
            print(f"{name}: {'passed' if code == 0 else f'FAILED (exit {code})'} "
                  f"in {seconds:.0f} s", flush=True)
    # the test suite's output last, so that its closing line ends the log
    for name in sorted(results, key=lambda n: n == 'tests'):
        code, seconds, output = results[name]
        print(f"\n===== {name} ({'passed' if code == 0 else f'FAILED, exit {code}'}, "
              f"{seconds:.0f} s): {' '.join(chosen[name])}")
        print(output, end='' if output.endswith('\n') else '\n', flush=True)
        if code:
            failed.append(name)
    if failed:
        sys.exit(f"failed checks: {', '.join(failed)}")


if __name__ == '__main__':
    main(sys.argv[1:])
