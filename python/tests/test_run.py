"""Runs from Python against the command's: the same case gives the same probe series bit for
bit, the particle arrays are the files', and a run the command wrote opens in Python."""

import pathlib

import numpy as np
import pytest

import vtu
import wgsph
from conftest import ADAPTER, DAM_BREAK, TINY


def csv_columns(path):
    """The columns of a probe CSV read here with Python's float()."""
    lines = [l for l in path.read_text().splitlines() if l and not l.startswith("#")]
    return [np.array([float(v) for v in col]) for col in zip(*(l.split(",") for l in lines[1:]))]


def same_bits(a, b):
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    return a.shape == b.shape and np.array_equal(a.view(np.uint64), b.view(np.uint64))


@pytest.fixture(scope="module")
def py_run(tmp_path_factory):
    case = wgsph.Case.load(DAM_BREAK)
    for k, v in TINY.items():
        case.set(k, v)
    return wgsph.run(case, out=tmp_path_factory.mktemp("py") / "run", adapter=ADAPTER,
                     progress=False)


def test_probes_equal_the_commands_csv_bit_for_bit(py_run, cli_run):
    assert py_run.status == "completed"
    names = py_run.probes()
    assert names == ["front", "front_continuous", "p_right_wall"]
    for name in names:
        t, v = py_run.probe(name)
        assert t.dtype == np.float64 and len(t) == 26  # 0.05 s every 0.002 s, and t = 0
        cli_t, cli_v = csv_columns(cli_run / "probes" / f"{name}.csv")
        assert same_bits(t, cli_t) and same_bits(v, cli_v), name
        # The two runs' files agree byte for byte too (same adapter, deterministic engine).
        ours = pathlib.Path(py_run.dir) / "probes" / f"{name}.csv"
        assert ours.read_bytes() == (cli_run / "probes" / f"{name}.csv").read_bytes(), name


def test_particles_equal_the_vtu(py_run):
    files = sorted((pathlib.Path(py_run.dir) / "particles").glob("*.vtu"))
    assert py_run.outputs == len(files) == 6
    for i, path in [(0, files[0]), (-1, files[-1]), (2, files[2])]:
        p = py_run.particles(i)
        f = vtu.read(path)
        assert p["time_s"] == f["TimeValue"][0]
        assert p["position"].dtype == np.float64 and p["position"].shape == (318, 3)
        assert np.array_equal(p["position"], f["Points"])
        assert p["velocity"].dtype == np.float32
        assert np.array_equal(p["velocity"], f["velocity"])
        for name in ["density", "pressure", "kind", "id"]:
            assert p[name].dtype == f[name].dtype and np.array_equal(p[name], f[name]), name
    with pytest.raises(IndexError, match="6"):
        py_run.particles(6)
    with pytest.raises(KeyError, match="front_continuous"):
        py_run.probe("back")


def test_a_run_of_the_command_opens(cli_run):
    run = wgsph.Run.open(cli_run)
    s = run.summary
    assert s["case"] == "dam_break_2d" and s["status"] == "completed"
    assert s["particles_fluid"] == 105 and s["overrides"] == [
        f"{k}={v!r}" for k, v in TINY.items()
    ]
    t, front = run.probe("front")
    assert same_bits(front, csv_columns(cli_run / "probes" / "front.csv")[1])
    assert 0.1 < front[-1] < 0.3
    p = run.particles(-1)
    last = sorted((cli_run / "particles").glob("*.vtu"))[-1]
    assert np.array_equal(p["position"], vtu.read(last)["Points"])


def test_bench(tiny_case):
    r = wgsph.bench(tiny_case, steps=5, warmup=1, adapter=ADAPTER)
    assert r["particles"] == 318 and r["steps"] == 5
    assert r["particle_steps_per_s"] > 0 and r["simulated_s"] > 0
    assert r["stages"] is None


def test_body_and_point_tables_equal_their_csv(tmp_path):
    case = wgsph.Case.load(DAM_BREAK.parent / "floating_box_2d.toml")
    case.set("particles.dx_m", 0.04)
    case.set("time.end_s", 0.02)
    run = wgsph.run(case, out=tmp_path, adapter=ADAPTER, progress=False)
    for table, name in [(run.body("box"), "body_box"), (run.point("corner"), "point_corner")]:
        path = tmp_path / "probes" / f"{name}.csv"
        header = [l for l in path.read_text().splitlines() if not l.startswith("#")][0]
        assert list(table) == header.split(","), name
        for column, values in zip(table, csv_columns(path)):
            assert same_bits(table[column], values), (name, column)
    assert run.body("box")["y_m"][0] == 0.32
    with pytest.raises(KeyError, match="body_box"):
        run.table("body_boat")
