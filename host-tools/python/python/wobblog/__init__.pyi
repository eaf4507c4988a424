"""Type stubs of the wobblog package; host-tools/docs/python.md has the API."""

import os
from typing import Any, Optional, Sequence, Union

from ._wobblog import DamageWarning as DamageWarning
from ._wobblog import Log as Log
from ._wobblog import Scan as Scan
from ._wobblog import Table as Table
from ._wobblog import WobblogError as WobblogError
from ._wobblog import __version__ as __version__
from ._wobblog import open as open
from ._wobblog import scan as scan
from ._wobblog import summary as summary

_Path = Union[str, "os.PathLike[str]"]

class Margin(dict[str, Any]):
    """The report of ``wobblog margin --json``; keys are also attributes."""

    wobble_speed_mps: Optional[float]
    ci95_mps: list[Optional[float]]
    ride_below_mps: Optional[float]
    next_pass_max_mps: Optional[float]
    kicks_used: int
    kicks_rejected: int
    method: str
    trend: str
    coefficients: Optional[list[float]]
    warnings: list[str]
    kicks: list[dict[str, Any]]
    def __getattr__(self, name: str) -> Any: ...

def margin(
    paths_or_dirs: Union[_Path, Sequence[_Path]],
    model: Optional[_Path] = None,
    kicks: str = "best",
    trend: str = "line",
    ride_margin_pct: float = 10.0,
    params: Optional[Sequence[str]] = None,
) -> Margin:
    """The wobble speed predicted from the kicks of a campaign below it (m/s),
    with its 95 % interval, as ``wobblog margin --json``."""

def episodes(
    steer_deg: Any, speed_mps: Any, rate_hz: float = 100.0, t_s: Optional[Any] = None
) -> dict[str, Any]:
    """Wobble episodes in 100 Hz samples from any source (``steer_deg`` deg,
    ``speed_mps`` m/s, ``t_s`` s), as ``wobblog wobble --json``."""

def kicks(
    steer_deg: Any,
    speed_mps: Any,
    rate_hz: float = 100.0,
    t_s: Optional[Any] = None,
    wheel_circumference_m: Optional[float] = None,
) -> list[dict[str, Any]]:
    """Kick ring-downs in 100 Hz samples from any source, as ``Log.kicks(kicks="host")``."""
