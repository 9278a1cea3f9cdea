"""Traces (JSON Lines, docs/trace.md) as plain records, and as a pandas DataFrame when pandas
is installed (it is optional: nothing else here needs it)."""

from __future__ import annotations

import os
from typing import Any, Dict, Iterator, List, Optional

from . import _core


class TraceError(ValueError):
    """The file is not a valid trace. `errors` lists every problem found, each as
    "FILE:LINE: error: what"; str() is all of them, one per line."""

    def __init__(self, errors: List[str]):
        super().__init__("\n".join(errors))
        self.errors = errors


class Trace:
    """A run's trace: `header` (the first line: mission, fleet, drones) and `events`, every
    other line in file order, each a dict with the fields of docs/trace.md."""

    def __init__(self, header: Dict[str, Any], events: List[Dict[str, Any]]):
        self.header = header
        self.events = events

    @property
    def drones(self) -> List[str]:
        return [d["name"] for d in self.header["drones"]]

    @property
    def outcome(self) -> Optional[str]:
        """"completed" or "failed": the mission's end, the last event."""
        return self.events[-1].get("outcome") if self.events else None

    def of(self, event: str, drone: Optional[str] = None) -> List[Dict[str, Any]]:
        """The events of one kind ("telemetry", "start", "end", ...), of one drone if given."""
        return [e for e in self.events if e.get("event") == event and (drone is None or e.get("drone") == drone)]

    def to_dataframe(self, event: Optional[str] = None):
        """The events (of one kind, if given) as a pandas DataFrame, one row per event, one
        column per field (missing fields are NaN/None). Needs pandas (python3-pandas)."""
        try:
            import pandas
        except ImportError as e:
            raise ImportError("Trace.to_dataframe needs pandas: install python3-pandas "
                              "(the records are in Trace.events without it)") from e
        rows = self.events if event is None else self.of(event)
        return pandas.DataFrame.from_records(rows)

    def __len__(self) -> int:
        return len(self.events)

    def __iter__(self) -> Iterator[Dict[str, Any]]:
        return iter(self.events)

    def __repr__(self) -> str:
        return f"<eamos.Trace {self.header.get('mission', '')!r}: {len(self.events)} events, {self.outcome}>"


def load_trace(path: str | os.PathLike) -> Trace:
    """Reads and checks a trace file; raises TraceError listing every problem when it is not
    one (nothing of a broken file is returned)."""
    raw = _core.read_trace(os.fspath(path))
    if raw["errors"]:
        raise TraceError(list(raw["errors"]))
    return Trace(raw["header"], raw["events"])
