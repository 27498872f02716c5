"""Functions that a class's methods alias, registered by the modules that define them.

python-control's functions call a system's own methods (``ct.zeros(sys)``
calls ``sys.zeros()``, ``ct.sample_system`` calls ``sys.sample``,
``ct.poles`` calls ``sys.poles()``), so `LTPStateSpace` offers methods
that alias public functions: ``sys.monodromy()`` is ``ltp.monodromy(sys)``,
``sys.htf(K)`` is ``ltp.htf(sys, K)``, ``sys.zeros()`` is
``ltp.zeros(sys)``.  Those functions live in modules that import the
system class (some in higher layers), so the class cannot import them
without an import cycle.  Instead each such function is decorated with
`method_alias` where it is defined, which records it here when its module
is imported (``import ltpcontrol`` imports them all), and the method looks
it up with `aliased`.  The import graph stays acyclic and points down the
layers; the registry is the one place where a lower layer reaches a higher
one, and it holds only functions, never state.
"""

__all__ = []

_FUNCTIONS = {}


def method_alias(func):
    """Register `func` under its name as the function behind a method alias.

    Returns `func` unchanged, so it decorates the definition.

    Examples
    --------
    >>> from ltpcontrol._core.registry import aliased, method_alias
    >>> method_alias(ltp.zeros) is ltp.zeros is aliased('zeros')
    True
    """
    name = func.__name__
    if _FUNCTIONS.get(name, func) is not func:
        raise RuntimeError(f"two functions named {name!r} are registered as method aliases")
    _FUNCTIONS[name] = func
    return func


def aliased(name):
    """The function registered under `name` by `method_alias`.

    Examples
    --------
    >>> from ltpcontrol._core.registry import aliased
    >>> aliased('monodromy') is ltp.monodromy
    True
    >>> aliased('no_such_function')
    Traceback (most recent call last):
    ...
    LookupError: ltpcontrol provides no function 'no_such_function' behind a method; import ltpcontrol to load them all
    """
    try:
        return _FUNCTIONS[name]
    except KeyError:
        raise LookupError(f"ltpcontrol provides no function {name!r} behind a method; "
                          "import ltpcontrol to load them all") from None


def registered():
    """Names of the registered functions (sorted).

    Examples
    --------
    >>> from ltpcontrol._core.registry import registered
    >>> 'zeros' in registered()
    True
    """
    return sorted(_FUNCTIONS)


# -- implementations of public functions for system classes of higher layers --
_OVERRIDES = {}


def override(name, cls):
    """Register the decorated function as public function `name`'s implementation for `cls`.

    A public function of a lower layer (``floquet_multipliers``,
    ``forced_response``, ``series``...) begins with ``if (own :=
    overridden(name, sys)) is not None: return own(...)``, so that a
    system class of a higher layer (systems with delays) gets its own
    algorithm without the lower layer importing it.

    Examples
    --------
    >>> from ltpcontrol._core.registry import overridden
    >>> overridden('floquet_multipliers', ltp.ltpdss([[-1.0]], [[1.0]], [[1.0]], 0,
    ...            period=1.0, delays=[(0.5, [[0.1]])])) is not None
    True
    """
    def register(func):
        _OVERRIDES.setdefault(name, []).append((cls, func))
        return func
    return register


def overridden(name, *objs):
    """The function registered by `override` for `name` and the class of one of `objs`, or None.

    Examples
    --------
    >>> from ltpcontrol._core.registry import overridden
    >>> overridden('floquet_multipliers', 1.0) is None
    True
    """
    for cls, func in _OVERRIDES.get(name, ()):
        if any(isinstance(obj, cls) for obj in objs):
            return func
    return None
