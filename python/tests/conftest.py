"""Shared set-up of the Python package's tests: the repository, the `wgsph` command they
compare with, and a tiny dam break (a second of lavapipe time a run)."""

import os
import pathlib
import subprocess

import pytest

import wgsph

REPO = pathlib.Path(__file__).resolve().parents[2]
DAM_BREAK = REPO / "cases" / "dam_break_2d.toml"
# Coarse and short: 318 particles, 0.05 s simulated (about 170 steps, 6 particle outputs).
TINY = {"particles.dx_m": 0.02, "time.end_s": 0.05}
# Every run of the tests on the CPU adapter, as CI has only lavapipe: the command's runs and
# the package's must be on the same adapter to agree bit for bit.
ADAPTER = "cpu"


def cli_binary():
    """The `wgsph` command built from this checkout ($WGSPH_BIN, else target/debug/wgsph,
    which README's `cargo test --locked` builds). Missing is a failure, not a skip."""
    given = os.environ.get("WGSPH_BIN")
    path = pathlib.Path(given) if given else REPO / "target" / "debug" / "wgsph"
    if not path.is_file():
        pytest.fail(f"no wgsph command at {path}: run `cargo build` (or set WGSPH_BIN)")
    return path


def cli(*args, check=True):
    """Runs the command; returns the CompletedProcess (text)."""
    out = subprocess.run(
        [str(cli_binary()), "--adapter", ADAPTER, *map(str, args)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    if check and out.returncode != 0:
        raise AssertionError(f"wgsph {args} failed ({out.returncode}):\n{out.stderr}")
    return out


def set_args(overrides):
    """--set arguments of a dict, written as Case.set writes the values."""
    return [a for k, v in overrides.items() for a in ("--set", f"{k}={v!r}")]


@pytest.fixture
def tiny_case():
    case = wgsph.Case.load(DAM_BREAK)
    for k, v in TINY.items():
        case.set(k, v)
    return case


@pytest.fixture(scope="session")
def cli_run(tmp_path_factory):
    """The tiny dam break run by the command, once for the session."""
    out = tmp_path_factory.mktemp("cli") / "run"
    cli("run", DAM_BREAK, "--out", out, "--quiet", *set_args(TINY))
    return out
