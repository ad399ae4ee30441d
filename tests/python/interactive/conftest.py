"""The interactive tests' sessions: small scenes, built anew for each test."""
import pytest
import tool_scripts

from snede.app.interactive.window import display_answers


@pytest.fixture
def cut_session():
    return tool_scripts.cut_session()


@pytest.fixture
def needle_session():
    return tool_scripts.needle_session()


@pytest.fixture(scope="session")
def display():
    """A display of our own for the window tests, DISPLAY set to it for the tests and their
    subprocesses: Xvfb on a number no other server holds, away from the low numbers other test
    runs on this machine take, once a client reaches it."""
    import os
    import shutil
    import subprocess
    import time

    xvfb = shutil.which("Xvfb")
    if xvfb is None:
        pytest.skip("Xvfb is not installed (`make setup` installs it): the window tests need a display")
    for number in [100 + (os.getpid() + k) % 800 for k in range(20)]:
        if os.path.exists(f"/tmp/.X{number}-lock") or os.path.exists(f"/tmp/.X11-unix/X{number}"):
            continue
        server = subprocess.Popen([xvfb, f":{number}", "-screen", "0", "1024x768x24", "-nolisten", "tcp"],
                                  stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        deadline = time.monotonic() + 20
        while server.poll() is None and not display_answers(f":{number}") and time.monotonic() < deadline:
            time.sleep(0.05)
        if server.poll() is None and display_answers(f":{number}"):
            break
        server.kill()
        server.wait()
    else:
        pytest.fail("Xvfb did not start on any of 20 display numbers")
    before = os.environ.get("DISPLAY")
    os.environ["DISPLAY"] = f":{number}"
    yield os.environ["DISPLAY"]
    server.terminate()
    server.wait()
    if before is None:
        del os.environ["DISPLAY"]
    else:
        os.environ["DISPLAY"] = before
