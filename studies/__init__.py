"""The studies beside the snede package (not in its wheel): ``studies.experiments`` regenerates
the tables and figures of ``docs/results/`` (``.venv/bin/python -m studies.experiments.<name>``,
from the repository root) and ``studies/benchmarks/`` holds scripts that print tables
(``.venv/bin/python studies/benchmarks/<name>.py``)."""
