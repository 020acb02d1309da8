"""exit_cli: a command line that has finished exits with its code even when Ctrl-C
arrives during the interpreter's shutdown."""

import os
import subprocess
import sys

from paths import REPO_ROOT

# SIGINT at shutdown (an atexit callback), where a finished run used to die with -2 or a
# stray KeyboardInterrupt traceback (tests/project/test_interrupts.py hit it by timing).
SCRIPT = """
import atexit, os, signal, time
from envelope.cli_errors import exit_cli
signal.signal(signal.SIGINT, signal.default_int_handler)  # as from a terminal, even when
# the test runs in the background, where the shell hands children SIGINT ignored
atexit.register(lambda: (os.kill(os.getpid(), signal.SIGINT), time.sleep(0.2)))
print("done", flush=True)
{exit}
"""


def _run(exit_line: str) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": str(REPO_ROOT)}
    return subprocess.run([sys.executable, "-c", SCRIPT.format(exit=exit_line)], cwd=REPO_ROOT,
                          env=env, capture_output=True, text=True, timeout=60)


def test_ctrl_c_during_shutdown_does_not_turn_a_finished_run_into_an_interrupted_one():
    run = _run("exit_cli(3)")
    assert (run.returncode, run.stdout, run.stderr) == (3, "done\n", "")


def test_without_it_the_same_signal_leaves_a_traceback():
    """The control: plain sys.exit shows what exit_cli prevents."""
    run = _run("import sys; sys.exit(0)")
    assert "KeyboardInterrupt" in run.stderr
