"""eamos for Python: compile a mission, read its graphs, fly it in the simulator, read traces.

    import eamos
    mission = eamos.compile("examples/listing2.eamos")
    for d in mission.diagnostics:
        print(d.file, d.line, d.column, d.severity, d.message)
    result = mission.run(on_event=print)
    trace = eamos.load_trace("run.jsonl")

docs/python.md describes every call.
"""

from __future__ import annotations

import os
import warnings
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any, Callable, Dict, List, Optional

from . import _core
from ._trace import Trace, TraceError, load_trace

__version__ = _core.__version__

__all__ = [
    "CompileError", "Compilation", "Diagnostic", "DroneRun", "Failure", "RunResult", "Trace", "TraceError",
    "compile", "compile_text", "load_trace", "run", "__version__",
]


class CompileError(Exception):
    """The mission did not compile. `diagnostics` lists every problem; str() is the
    compiler's text, as `eamos check` prints it."""

    def __init__(self, text: str, diagnostics: List["Diagnostic"]):
        super().__init__(text)
        self.diagnostics = diagnostics


@dataclass(frozen=True)
class Diagnostic:
    """An error, warning or note of the compiler. `line` and `column` are 1-based (0: not tied
    to a place in a file, and `file` is None when not tied to a file); `text` is the diagnostic
    as `eamos check` prints it, with the source line and a caret."""

    file: Optional[str]
    line: int
    column: int
    severity: str  # "error", "warning" or "note"
    message: str
    text: str

    def __str__(self) -> str:
        return self.text


class Compilation:
    """The result of eamos.compile / eamos.compile_text: diagnostics always; when `ok`, the
    graphs as plain Python data (the JSON of `eamos graph --format json`)."""

    def __init__(self, core: "_core.CompiledMission"):
        self._core = core

    @property
    def ok(self) -> bool:
        """True when the mission compiled (warnings allowed)."""
        return self._core.ok

    @cached_property
    def diagnostics(self) -> List[Diagnostic]:
        return [Diagnostic(**d) for d in self._core.diagnostics()]

    @property
    def errors(self) -> List[Diagnostic]:
        return [d for d in self.diagnostics if d.severity == "error"]

    @property
    def warnings(self) -> List[Diagnostic]:
        return [d for d in self.diagnostics if d.severity == "warning"]

    @property
    def text(self) -> str:
        """Every diagnostic as `eamos check` prints them."""
        return self._core.formatted()

    def check(self) -> "Compilation":
        """Raises CompileError when the mission did not compile; returns self otherwise."""
        if not self.ok:
            raise CompileError(self.text, self.diagnostics)
        return self

    @cached_property
    def drones(self) -> List[str]:
        """The drones in declaration order (the fleet order of traces and mission files)."""
        return self.check()._core.drones()

    @cached_property
    def amt(self) -> Dict[str, Any]:
        """The Abstract Mission Tree: {"nodes": [...]} (docs/architecture.md)."""
        return self.check()._core.amt()

    @cached_property
    def meg(self) -> Dict[str, Any]:
        """The Mission Execution Graph: {"nodes": [...], "arcs": [...]}."""
        return self.check()._core.meg()

    @cached_property
    def mdgs(self) -> Dict[str, Dict[str, Any]]:
        """Each drone's Mission Dependency Graph, by drone name."""
        return {name: self._core.mdg(i) for i, name in enumerate(self.drones)}

    def mdg(self, drone: str | int) -> Dict[str, Any]:
        """One drone's MDG, by name or index."""
        return self.mdgs[self._drone_name(drone)]

    def stats(self) -> Dict[str, Any]:
        """Nodes and arcs per graph and per drone (`eamos stats`)."""
        return self.check()._core.stats()

    def mission_file(self, drone: str | int) -> Dict[str, Any]:
        """The mission file a drone's DEX runs (`eamos compile`'s DIR/<drone>/mission.json)."""
        return self._core.mission_file(self.drones.index(self._drone_name(drone)))

    def run(self, on_event: Optional[Callable[[Dict[str, Any]], None]] = None, *, time_limit: float = 3600.0,
            telemetry_hz: float = 5.0, speed: Optional[float] = None,
            trace: Optional[str | os.PathLike] = None, tracks: bool = True) -> "RunResult":
        """Flies the mission in the built-in simulator, as `eamos run` does.

        on_event: called with each trace event (a dict with the fields of docs/trace.md) as it
        happens; if it raises, every drone runs its failsafe and the exception is raised here.
        time_limit: mission seconds after which a mission still running fails.
        telemetry_hz: telemetry events per mission second (0: none).
        speed: None flies on virtual time (as fast as the machine goes); a number flies in real
        time at that factor (needed for drones on the mavlink adapter).
        trace: also write the trace (JSON Lines) to this file, header first, as `--trace` does.
        tracks: keep each drone's whole track in the result (a row per change, 20 per second of
        flight); False keeps its first and last state only (fleets of hundreds of drones).
        """
        self.check()
        raw = _core.run(self._core, on_event, time_limit=float(time_limit), telemetry_hz=float(telemetry_hz),
                        speed=None if speed is None else float(speed),
                        trace=None if trace is None else os.fspath(trace), tracks=bool(tracks))
        result = RunResult._from_core(raw)
        for what in raw["warnings"]:  # eamos run's warnings, in its words (dex::run_warnings)
            warnings.warn(what, RuntimeWarning, stacklevel=2)
        return result

    def _drone_name(self, drone: str | int) -> str:
        if isinstance(drone, int):
            if not 0 <= drone < len(self.drones):
                raise IndexError(f"drone index {drone} is out of range: the mission has {len(self.drones)} drones")
            return self.drones[drone]
        if drone not in self.drones:
            raise KeyError(f"no drone {drone!r} in the mission; its drones are {', '.join(self.drones)}")
        return drone

    def __repr__(self) -> str:
        if self.ok:
            return f"<eamos.Compilation ok: {len(self.drones)} drones, {len(self.warnings)} warnings>"
        return f"<eamos.Compilation failed: {len(self.errors)} errors, {len(self.warnings)} warnings>"


@dataclass(frozen=True)
class Failure:
    """The action whose failure ended the mission."""

    drone: str
    action: str
    line: int
    reason: str
    kind: Optional[str]  # refused, timed_out, link_lost, vehicle_fault, pilot_took_over; None: not an action's
    detail: str          # the vehicle's own words, or ""


@dataclass(frozen=True)
class DroneRun:
    """One drone after the run: its final `state` (x, y, z m; heading deg or None; armed,
    landed, battery %, pictures, mode) and its `track`, columns t, x, y, z, armed, landed,
    battery with one row per change of position or phase."""

    name: str
    final: bool  # False: the final state is not known, `state` is what was last seen
    state: Dict[str, Any]
    track: Dict[str, list] = field(repr=False)


@dataclass(frozen=True)
class RunResult:
    """What a run did: `completed`, `duration` (mission seconds), the `failure` that ended it
    (or None), `error` (the reason in words, "" when completed), each drone's summary, and on
    real time `max_lag`: the most mission seconds an event ran late (0 on virtual time)."""

    completed: bool
    duration: float
    error: str
    failure: Optional[Failure]
    drones: Dict[str, DroneRun]
    activations: int  # node activations over all drones
    max_lag: float = 0.0  # real time: the most mission seconds an event ran late

    @classmethod
    def _from_core(cls, raw: Dict[str, Any]) -> "RunResult":
        failure = Failure(**raw["failure"]) if raw["failure"] else None
        drones = {d["name"]: DroneRun(**d) for d in raw["drones"]}
        return cls(raw["completed"], raw["duration"], raw["error"], failure, drones, raw["activations"],
                   raw["max_lag"])


def compile(path: str | os.PathLike, fleet: Optional[str | os.PathLike] = None) -> Compilation:
    """Compiles the mission file at `path`, with the fleet file `fleet` (YAML) when given.
    Never raises for a bad mission: look at `.ok` and `.diagnostics` (or call `.check()`)."""
    return Compilation(_core.compile_file(os.fspath(path), None if fleet is None else os.fspath(fleet)))


def compile_text(source: str, name: str = "<mission>", fleet: Optional[str | os.PathLike] = None,
                 fleet_text: Optional[str] = None) -> Compilation:
    """Compiles mission text; `name` is the file name diagnostics show. The fleet is a file
    (`fleet`) or YAML text (`fleet_text`), not both."""
    if fleet is not None and fleet_text is not None:
        raise ValueError("give the fleet as a file (fleet=) or as text (fleet_text=), not both")
    return Compilation(_core.compile_text(source, name, None if fleet is None else os.fspath(fleet), fleet_text))


def run(mission: str | os.PathLike | Compilation, fleet: Optional[str | os.PathLike] = None,
        on_event: Optional[Callable[[Dict[str, Any]], None]] = None, **options: Any) -> RunResult:
    """Compiles `mission` (a file, or an existing Compilation) and flies it in the simulator:
    Compilation.run's options. Raises CompileError when it does not compile."""
    if not isinstance(mission, Compilation):
        mission = compile(mission, fleet)
    elif fleet is not None:
        raise ValueError("a Compilation already has its fleet; give fleet= to eamos.compile instead")
    return mission.run(on_event, **options)
