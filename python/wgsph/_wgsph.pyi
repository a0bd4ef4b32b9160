"""Typed stubs of the compiled module wgsph._wgsph (re-exported by ``wgsph``)."""

from os import PathLike
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

_Path = Union[str, "PathLike[str]"]
_Value = Union[bool, int, float, str, Sequence[Any]]

class CaseError(ValueError):
    """A case file, or a value given to ``Case.set``, is not a valid case.

    The message is the engine's, as ``wgsph run --set`` prints it: the file, the line, the
    field's dotted path, what is wrong and the fix.
    """

class WgsphError(RuntimeError):
    """The engine failed: no adapter, a GPU failure, an output folder that cannot be written,
    a run folder that cannot be read."""

class RunStopped(WgsphError):
    """A run stopped before its end (it went unstable, or the GPU failed). Its outputs up to
    then and its last checkpoint are kept: ``Run.open(dir)`` reads them."""

class Case:
    """A case: a case file's text and the overrides set on it, checked by the engine's loader
    on every change (docs/cases.md documents the fields)."""

    @staticmethod
    def load(path: _Path) -> "Case":
        """Loads the case file at ``path``. Raises ``CaseError`` naming the file, line, field
        and fix. Runs of it record the file (and the overrides) in their checkpoints, so
        ``wgsph resume DIR`` on the command line continues them too."""
    @staticmethod
    def from_toml(text: str, file: str = "case.toml") -> "Case":
        """A case from its TOML text; ``file`` is its name in messages, and relative paths in
        the case (meshes, motion series) are read from that file's folder."""
    @staticmethod
    def built_in(name: str) -> "Case":
        """A case built into the package by name (see ``built_in_names``), e.g.
        ``"dam_break_2d"``: works from any folder."""
    @staticmethod
    def built_in_names() -> List[str]:
        """The names ``built_in`` takes."""
    def set(self, field: str, value: _Value) -> None:
        """Sets a field as ``--set FIELD=VALUE`` does, e.g. ``case.set("particles.dx_m",
        0.005)``; list entries by index, ``case.set("probe[0].point_m", [0.5, 0.1])``. A str
        is passed as written (a TOML value, else a bare string, as on the command line);
        numbers, bools and lists as TOML. The case is checked again; on an error
        (``CaseError``) it is left unchanged."""
    def copy(self) -> "Case":
        """A copy, to set fields on without changing this one."""
    def to_toml(self) -> str:
        """The case's TOML: the file's text when nothing is set, else its document with the
        overrides applied (comments are then lost)."""
    @property
    def name(self) -> str:
        """The case's name: its ``name`` field, else the file's stem."""
    @property
    def dimension(self) -> int:
        """2 or 3."""
    @property
    def end_s(self) -> float:
        """``time.end_s``, s."""
    @property
    def file(self) -> str:
        """The file's name in messages."""
    @property
    def overrides(self) -> List[str]:
        """The fields set, as ``FIELD=VALUE`` strings."""
    @property
    def particles(self) -> Dict[str, int]:
        """Particle counts: ``fluid``, ``boundary``, ``solid``, ``inlet``."""

class Run:
    """A run folder and its outputs, read with the engine's own readers."""

    @staticmethod
    def open(dir: _Path) -> "Run":
        """Opens a run folder (``wgsph run --out DIR`` or ``wgsph.run(out=DIR)``)."""
    @property
    def dir(self) -> str:
        """The run's folder."""
    @property
    def summary(self) -> Optional[Dict[str, Any]]:
        """``run.json`` as a dict; None while the run has not ended (or was killed)."""
    @property
    def status(self) -> Optional[str]:
        """``run.json``'s status: ``"completed"``, ``"interrupted ..."``, ``"stopped: ..."``;
        None without run.json."""
    @property
    def interrupted_at_s(self) -> Optional[float]:
        """The checkpoint's simulated time, when this call stopped the run early."""
    @property
    def already_complete(self) -> bool:
        """True when ``resume`` found the run complete and computed nothing."""
    @property
    def outputs(self) -> int:
        """The number of particle outputs."""
    def probes(self) -> List[str]:
        """Every probe name: the probe CSVs' stems, and ``table.column`` for each column of
        a body's or tracked point's table (``body_box.y_m``)."""
    def probe(self, name: str) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """``(t, values)`` of a probe (or ``table.column``), float64; NaN where it had no
        value. ``KeyError`` names the probes there are."""
    def maps(self) -> List[str]:
        """The flood maps' names (``maps/<name>.asc``: ``max_depth_m``, ``arrival_s``, …),
        sorted; empty for a case without ``[maps]``."""
    def map(self, name: str) -> Dict[str, npt.NDArray[np.float64]]:
        """A flood map: ``values`` (rows × columns, row 0 the southernmost, NaN where the map
        has no value: a cell never wet), ``x`` and ``y`` (the cells' centres, world
        coordinates). ``KeyError`` names the maps there are."""
    def table(self, name: str) -> Dict[str, npt.NDArray[np.float64]]:
        """``probes/<name>.csv`` (``body_<body>``, ``point_<point>``) as a dict of float64
        arrays, time ``t_s`` first."""
    def body(self, name: str) -> Dict[str, npt.NDArray[np.float64]]:
        """A body's table, ``probes/body_<name>.csv``: t_s, position, angle, velocity, force,
        torque columns (docs/cases.md, "Bodies")."""
    def point(self, name: str) -> Dict[str, npt.NDArray[np.float64]]:
        """A tracked point's table, ``probes/point_<name>.csv``."""
    def particles(self, i: int = -1, complete: bool = False) -> Dict[str, Any]:
        """Particle output ``i`` (negative from the end): ``position`` (n, 3) float64,
        ``velocity`` (n, 3) float32, ``density``, ``pressure`` float32, ``kind``, ``id``
        uint32 (kind 0 fluid, 15 excluded), the extra fields the run writes (``energy``,
        ``tau_xx`` ...) and ``time_s`` (a float). With ``complete``, an output that left out
        unmoved walls (``time.output_boundary = "first"``) gets them from the first output.
        """

def run(
    case: Case,
    out: Optional[_Path] = None,
    *,
    adapter: Optional[str] = None,
    snapshots: bool = False,
    progress: bool = True,
    checkpoint_every: Optional[str] = None,
    snapshot_field: Optional[str] = None,
) -> Run:
    """Runs ``case`` to its end into ``out`` (default ``out/<case name>``), as ``wgsph run``.

    Blocks with the GIL released. ``adapter``: ``"auto"``, ``"gpu"`` or ``"cpu"`` (default:
    ``$WGSPH_ADAPTER``, else auto). ``checkpoint_every``: ``"0.5"`` simulated s, ``"10min"``,
    ``"never"`` (default 30 wall minutes). ``progress``: a bar on a terminal, else a log line
    about every 10 s; False shows only warnings.

    Ctrl-C writes a checkpoint at the next probe time, stops, and then raises
    ``KeyboardInterrupt`` saying where the checkpoint is (``resume`` continues); a second
    Ctrl-C stops waiting at once. Raises ``RunStopped`` when the run goes unstable or the GPU
    fails, ``WgsphError`` for other failures.
    """

def resume(
    dir: _Path,
    set: Optional[Mapping[str, _Value]] = None,
    *,
    case: Optional[Case] = None,
    adapter: Optional[str] = None,
    progress: bool = True,
    checkpoint_every: Optional[str] = None,
) -> Run:
    """Continues the run in ``dir`` from its checkpoint, as ``wgsph resume``; ``set`` changes
    its time control (``{"time.end_s": 2.0}``). ``case`` is needed only for a run whose
    checkpoint records no case file (a case given as text or built in). Ctrl-C as for ``run``.
    """

def bench(
    case: Case,
    steps: int = 200,
    warmup: int = 20,
    *,
    adapter: Optional[str] = None,
    stages: bool = False,
) -> Dict[str, Any]:
    """Times ``steps`` steps after ``warmup``, as ``wgsph bench``: particle_steps_per_s,
    simulated_s_per_wall_s, neighbours per particle, ...; with ``stages``, each stage's GPU
    time as (name, seconds) pairs (needs timestamp queries); for a case with ``[maps]``,
    ``map_sample_s``, the wall time of one flood-map sample (else None)."""

def validate(
    out: _Path,
    *,
    mode: str = "quick",
    cases: Sequence[str] = (),
    reuse: bool = False,
    adapter: Optional[str] = None,
    progress: bool = True,
) -> Dict[str, Any]:
    """Runs the validation cases and writes ``out/report.md``, as ``wgsph validate``.
    Returns ``passed``, ``exit_status``, ``report`` (its path), ``table`` and ``rows`` (dicts:
    case, metric, error, bound, result). Ctrl-C stops waiting; the cases cannot stop early."""
