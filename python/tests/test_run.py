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


MAPS_CASE = """
name = "maps_tank"
dimension = 3
[particles]
dx_m = 0.04
[physics]
gravity_m_s2 = [0.0, 0.0, -9.81]
sound_speed_coef = 10.0
[time]
end_s = 0.02
output_every_s = 0.02
[tank]
min_m = [0.0, 0.0, 0.0]
max_m = [0.4, 0.2, 0.3]
layers = 3
open_top = true
[[fluid_block]]
min_m = [0.0, 0.0, 0.0]
max_m = [0.2, 0.2, 0.12]
[maps]
cell_m = 0.05
"""


def test_flood_maps_are_arrays_of_their_grids(tmp_path):
    case = wgsph.Case.from_toml(MAPS_CASE, str(tmp_path / "maps_tank.toml"))
    run = wgsph.run(case, out=tmp_path / "out", adapter=ADAPTER, progress=False)
    assert "max_depth_m" in run.maps() and "arrival_s" in run.maps()
    depth = run.map("max_depth_m")
    path = tmp_path / "out" / "maps" / "max_depth_m.asc"
    lines = path.read_text().splitlines()
    header = dict(l.split() for l in lines[:6])
    rows = [[float(v) for v in l.split()] for l in lines[6:]]
    # The file lists rows from the north; the array's row 0 is the south.
    expected = np.array(rows[::-1])
    values = depth["values"]
    assert values.shape == (int(header["nrows"]), int(header["ncols"]))
    assert np.array_equal(np.isnan(values), expected == -9999.0)
    wet = ~np.isnan(values)
    assert np.array_equal(values[wet], expected[wet])
    # The water 0.12 m deep over the tank's west half; the rest never wet.
    assert 0.10 < np.nanmax(values) < 0.14
    assert wet.any() and not wet.all()
    assert depth["x"][0] == float(header["xllcorner"]) + 0.025
    with pytest.raises(KeyError, match="max_depth_m"):
        run.map("max_deep")
