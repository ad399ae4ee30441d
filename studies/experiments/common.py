"""Small helpers shared by the experiments: their command line, results pages written from
templates, results tables written as markdown and CSV, PETSc options prefixes that never
repeat, and solve outcomes that always end with a verdict."""
from __future__ import annotations

import argparse
import csv
import itertools
import math
import re
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Sequence

_REPOSITORY = Path(__file__).resolve().parents[2]
RESULTS_DIR = (_REPOSITORY if (_REPOSITORY / "pyproject.toml").exists() else Path.cwd()) / "docs" / "results"
TEMPLATES = Path(__file__).resolve().parents[1] / "templates"


def parse_arguments(description: str, argv: Sequence[str] | None = None,
                    add_arguments: Callable[[argparse.ArgumentParser], None] | None = None) -> argparse.Namespace:
    """``--quick`` (small sizes, seconds), ``--out DIR`` (default docs/results) and what
    ``add_arguments`` adds to the parser (an experiment's own options); anything else is left to
    PETSc, which reads the command line itself."""
    parser = argparse.ArgumentParser(description=description, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="small sizes that run in seconds (for tests)")
    parser.add_argument("--out", type=Path, default=RESULTS_DIR, help=f"output folder (default {RESULTS_DIR})")
    if add_arguments:
        add_arguments(parser)
    arguments, _ = parser.parse_known_args(argv)
    arguments.out.mkdir(parents=True, exist_ok=True)
    return arguments


_SNIPPET_HEADER = re.compile(r"\n<!-- snippet ([A-Za-z0-9_]+) -->\n")
# A placeholder alone in a paragraph, with the blank line after it (or before it, at the end).
_LONE_PLACEHOLDER = re.compile(r"^\{([A-Za-z0-9_]+)\}\n\n|\n\n\{([A-Za-z0-9_]+)\}\n\Z", re.M)


class PageTemplate:
    """The prose of a results page, in ``studies/templates/<name>.md``: the page, then its
    snippets (sentences and paragraphs that only some runs print), each after a line
    ``<!-- snippet NAME -->``. The generator computes the values, picks the snippets and fills
    them in.

    Page and snippets are ``str.format`` strings: ``{name}`` or ``{name:.2f}`` takes the value
    of that name, ``{{`` and ``}}`` are braces. A snippet ends at the next snippet's line, less
    the line breaks before it; the page ends with one line break. A text value goes in without
    its last line break (a markdown table's), and a paragraph that is a placeholder alone goes,
    with the blank line after it, when its value is the empty string (a paragraph some runs
    leave out)."""

    def __init__(self, name: str):
        self.path = TEMPLATES / f"{name}.md"
        page, *rest = _SNIPPET_HEADER.split(self.path.read_text())
        self.text = page.rstrip("\n") + "\n"
        self.snippets = {name: text.rstrip("\n") for name, text in zip(rest[::2], rest[1::2])}

    def snippet(self, name: str, /, **values) -> str:
        return _fill(self.snippets[name], values)

    def page(self, **values) -> str:
        return _fill(self.text, values)


def _fill(text: str, values: dict) -> str:
    values = {key: value.removesuffix("\n") if isinstance(value, str) else value for key, value in values.items()}
    text = _LONE_PLACEHOLDER.sub(lambda match: "\n" * bool(match[2]) if values.get(match[1] or match[2]) == "" else match[0],
                                 text)
    return text.format_map(values)


@dataclass(frozen=True)
class Column:
    """One column of a markdown table: the row key, its header and a ``str.format`` spec."""

    key: str
    header: str
    format: str = "{}"


def _cell(value, spec: str) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "–"
    return spec.format(value).replace("|", "\\|")


def markdown_table(rows: Sequence[dict], columns: Sequence[Column]) -> str:
    lines = ["| " + " | ".join(column.header for column in columns) + " |",
             "|" + "|".join("---" for _ in columns) + "|"]
    lines += ["| " + " | ".join(_cell(row.get(column.key), column.format) for column in columns) + " |"
              for row in rows]
    return "\n".join(lines) + "\n"


def write_csv(path: Path, rows: Sequence[dict]) -> None:
    """All keys of all rows, in the order they first appear."""
    keys = list(dict.fromkeys(key for row in rows for key in row))
    with open(path, "w", newline="") as stream:
        writer = csv.DictWriter(stream, fieldnames=keys)
        writer.writeheader()
        writer.writerows(rows)


_prefix_numbers = itertools.count()


def options_prefix(label: str) -> str:
    """A PETSc options prefix no other solve in this process uses, so that command-line options
    for the default prefixes (``-static_…``, ``-dynamic_…``) leave an experiment's settings alone."""
    return re.sub(r"[^A-Za-z0-9]", "_", label) + f"_{next(_prefix_numbers)}_"


@dataclass
class Outcome:
    converged: bool
    reason: str
    seconds: float
    iterations: int = 0
    linear_iterations: int = 0
    flops: float = 0.0


def run_solve(solve: Callable[[], object]) -> Outcome:
    """Run ``solve`` (returning a ``snede.SolveResult``). An exception becomes a
    non-converged outcome whose reason is the exception's class and message, so that every
    run ends converged or with a named reason."""
    start = time.perf_counter()
    try:
        result = solve()
    except Exception as error:  # reported in the table, not hidden
        return Outcome(False, f"{type(error).__name__}: {error}", time.perf_counter() - start)
    return Outcome(result.converged, result.reason, result.seconds, result.iterations, result.linear_iterations,
                   result.flops)


def best_seconds(operation: Callable[[], object], repeats: int) -> float:
    """The shortest wall time of ``repeats`` calls (the least disturbed by a shared machine)."""
    best = float("inf")
    for _ in range(repeats):
        start = time.perf_counter()
        operation()
        best = min(best, time.perf_counter() - start)
    return best


def pyplot():
    """matplotlib.pyplot on the Agg backend (files only, no display)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save_figure(figure, path, dpi: int) -> None:
    """Lays `figure` out, writes it to `path` at `dpi` and frees it."""
    figure.tight_layout()
    figure.savefig(path, dpi=dpi)
    pyplot().close(figure)
