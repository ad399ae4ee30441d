"""``python -m snede`` (and the ``snede`` script): the command line of ``snede.app.command_line``."""
from snede.app.command_line import main, run

__all__ = ["main"]

if __name__ == "__main__":
    run()
