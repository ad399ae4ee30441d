"""Ctrl-C as a terminal sends it, to a child process: for the tests of the solvers, the meshing
and the command line."""
import signal
import subprocess
import time

import pytest

# A process started with SIGINT ignored (nohup, or `cmd &` from a script) passes that on to its
# children, which then never see the Ctrl-C these tests send (issue 38): skip rather than fail.
needs_sigint = pytest.mark.skipif(signal.getsignal(signal.SIGINT) is signal.SIG_IGN,
                                  reason="SIGINT is ignored in this process (nohup or a background job of a "
                                         "script): its children inherit that and cannot be interrupted")


def interrupt_after(arguments, marker: str, delay: float = 0.3, timeout: float = 120):
    """Runs a child, sends it SIGINT `delay` s after it printed a line containing `marker`;
    returns (exit status, its stdout, its stderr)."""
    child = subprocess.Popen(arguments, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    lines = []
    for line in child.stdout:
        lines.append(line)
        if marker in line:
            break
    time.sleep(delay)
    child.send_signal(signal.SIGINT)
    out, err = child.communicate(timeout=timeout)
    return child.returncode, "".join(lines) + out, err
