"""Issue 14, item 5: gmsh meshing no longer takes Ctrl-C over (before: Ctrl-C afterwards killed
the process without a word)."""
import subprocess
import sys
import textwrap

from interrupts import needs_sigint


@needs_sigint
def test_gmsh_meshing_leaves_ctrl_c_to_python():
    script = textwrap.dedent("""
        import os, signal, time, snede
        snede.meshing.cylinder(h=0.02)
        try:
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(5)
        except KeyboardInterrupt:
            print("caught")
    """)
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0 and "caught" in run.stdout, (run.returncode, run.stdout, run.stderr)
