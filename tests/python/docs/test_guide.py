"""The code a reader copies from README.md and docs/guide/*.md runs as written (issue 36 item 5).

Each page's ```python blocks run in order, in one fresh interpreter, as a reader pasting them
one after another would: the working directory is a temporary folder (what the blocks write
lands there) in which ``meshes/`` and ``examples/`` are the repository's, so paths read as they
do from the repository's root. Tracebacks name the page and its line.

Conventions of the pages (docs/guide/README.md says them to writers):

* ```python — runs.
* ```python no-run — not run (it needs ``mpirun`` or minutes), only compiled; the line before
  its fence says why.
* ```sh, ```toml and plain ``` (printed output) blocks are not run.
"""
from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]
GUIDE = ROOT / "docs" / "guide"
PAGES = [ROOT / "README.md", *sorted(GUIDE.glob("*.md"))]
# What a page's blocks may take, all of them together, in seconds (the whole test: < 60 s).
TIMEOUT = 120
FENCE = re.compile(r"^```([^\n`]*)\n(.*?)^```[ \t]*$", re.S | re.M)
KNOWN_INFO = {"", "python", "python no-run", "sh", "toml", "text"}


def blocks(page: Path) -> list[tuple[str, int, str]]:
    """(info string, line of the block's first code line, code) of every fenced block."""
    text = page.read_text()
    return [(match.group(1).strip(), text.count("\n", 0, match.start(2)) + 1, match.group(2))
            for match in FENCE.finditer(text)]


def python_blocks(page: Path, run: bool = True) -> list[tuple[int, str]]:
    wanted = {"python"} if run else {"python", "python no-run"}
    return [(line, code) for info, line, code in blocks(page) if info in wanted]


# Runs the blocks given as JSON [[line, code], ...] in one namespace, each compiled with blank
# lines before it so that a traceback gives the page's own line numbers.
RUNNER = """
import json, sys
path, blocks = sys.argv[1], json.load(open(sys.argv[2]))
namespace = {"__name__": "__main__"}
for line, code in blocks:
    exec(compile("\\n" * (line - 1) + code, path, "exec"), namespace)
"""


def run_page(page: Path, workdir: Path) -> subprocess.CompletedProcess:
    for folder in ("meshes", "examples"):
        link = workdir / folder
        if not link.exists():
            link.symlink_to(ROOT / folder, target_is_directory=True)
    listing = workdir / "blocks.json"
    listing.write_text(json.dumps(python_blocks(page)))
    environment = {key: value for key, value in os.environ.items() if key != "SNEDE_OUT"}
    environment["MPLBACKEND"] = "Agg"
    return subprocess.run([sys.executable, "-c", RUNNER, str(page), str(listing)], cwd=workdir, env=environment,
                          capture_output=True, text=True, timeout=TIMEOUT)


def page_id(page: Path) -> str:
    return str(page.relative_to(ROOT))


@pytest.mark.parametrize("page", PAGES, ids=page_id)
def test_the_python_of_the_page_runs_as_written(page, tmp_path):
    if not python_blocks(page):
        pytest.skip(f"{page_id(page)} has no python block")
    done = run_page(page, tmp_path)
    assert done.returncode == 0, f"{page_id(page)}:\n{done.stdout[-3000:]}\n{done.stderr[-5000:]}"


@pytest.mark.parametrize("page", PAGES, ids=page_id)
def test_every_python_block_compiles_and_every_fence_is_known(page):
    """A command line pasted into a python block is a syntax error where a reader runs it; an
    unknown info string (```py, ```python skip) would be silently left out of the run above."""
    for info, line, code in blocks(page):
        assert info in KNOWN_INFO, f"{page_id(page)}:{line}: fence ```{info} (known: {sorted(KNOWN_INFO)})"
        if info.startswith("python"):
            compile("\n" * (line - 1) + code, str(page), "exec")


@pytest.mark.parametrize("page", PAGES, ids=page_id)
def test_a_block_that_does_not_run_says_why(page):
    lines = page.read_text().splitlines()
    for info, line, _ in blocks(page):
        if info == "python no-run":
            before = [text for text in lines[:line - 2] if text.strip()][-1]
            assert re.search(r"mpirun|minutes|not run", before), \
                f"{page_id(page)}:{line}: a python no-run block follows a line that does not say why: {before!r}"


LINK = re.compile(r"\]\(([^)\s]+)\)")


@pytest.mark.parametrize("page", PAGES, ids=page_id)
def test_every_link_of_the_page_leads_to_a_file(page):
    """Relative links (the guide's pages, docs/results/*.md, examples) and their #anchors."""
    for target in LINK.findall(page.read_text()):
        if re.match(r"[a-z]+:", target):
            continue
        path, _, anchor = target.partition("#")
        linked = (page.parent / path).resolve() if path else page
        assert linked.exists(), f"{page_id(page)} links to {target}, which does not exist"
        if anchor and linked.suffix == ".md":
            assert anchor in anchors(linked), f"{page_id(page)} links to {target}: no such heading"


def anchors(page: Path) -> set[str]:
    """GitHub's anchors of a page's headings: lower case, punctuation dropped, spaces to '-'."""
    found = set()
    for heading in re.findall(r"^#+ (.+)$", page.read_text(), re.M):
        slug = re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")
        found.add(slug)
    return found


def test_importing_snede_loads_neither_h5py_nor_matplotlib(tmp_path):
    """The output guide calls ``snede.output.read_series`` after ``import snede`` alone: the
    module loads on first use (it raised AttributeError once), and h5py with it, not before."""
    done = subprocess.run([sys.executable, "-c", "import sys, snede\n"
                           "assert 'h5py' not in sys.modules and 'matplotlib' not in sys.modules\n"
                           "snede.output.read_series\nassert 'h5py' in sys.modules"],
                          cwd=tmp_path, capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr


@pytest.mark.skipif(shutil.which("mpirun") is None, reason="needs mpirun")
def test_the_mpi_page_runs_on_two_ranks(tmp_path):
    """docs/guide/mpi.md says its blocks run as they stand on one rank and on N: here on 2."""
    page = GUIDE / "mpi.md"
    (tmp_path / "meshes").symlink_to(ROOT / "meshes", target_is_directory=True)
    (tmp_path / "blocks.json").write_text(json.dumps(python_blocks(page)))
    (tmp_path / "runner.py").write_text(RUNNER)
    environment = {**os.environ, "OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
                   "OMPI_MCA_rmaps_base_oversubscribe": "1", "MPLBACKEND": "Agg"}
    done = subprocess.run(["mpirun", "-n", "2", sys.executable, "runner.py", str(page), "blocks.json"], cwd=tmp_path,
                          env=environment, capture_output=True, text=True, timeout=TIMEOUT)
    assert done.returncode == 0, f"{done.stdout[-3000:]}\n{done.stderr[-5000:]}"
    assert done.stdout.count("True") == 18  # each rank prints nine times (their lines may interleave)
    assert done.stdout.count("240") == 2  # the box made on the ranks: every rank knows its size
    assert len(snede_series_steps(tmp_path / "out" / "run.xdmf")) == 1
    assert len(snede_series_steps(tmp_path / "out" / "cylinder.xdmf")) == 1


def snede_series_steps(path: Path) -> list:
    import snede.output

    return snede.output.read_series(path)
