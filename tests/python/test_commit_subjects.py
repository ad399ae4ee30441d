"""Commit subjects stay within 72 characters from the check's own commit on (issue 51)."""
import importlib.util
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
spec = importlib.util.spec_from_file_location("check_commit_subjects", ROOT / "tools" / "check_commit_subjects.py")
check = importlib.util.module_from_spec(spec)
spec.loader.exec_module(check)


def test_this_repository_keeps_its_subjects_short():
    assert check.long_subjects(ROOT) in ([], None)


def commit(repository: Path, path: str, subject: str) -> None:
    (repository / path).parent.mkdir(parents=True, exist_ok=True)
    (repository / path).write_text(subject)
    subprocess.run(["git", "-C", str(repository), "add", path], check=True)
    subprocess.run(["git", "-C", str(repository), "-c", "user.name=t", "-c", "user.email=t@t", "commit", "-q",
                    "-m", subject, "-m", "the detail, as long as it needs to be"], check=True)


def test_a_long_subject_after_the_check_is_named_and_earlier_ones_are_not(tmp_path):
    subprocess.run(["git", "init", "-q", str(tmp_path)], check=True)
    commit(tmp_path, "a.txt", "an old subject " + "x" * 80)
    assert check.long_subjects(tmp_path) == []
    commit(tmp_path, check.THIS_FILE, "Check commit subjects")
    commit(tmp_path, "b.txt", "Short subject")
    assert check.long_subjects(tmp_path) == []
    commit(tmp_path, "c.txt", "y" * 73)
    found = check.long_subjects(tmp_path)
    assert len(found) == 1 and ": 73 characters: " + "y" * 72 in found[0]
    assert check.long_subjects(tmp_path / "not-a-repository") is None
