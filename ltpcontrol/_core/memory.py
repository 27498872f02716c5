"""A clear error before an allocation that cannot fit.

Large models (hundreds of states, thousands of steps) can ask for arrays
larger than the machine's memory.  `check_allocation` compares the size
of a planned array with the memory available and raises a `MemoryError`
naming the array, its shape and its size before NumPy tries (and, on
some systems, swaps for minutes first).
"""

import os

__all__ = []


def available_memory():
    """Bytes of memory available to the process (None when unknown).

    Examples
    --------
    >>> from ltpcontrol._core.memory import available_memory
    >>> m = available_memory()
    >>> m is None or m > 0
    True
    """
    try:
        with open('/proc/meminfo') as f:
            for line in f:
                if line.startswith('MemAvailable:'):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    try:
        return os.sysconf('SC_AVPHYS_PAGES') * os.sysconf('SC_PAGE_SIZE')
    except (ValueError, OSError, AttributeError):
        return None


def check_allocation(shape, what, itemsize=8, copies=1):
    """Raise MemoryError when `copies` arrays of `shape` exceed the available memory.

    Parameters
    ----------
    shape : tuple of int
    what : str
        What the array holds (named in the error).
    itemsize : int
        Bytes per entry (8: float64).
    copies : int
        Arrays of that size alive at once.

    Examples
    --------
    >>> from ltpcontrol._core.memory import check_allocation
    >>> check_allocation((10, 4, 4), 'step factors')
    >>> check_allocation((10 ** 9, 300, 300), 'step factors')  # doctest: +ELLIPSIS
    Traceback (most recent call last):
        ...
    MemoryError: step factors need an array of shape (1000000000, 300, 300) (720000.0 GB) but only ...
    """
    nbytes = float(itemsize) * copies
    for s in shape:
        nbytes *= int(s)
    avail = available_memory()
    if avail is not None and nbytes > avail:
        count = f"{copies} arrays" if copies > 1 else "an array"
        raise MemoryError(
            f"{what} need {count} of shape {tuple(int(s) for s in shape)} "
            f"({nbytes / 1e9:.1f} GB) but only {avail / 1e9:.1f} GB are available")
