"""Experiments that regenerate the tables and figures under ``docs/results/``: each module
runs with ``python -m studies.experiments.<name> [--quick] [--out DIR]`` and exposes
``main(argv)`` for tests."""
