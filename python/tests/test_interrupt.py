"""Ctrl-C in Python: SIGINT to a process inside wgsph.run stops the run after the steps under way
with a checkpoint and raises KeyboardInterrupt saying so; resume (the package's and the
command's) continues it."""

import pathlib
import signal
import subprocess
import sys
import textwrap
import time

import wgsph
from conftest import ADAPTER, DAM_BREAK, cli

SCRIPT = textwrap.dedent(
    """
    import signal
    import sys
    import wgsph
    # Python's own Ctrl-C handler, as in a terminal or a notebook: a process started in the
    # background by a shell inherits SIGINT ignored, and Python then keeps ignoring it.
    signal.signal(signal.SIGINT, signal.default_int_handler)
    case = wgsph.Case.load(sys.argv[1])
    case.set("particles.dx_m", 0.02)
    case.set("time.end_s", 5.0)  # about a minute: it is interrupted long before
    try:
        wgsph.run(case, out=sys.argv[2], adapter=sys.argv[3], progress=False)
    except KeyboardInterrupt as e:
        print("KeyboardInterrupt:", e, flush=True)
        sys.exit(130)
    print("completed", flush=True)
    """
)


def test_sigint_stops_with_a_checkpoint_and_resume_continues(tmp_path):
    out = tmp_path / "run"
    proc = subprocess.Popen(
        [sys.executable, "-c", SCRIPT, str(DAM_BREAK), str(out), ADAPTER],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    # Interrupt once the run is under way: its second particle output is written.
    deadline = time.monotonic() + 120
    while not (out / "particles" / "particles_000002.vtu").exists():
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < deadline, "the run did not start"
        time.sleep(0.05)
    proc.send_signal(signal.SIGINT)
    stdout, stderr = proc.communicate(timeout=120)
    assert proc.returncode == 130, (stdout, stderr)
    assert "KeyboardInterrupt: run interrupted at t = " in stdout, stdout
    assert str(out / "checkpoint.bin") in stdout and "wgsph.resume(" in stdout
    assert "writing a checkpoint after the steps under way" in stderr
    assert (out / "checkpoint.bin").is_file()
    run = wgsph.Run.open(out)
    assert run.status.startswith("interrupted"), run.status
    t_stop = run.summary["simulated_time_s"]
    assert 0.02 <= t_stop < 1.0, t_stop
    assert not (out / ".wgsph.lock").exists()

    # The package's resume: on to a little later.
    end = round(t_stop + 0.01, 6)
    resumed = wgsph.resume(out, {"time.end_s": end}, adapter=ADAPTER, progress=False)
    assert resumed.status == "completed"
    assert abs(resumed.summary["simulated_time_s"] - end) < 1e-3
    t, front = resumed.probe("front")
    assert abs(t[-1] - end) < 2e-3 and (t[1:] > t[:-1]).all()
    # The command's resume of the same folder: the case file was recorded.
    cli("resume", out, "--set", f"time.end_s={end + 0.01}", "--checkpoint-every", "0.005")
    assert wgsph.Run.open(out).summary["simulated_time_s"] > end


def test_resume_of_a_case_given_as_text_needs_the_case(tmp_path):
    case = wgsph.Case.from_toml(DAM_BREAK.read_text())
    case.set("particles.dx_m", 0.02)
    case.set("time.end_s", 0.02)
    run = wgsph.run(case, out=tmp_path, adapter=ADAPTER, progress=False,
                    checkpoint_every="0.01")
    assert run.status == "completed"
    try:
        wgsph.resume(tmp_path, {"time.end_s": 0.03}, adapter=ADAPTER, progress=False)
    except wgsph.WgsphError as e:
        assert "case=" in str(e), str(e)
    else:
        raise AssertionError("resumed without the case")
    run = wgsph.resume(tmp_path, {"time.end_s": 0.03}, case=case, adapter=ADAPTER,
                       progress=False)
    assert run.status == "completed" and abs(run.summary["simulated_time_s"] - 0.03) < 1e-3
