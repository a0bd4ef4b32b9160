#!/usr/bin/env python3
"""Resolution study of the 2D dam break (cases/dam_break_2d.toml) against Martin & Moyce.

Runs the case at three particle spacings, dx = a/n for n particles across the water column
(a = 0.146 m; the shipped case has n = 40), collects each run's surge front (the "front"
probe) and plots, with Matplotlib, the front Z = z/a against T = t*sqrt(2g/a) beside the
experiment, and the RMS error against the experiment over its points at T <= --end-T
against dx: the convergence.

    python examples/python/resolution_study.py                     # n = 10, 20, 40 to T = 3
    python examples/python/resolution_study.py --columns 5 7 10 --end-T 0.6   # seconds

Writes OUT/n<N>/ (each run) and OUT/resolution_study.png. In a notebook, import it and call
``study()`` and ``plot()`` instead (they return the data and the figure).
"""

import argparse
import math
import pathlib

import numpy as np

import wgsph

REPO = pathlib.Path(__file__).resolve().parents[2]
CASE = REPO / "cases" / "dam_break_2d.toml"
# The measured front the validation uses (src/validation/dam_break.rs).
REFERENCE = REPO / "tests" / "data" / "db2d_martin_moyce_1952_front_n2sq2_a2.25in.csv"
COLUMN_WIDTH_M = 0.146
G = 9.81


def t_scale():
    """T per second of simulated time: sqrt(2g/a)."""
    return math.sqrt(2.0 * G / COLUMN_WIDTH_M)


def experiment():
    """(T, Z) of Martin & Moyce's measured front."""
    data = np.loadtxt(REFERENCE, delimiter=",", comments="#", skiprows=4)
    return data[:, 0], data[:, 1]


def study(columns=(10, 20, 40), end_T=3.0, out="out/resolution_study", adapter=None):
    """Runs the case at dx = a/n for each n in `columns` up to T = `end_T`.

    Returns a list of dicts: n, dx_m, T and Z (the front), rms (the RMS error of Z against
    the experiment's points at T <= end_T, interpolated at their T), run (the wgsph.Run).
    """
    T_exp, Z_exp = experiment()
    results = []
    for n in columns:
        case = wgsph.Case.load(CASE)
        dx = COLUMN_WIDTH_M / n
        case.set("particles.dx_m", dx)
        case.set("time.end_s", end_T / t_scale())
        run = wgsph.run(case, out=pathlib.Path(out) / f"n{n}", adapter=adapter)
        t, front = run.probe("front")
        T, Z = t * t_scale(), front / COLUMN_WIDTH_M
        judged = T_exp <= T[-1]
        rms = (
            float(np.sqrt(np.mean((np.interp(T_exp[judged], T, Z) - Z_exp[judged]) ** 2)))
            if judged.any()
            else float("nan")
        )
        results.append({"n": n, "dx_m": dx, "T": T, "Z": Z, "rms": rms, "run": run})
        print(f"n = {n:3d}  dx = {dx:.5f} m  {run.summary['steps']} steps  RMS error {rms:.4f}")
    return results


def plot(results):
    """The fronts beside the experiment, and the error against dx. Returns the figure."""
    import matplotlib.pyplot as plt

    T_exp, Z_exp = experiment()
    fig, (fronts, errors) = plt.subplots(1, 2, figsize=(11, 4.2))
    for r in results:
        fronts.plot(r["T"], r["Z"], label=f"dx = a/{r['n']}")
    end = max(r["T"][-1] for r in results)
    shown = T_exp <= end
    fronts.plot(T_exp[shown], Z_exp[shown], "ko", label="Martin & Moyce (1952)")
    fronts.set_xlabel("T = t sqrt(2g/a)")
    fronts.set_ylabel("Z = z/a")
    fronts.set_title("Surge front")
    fronts.legend()
    dx = np.array([r["dx_m"] for r in results])
    rms = np.array([r["rms"] for r in results])
    errors.loglog(dx, rms, "o-")
    errors.set_xlabel("dx [m]")
    errors.set_ylabel("RMS error of Z")
    errors.set_title("Convergence against the experiment")
    fig.tight_layout()
    return fig


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--columns", type=int, nargs=3, default=[10, 20, 40], metavar="N",
                   help="particles across the column a for the three runs (default 10 20 40)")
    p.add_argument("--end-T", type=float, default=3.0,
                   help="end time in T = t sqrt(2g/a) (default 3, before the far wall)")
    p.add_argument("--out", default="out/resolution_study", help="output folder")
    p.add_argument("--adapter", default=None, help="auto, gpu or cpu")
    p.add_argument("--show", action="store_true", help="also show the figure in a window")
    args = p.parse_args()
    results = study(args.columns, args.end_T, args.out, args.adapter)
    import matplotlib

    if not args.show:
        matplotlib.use("Agg")
    fig = plot(results)
    png = pathlib.Path(args.out) / "resolution_study.png"
    fig.savefig(png, dpi=120)
    print(f"wrote {png}")
    if args.show:
        import matplotlib.pyplot as plt

        plt.show()


if __name__ == "__main__":
    main()
