"""Issue 14, item 5: Ctrl-C stops the command line with one line and exit status 130, leaving
the series written so far readable. The signal is sent from this process to a child, as a
terminal would."""
import sys

from interrupts import interrupt_after, needs_sigint
from snede.output import read_series


@needs_sigint
def test_the_command_line_stops_with_one_line_and_the_series_so_far_reads_back(tmp_path):
    # The signal must reach the child while it still cuts: at 60 divisions the 102 moves after the
    # eighth take about 1 s on a 2-core machine, against the 0.05 s this waits. (At 20 divisions the
    # last 30 moves took 60 ms, and in one CI run the child had ended before a 0.3 s wait was
    # over: status 0, nothing on stderr.)
    status, out, err = interrupt_after(
        [sys.executable, "-m", "snede", "run", "sheet-cut", "--divisions", "60", "--out", str(tmp_path)],
        "sheet-cut: move   8/", delay=0.05)
    assert status == 130, (out, err)
    assert err.strip().splitlines() == [f"interrupted (the files written so far in {tmp_path} are complete up to "
                                        "the last step)"], err
    steps = read_series(tmp_path / "sheet-cut" / "sheet-cut.xdmf")
    assert len(steps) >= 2  # the stretched sheet and at least one frame of the cut
    for step in steps:
        step.mesh.validate()
        assert step.displacement.shape == (step.mesh.n_points, 2)
