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
from ._wobblog import episodes as _episodes
from ._wobblog import kicks as _kicks
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


def _floats(name, values):
    """``values`` (a NumPy array, a Polars or pandas Series, a pyarrow array
    or column, a list) as a list of floats; a missing value is refused."""
    if values is None:
        return None
    for to_list in ("to_pylist", "to_list", "tolist"):
        if hasattr(values, to_list):
            values = getattr(values, to_list)()
            break
    out = []
    for i, v in enumerate(values):
        if v is None:
            raise WobblogError(f"{name}[{i}] is missing (null): drop or fill such samples first")
        out.append(float(v))
    return out


def episodes(steer_deg, speed_mps, rate_hz=100.0, t_s=None):
    """Wobble episodes in samples from any source, measured as for a log.

    ``steer_deg``: steering angle, degrees; ``speed_mps``: speed, m/s; one
    sample per frame at the logger's 100 Hz (``rate_hz`` must be 100:
    resample other data first). ``t_s``: the samples' times, s, increasing by
    0.01 s (a longer step is a gap); by default ``i / rate_hz``. NumPy arrays,
    Polars or pandas Series, pyarrow arrays or lists. Returns the dict of
    ``wobblog wobble --json`` (``log`` is ``"<arrays>"``).
    """
    return _episodes(_floats("steer_deg", steer_deg), _floats("speed_mps", speed_mps),
                     rate_hz, _floats("t_s", t_s))


def kicks(steer_deg, speed_mps, rate_hz=100.0, t_s=None, wheel_circumference_m=None):
    """Kick ring-downs in samples from any source, as ``Log.kicks(kicks="host")``.

    Arguments as :func:`episodes`; ``wheel_circumference_m``: the wheel the
    speed was measured with, m (the logger's default when not given).
    """
    return _kicks(_floats("steer_deg", steer_deg), _floats("speed_mps", speed_mps),
                  rate_hz, _floats("t_s", t_s), wheel_circumference_m)


__all__ = [
    "DamageWarning",
    "Log",
    "Margin",
    "Scan",
    "Table",
    "WobblogError",
    "__version__",
    "episodes",
    "kicks",
    "margin",
    "open",
    "scan",
    "summary",
]
