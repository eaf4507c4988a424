"""Wobble-logger card logs, their analyses and the bicycle model, in Python.

The numbers are those of the ``wobblog`` command line: the package calls the
same Rust library. Frames come as Arrow tables that Polars, pyarrow, pandas
and DuckDB read without a copy (the Arrow PyCapsule stream interface).
"""

from ._wobblog import (
    DamageWarning,
    Log,
    Scan,
    Table,
    WobblogError,
    __version__,
    open,
    scan,
    summary,
)
from ._wobblog import margin as _margin


class Margin(dict):
    """The report of ``wobblog margin --json``: a dict whose keys are also
    attributes (``m.wobble_speed_mps``, ``m.ci95_mps``, ``m.kicks``, ...)."""

    def __getattr__(self, name):
        try:
            return self[name]
        except KeyError:
            raise AttributeError(name) from None


def margin(paths_or_dirs, model=None, kicks="best", trend="line",
           ride_margin_pct=10.0, params=None):
    """Predicts the wobble speed from the kicks of a campaign below it.

    ``paths_or_dirs``: a log, a directory of ``*.WBL`` logs, or a list of
    them. ``model``: a parameter file (TOML or ``*Benchmark.txt``) whose
    wobble model is also fitted to the kicks (``params``: the keys fitted).
    ``kicks``: ``"best"``, ``"card"`` or ``"host"``; ``trend``: ``"line"`` or
    ``"quadratic"``; ``ride_margin_pct``: per cent below the lower bound.
    Returns a :class:`Margin` (speeds in m/s, damping in 1/s).
    """
    if isinstance(paths_or_dirs, (str, bytes)) or hasattr(paths_or_dirs, "__fspath__"):
        paths_or_dirs = [paths_or_dirs]
    return Margin(_margin(list(paths_or_dirs), model, kicks, trend,
                          ride_margin_pct, params))


__all__ = [
    "DamageWarning",
    "Log",
    "Margin",
    "Scan",
    "Table",
    "WobblogError",
    "__version__",
    "margin",
    "open",
    "scan",
    "summary",
]
