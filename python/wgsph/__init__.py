"""wgsph: GPU smoothed-particle hydrodynamics (wgpu/WGSL) from Python.

Cases, runs and their results as NumPy arrays, through the same engine as the ``wgsph``
command (docs/python.md)::

    import wgsph
    case = wgsph.Case.load("cases/dam_break_2d.toml")
    case.set("time.end_s", 0.2)
    run = wgsph.run(case, out="out/db")
    t, front = run.probe("front")
"""

from ._wgsph import (
    Case,
    CaseError,
    Run,
    RunStopped,
    WgsphError,
    __version__,
    bench,
    resume,
    run,
    validate,
)

__all__ = [
    "Case",
    "CaseError",
    "Run",
    "RunStopped",
    "WgsphError",
    "__version__",
    "bench",
    "resume",
    "run",
    "validate",
]
