"""Cases from Python: loading, `set` with the command's checks and messages, to_toml, and the
errors of the other calls' arguments."""

import json

import pytest

import wgsph
from conftest import DAM_BREAK, cli


def cli_error(*args):
    """The message `wgsph run` prints for a case it refuses (after `error: `)."""
    out = cli("run", *args, check=False)
    assert out.returncode == 1, out.stderr
    line = out.stderr.strip().splitlines()[-1]
    assert line.startswith("error: "), out.stderr
    return line[len("error: "):]


def test_set_error_is_the_commands_message_and_leaves_the_case_unchanged():
    case = wgsph.Case.load(DAM_BREAK)
    before = case.particles
    with pytest.raises(wgsph.CaseError) as e:
        case.set("particles.dx_m", -1.0)
    assert isinstance(e.value, ValueError)
    assert str(e.value) == cli_error(DAM_BREAK, "--set", "particles.dx_m=-1.0")
    assert "particles.dx_m" in str(e.value) and "fix:" in str(e.value)
    assert case.particles == before and case.overrides == []


def test_unknown_field_and_bad_key_name_the_field():
    case = wgsph.Case.load(DAM_BREAK)
    with pytest.raises(wgsph.CaseError) as e:
        case.set("particles.dxx_m", 0.01)
    assert str(e.value) == cli_error(DAM_BREAK, "--set", "particles.dxx_m=0.01")
    assert "dxx_m" in str(e.value)
    with pytest.raises(wgsph.CaseError, match="not a valid key"):
        case.set("[0].x", 1)


def test_load_errors_name_the_file():
    with pytest.raises(wgsph.CaseError) as e:
        wgsph.Case.load("no/such/case.toml")
    assert str(e.value) == cli_error("no/such/case.toml")
    with pytest.raises(wgsph.CaseError, match=r"bad\.toml:2"):
        wgsph.Case.from_toml('name = "x"\ndimension = = 2\n', file="bad.toml")


def test_a_case_beyond_the_hosts_memory_is_refused_before_it_is_built():
    """A case more than the host's memory holds (issue 64: the loader built its particles and
    the process aborted) is refused naming particles.dx_m and the host's memory, at once."""
    with open("/proc/meminfo") as f:
        kib = next(int(l.split()[1]) for l in f if l.startswith("MemAvailable:"))
    fits = kib * 1024 / 250  # the engine's bytes a particle on the host (sph::run_budget)
    if fits * 1.5 > 1.9e8:
        pytest.skip("the host holds more particles than a run may have: its limit binds first")
    dx = 1.0 / (1.5 * fits) ** (1 / 3)  # bench_fluid_cube: a cube of water 1 m wide
    case = wgsph.Case.load(DAM_BREAK.parent / "bench_fluid_cube.toml")
    with pytest.raises(wgsph.CaseError) as e:
        case.set("particles.dx_m", dx)
    assert "particles.dx_m" in str(e.value) and "host's memory" in str(e.value), str(e.value)


def test_set_values_of_every_type():
    case = wgsph.Case.load(DAM_BREAK)
    case.set("particles.dx_m", 0.02)
    case.set("particles.kernel", "cubic_spline")  # a bare string, as on the command line
    case.set("tank.open_top", False)
    case.set("tank.layers", 3)
    case.set("physics.gravity_m_s2", (0.0, -9.0))
    assert case.overrides == [
        "particles.dx_m=0.02",
        "particles.kernel=cubic_spline",
        "tank.open_top=false",
        "tank.layers=3",
        "physics.gravity_m_s2=[0.0, -9.0]",
    ]
    with pytest.raises(TypeError, match="particles.dx_m"):
        case.set("particles.dx_m", object())


def test_to_toml_round_trips_and_copy_is_independent():
    case = wgsph.Case.load(DAM_BREAK)
    assert case.to_toml() == DAM_BREAK.read_text()
    other = case.copy()
    other.set("particles.dx_m", 0.02)
    assert case.overrides == [] and other.overrides == ["particles.dx_m=0.02"]
    again = wgsph.Case.from_toml(other.to_toml())
    assert again.particles == other.particles
    assert "dx_m = 0.02" in other.to_toml()


def test_built_in_cases():
    names = wgsph.Case.built_in_names()
    assert "dam_break_2d" in names and "hydrostatic_2d" in names
    built = wgsph.Case.built_in("dam_break_2d")
    assert built.particles == wgsph.Case.load(DAM_BREAK).particles
    assert built.name == "dam_break_2d" and built.dimension == 2
    with pytest.raises(wgsph.CaseError, match="dam_break_2d"):
        wgsph.Case.built_in("dam_brake_2d")


def test_argument_errors(tmp_path, tiny_case):
    with pytest.raises(ValueError, match="adapter"):
        wgsph.run(tiny_case, out=tmp_path, adapter="tpu")
    with pytest.raises(ValueError, match="checkpoint_every"):
        wgsph.run(tiny_case, out=tmp_path, checkpoint_every="often")
    with pytest.raises(ValueError, match="snapshots=True"):
        wgsph.run(tiny_case, out=tmp_path, snapshot_field="speed")
    with pytest.raises(ValueError, match="quick"):
        wgsph.validate(tmp_path, mode="slow")
    with pytest.raises(ValueError, match="no_such_case"):
        wgsph.validate(tmp_path, cases=["no_such_case"])
    with pytest.raises(wgsph.WgsphError, match="not a run folder"):
        wgsph.Run.open(tmp_path)
    with pytest.raises(wgsph.WgsphError, match="checkpoint"):
        wgsph.resume(tmp_path)


def test_a_real_place_loads_with_its_files(tmp_path):
    """The town (issue 59): its elevation grid, footprints and gate series are found beside the
    case file, and Python builds the particles the command builds."""
    town = DAM_BREAK.parent / "town_flood_3d.toml"
    case = wgsph.Case.load(town)
    short = ["time.end_s=0.002", "time.output_every_s=0.002", "time.probe_every_s=0.002"]
    cli("run", town, *[a for s in short for a in ("--set", s)], "--out", tmp_path / "run", "-q")
    summary = json.loads((tmp_path / "run" / "run.json").read_text())
    assert case.particles["fluid"] == summary["particles_fluid"] > 500
    assert case.particles["boundary"] == summary["particles_wall"]
    assert summary["world_origin_m"] == [2600000.0, 1200000.0, 431.0]


def test_the_isolated_building_loads_from_its_place_files(tmp_path):
    """The Soares-Frazao & Zech flume (issue 59): its bed grid, the dam's footprints and the
    building's STL are found beside the case file; at a coarse dx (as shipped, without the wet
    bed) Python builds the particles the command builds."""
    sfz = DAM_BREAK.parent / "sfz_building_3d.toml"
    coarse = ["particles.dx_m=0.1"]
    text = sfz.read_text().replace("dx_m = 0.08", "dx_m = 0.1")
    case = wgsph.Case.from_toml(text, str(sfz))
    short = ["time.end_s=0.002", "time.output_every_s=0.002", "time.probe_every_s=0.002"]
    sets = [a for s in coarse + short for a in ("--set", s)]
    cli("run", sfz, *sets, "--out", tmp_path / "run", "-q")
    summary = json.loads((tmp_path / "run" / "run.json").read_text())
    assert case.particles["fluid"] == summary["particles_fluid"] > 5000
    assert case.particles["boundary"] == summary["particles_wall"]
    assert summary["world_origin_m"] == [7.55, 1.8, 0.0]
    assert summary["case_build_s"] > 0
