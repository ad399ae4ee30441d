"""The README as a reader meets it (issues 36 item 5 and 38 item 9): short, its example runs and
prints what it says, its paths and links exist, and it gives the commands the CI runs.
tests/python/docs/test_guide.py runs its python blocks with the guide's."""
import glob
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
README = ROOT / "README.md"
FOLDERS = ("engine", "bindings", "python", "tests", "examples", "meshes", "docs", "studies", "tools")


def test_the_readme_stays_short():
    """The manual lives in docs/guide/; the README says what snede is and where to go."""
    assert len(README.read_text().splitlines()) <= 250


def test_the_readme_gives_the_commands_the_ci_runs():
    text = README.read_text()
    assert "make test" in text and "make demo" in text
    assert "make test" in (ROOT / ".ci" / "run").read_text()
    for target in ("demo:", "test:", "setup:"):
        assert re.search(rf"^{target}", (ROOT / "Makefile").read_text(), re.M)


def code_spans() -> list[str]:
    return re.findall(r"`([^`\n]+)`", README.read_text())


def test_every_path_the_readme_names_exists():
    """The table thesis section → code, and the other paths in `code`: engine/cutting/x.* is a
    file with any suffix, a path ending in / a folder."""
    paths = [span for span in code_spans() if span.split("/")[0] in FOLDERS and " " not in span]
    assert len(paths) > 20, paths
    for path in paths:
        if path.endswith("/"):
            assert (ROOT / path).is_dir(), f"the README names {path}, which is not a folder"
        else:
            assert glob.glob(str(ROOT / path)), f"the README names {path}, which does not exist"


def test_the_readme_links_every_results_page_and_every_guide_page():
    linked = set(re.findall(r"\]\((docs/[^)#]+)", README.read_text()))
    for page in [*(ROOT / "docs" / "results").glob("*.md"), *(ROOT / "docs" / "guide").glob("*.md")]:
        if page.name == "README.md":
            continue
        assert str(page.relative_to(ROOT)) in linked, f"the README does not link {page.relative_to(ROOT)}"


def python_blocks() -> list[str]:
    return re.findall(r"^```python\n(.*?)^```", README.read_text(), re.S | re.M)


def test_the_scene_of_the_readme_prints_what_it_says(tmp_path):
    """Its comments quote the solves and the cut; the series lands where output_folder says."""
    (block,) = python_blocks()
    assert len(block.splitlines()) <= 20
    done = subprocess.run([sys.executable, "-c", block], cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    before, cut, after = done.stdout.strip().splitlines()
    assert re.match(r"converged \(CONVERGED_FNORM_ABS\) after \d+ iterations \(\d+ linear\): .* MFLOP$", before)
    assert re.match(r"[1-9]\d* faces dissected .* 1 pieces in", cut)  # into the beam, not through it
    assert re.match(r"converged \(CONVERGED_FNORM_ABS\) after \d+ iterations", after)
    assert (tmp_path / "out" / "beam" / "beam.xdmf").is_file()


def test_the_demo_table_of_the_readme_is_the_demos_scene_list():
    """Every built-in scene has its row, and nothing else does."""
    import snede.app.scenes

    table = re.search(r"^```text\nscene .*?^```", README.read_text(), re.S | re.M).group(0)
    lines = table.splitlines()[2:]
    rows = [line.split()[0] for line in lines[:lines.index("...")]]
    assert rows == list(snede.app.scenes.builders())
