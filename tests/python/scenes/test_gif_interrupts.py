"""Issue 14, item 5: Ctrl-C while an animation is drawn stays a KeyboardInterrupt."""
import pytest


def test_ctrl_c_while_a_gif_is_drawn_stays_a_keyboard_interrupt(tmp_path):
    # matplotlib's writer.saving() called finish() on the way out, which raised IndexError on a
    # GIF without frames and hid the KeyboardInterrupt (the command line then exited 1).
    from snede.app.plotting import animate

    def draw(ax, frame):
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        animate([0, 1], tmp_path / "cut.gif", draw)
    assert not (tmp_path / "cut.gif").exists() or (tmp_path / "cut.gif").stat().st_size == 0
