"""Type stubs of the native module; host-tools/docs/python.md has the API."""

import os
from pathlib import Path
from datetime import datetime
from typing import Any, BinaryIO, Optional, Sequence, Union

_Time = Union[float, int, datetime]
_Path = Union[str, "os.PathLike[str]"]

__version__: str

class WobblogError(Exception):
    """A log, parameter file or argument that wobblog cannot use; the message
    names the file and the cause, as the CLI's."""

class DamageWarning(UserWarning):
    """A log lost data (blocks, frames, bytes); what survived is still returned."""

class Table:
    """Decoded data as Arrow record batches, read through the Arrow PyCapsule
    stream interface: ``polars.DataFrame(t)``, ``pyarrow.table(t)``,
    ``duckdb.sql("select * from t")``."""

    @property
    def num_rows(self) -> int: ...
    @property
    def column_names(self) -> list[str]:
        """Column names in order, units in the names (``steer_deg``, ``speed_mps``)."""
    def __len__(self) -> int: ...
    def __arrow_c_stream__(self, requested_schema: Optional[object] = None) -> object:
        """A PyCapsule ``arrow_array_stream`` of the table's batches (no copy)."""
    def __arrow_c_schema__(self) -> object:
        """A PyCapsule ``arrow_schema`` of the table's columns."""
    def to_polars(self) -> Any:
        """The table as a ``polars.DataFrame`` (needs polars)."""
    def to_arrow(self) -> Any:
        """The table as a ``pyarrow.Table`` (needs pyarrow)."""
    def to_pandas(self) -> Any:
        """The table as a ``pandas.DataFrame`` (needs pandas and pyarrow)."""

class Log:
    """A card log, read once on opening; its losses are ``DamageWarning``s."""

    @property
    def path(self) -> Path: ...
    @property
    def info(self) -> dict[str, Any]:
        """The keys and values of ``wobblog info --json`` (times in s, speeds in m/s)."""
    @property
    def config(self) -> dict[str, str]:
        """The configuration the log was recorded with (``CONFIG.TXT`` keys), values as text."""
    @property
    def damage(self) -> dict[str, Any]:
        """The loss counters of ``info`` and ``losses`` (every lost stretch)."""
    def frames(
        self,
        columns: Optional[Sequence[str]] = None,
        start: Optional[_Time] = None,
        end: Optional[_Time] = None,
    ) -> Table:
        """The decoded 100 Hz frames in ``wobblog decode``'s columns (units in the
        names: ``t_s`` s since boot, ``steer_deg`` deg, ``speed_mps`` m/s, ``utc`` a
        UTC timestamp), from ``start`` to ``end`` inclusive: seconds since boot, or
        timezone-aware datetimes (UTC). Taken from the frames decoded on opening,
        without a copy."""
    def events(self) -> list[dict[str, Any]]:
        """Alerts, markers, faults, dropouts and damage in time order, as
        ``wobblog events --json`` (``t_s`` s since boot)."""
    def episodes(
        self, start: Optional[_Time] = None, end: Optional[_Time] = None
    ) -> dict[str, Any]:
        """Wobble episodes and the weave's kick ring-downs with onset in the window,
        as ``wobblog wobble --json``: ``wobble_speed_mps`` (m/s) and ``episodes``
        (``mode`` ``wobble`` or ``weave``, ``freq_hz``, ``sigma_per_s`` 1/s,
        ``speed_at_onset_mps`` m/s, ...)."""
    def kicks(self, kicks: str = "best") -> list[dict[str, Any]]:
        """Kick ring-downs as the rows of ``wobblog margin --json`` (``speed_mps``
        m/s, ``freq_hz`` Hz, ``sigma_per_s`` 1/s); ``kicks``: best, card or host."""
    def roll(self) -> Table:
        """``t_s`` (s since boot) and ``roll_deg`` (deg, positive leaning right),
        the roll estimate ``wobblog plot`` draws, one row per frame."""

class Scan:
    """The frames of every log of a card or folder of cards, then ``run`` (and
    ``card``): one Arrow stream, each log decoded when the reader gets to it."""

    @property
    def logs(self) -> list[Path]: ...
    @property
    def column_names(self) -> list[str]: ...
    def __arrow_c_stream__(self, requested_schema: Optional[object] = None) -> object: ...
    def to_polars(self) -> Any: ...
    def to_arrow(self) -> Any: ...
    def lazy(self) -> Any:
        """The frames as a ``polars.LazyFrame`` (needs polars): each log is decoded
        when the query reaches it, and the query's columns, filter and row limit
        are applied to its frames before the next log is read."""

def scan(
    dir: _Path,
    columns: Optional[Sequence[str]] = None,
    start: Optional[_Time] = None,
    end: Optional[_Time] = None,
) -> Scan:
    """Every log of a card (``RUNnnnnn.WBL`` at its top) or a folder of cards as
    one table: ``Log.frames()``'s columns, then ``run`` and, for cards, ``card``
    (the columns of ``wobblog export``'s frames dataset, whose files put ``run``
    first)."""

def summary(dir: _Path) -> list[dict[str, Any]]:
    """One row per run, as ``wobblog summary --json`` (``duration_s`` s,
    ``distance_m`` m, ``max_speed_mps`` and ``wobble_speed_mps`` m/s, ...)."""

def open(source: Union[_Path, BinaryIO]) -> Log:
    """Opens a card log (``RUNnnnnn.WBL``), warning (``DamageWarning``) of what it lost.
    ``source``: a path, ``"-"`` for standard input, or a binary stream (an object
    with ``read``: ``sys.stdin.buffer``, a pipe, ``io.BytesIO``, a file opened
    with ``"rb"``), which is copied to an unnamed temporary file first, as the
    command line copies a pipe. The log is decoded once, here: its summary and
    its frames, which the ``Log`` keeps for ``frames()``."""

def margin(
    inputs: Sequence[_Path],
    model: Optional[_Path] = None,
    kicks: str = "best",
    trend: str = "line",
    ride_margin_pct: float = 10.0,
    params: Optional[Sequence[str]] = None,
) -> dict[str, Any]: ...
