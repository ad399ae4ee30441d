"""The interactive tests' sessions: small scenes, built anew for each test."""
import pytest
import tool_scripts


@pytest.fixture
def cut_session():
    return tool_scripts.cut_session()


@pytest.fixture
def needle_session():
    return tool_scripts.needle_session()


@pytest.fixture(scope="session")
def display():
    """A display of our own for the window tests: Xvfb on the first free number (it writes the
    number to us when it is ready), DISPLAY set to it for the tests and their subprocesses."""
    import os
    import shutil
    import subprocess

    xvfb = shutil.which("Xvfb")
    if xvfb is None:
        pytest.skip("Xvfb is not installed (`make setup` installs it): the window tests need a display")
    read, write = os.pipe()
    server = subprocess.Popen([xvfb, "-displayfd", str(write), "-screen", "0", "1024x768x24", "-nolisten", "tcp"],
                              pass_fds=(write,), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    os.close(write)
    # Up to its newline, and the pipe kept open: Xvfb dies if its write meets a closed pipe.
    answer = b""
    while not answer.endswith(b"\n") and (chunk := os.read(read, 32)):
        answer += chunk
    number = answer.decode().strip()
    if not number:
        server.wait()
        pytest.fail(f"Xvfb did not start (status {server.returncode})")
    before = os.environ.get("DISPLAY")
    os.environ["DISPLAY"] = f":{number}"
    yield os.environ["DISPLAY"]
    server.terminate()
    server.wait()
    os.close(read)
    if before is None:
        del os.environ["DISPLAY"]
    else:
        os.environ["DISPLAY"] = before
