"""Type stubs of wobblog.model; host-tools/docs/python.md has the API."""

import os
from pathlib import Path
from typing import Any, Optional, Sequence, Union

from ._wobblog import Table

_Speeds = Union[str, Sequence[float]]

class Model:
    """A bicycle model: a parameter file's values and the model built of them."""

    @property
    def path(self) -> Path: ...
    @property
    def variant(self) -> str:
        """``own``, ``whipple`` or ``no-slip``."""
    @property
    def params(self) -> dict[str, float]:
        """Every parameter's value in its file's unit (see ``units``)."""
    @property
    def units(self) -> dict[str, str]: ...
    @property
    def state_names(self) -> list[str]: ...
    def with_params(self, values: dict[str, float]) -> "Model":
        """A copy with these parameters changed (values in the file's units)."""
    def state_matrix(self, speed_mps: float) -> Any:
        """The state matrix A at this speed (m/s), a NumPy array."""
    def eig(self, speeds: Optional[_Speeds] = None) -> Table:
        """Eigenvalues by mode: ``speed_mps``, ``mode``, ``re_per_s`` (1/s),
        ``im_rad_per_s`` (rad/s); speeds ``"FROM:TO:STEP"`` (m/s) or a sequence,
        default ``"0:10:0.1"``."""
    def critical_speeds(self, speeds: Optional[_Speeds] = None) -> list[dict[str, Any]]:
        """Critical speeds (m/s) by mode, with the side that is unstable."""

def load(path: Union[str, "os.PathLike[str]"], variant: str = "own") -> Model:
    """Reads a parameter file (TOML or BicycleParameters ``*Benchmark.txt``)."""
