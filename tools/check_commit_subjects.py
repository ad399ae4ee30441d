"""Fails on a commit subject longer than 72 characters (issue 51).

    python tools/check_commit_subjects.py [repository]

A subject says what a commit does in one line that `git log --oneline` shows whole; the detail
goes in the body, after a blank line. Checks every commit from the one that added this file on
(earlier history is left as it is); prints each subject over the limit with its commit and exits
with status 1 if there is any. Outside a git checkout (an unpacked archive) there is nothing to
check. `make test` runs it (tests/python/test_commit_subjects.py).
"""
import subprocess
import sys
from pathlib import Path

LIMIT = 72
THIS_FILE = "tools/check_commit_subjects.py"


def git(repository: Path, *arguments: str) -> str:
    return subprocess.run(["git", "-C", str(repository), *arguments], capture_output=True, text=True,
                          check=True).stdout


def long_subjects(repository: Path) -> list[str] | None:
    """`commit: subject` of each checked commit whose subject is over LIMIT characters; None
    outside a git checkout."""
    try:
        git(repository, "rev-parse", "--git-dir")
    except (subprocess.CalledProcessError, FileNotFoundError):
        return None
    added = git(repository, "log", "--diff-filter=A", "--format=%H", "--", THIS_FILE).split()
    if not added:
        return []  # the check is not committed yet
    found = []
    for line in git(repository, "log", "--format=%H %s", "HEAD").splitlines():
        commit, _, subject = line.partition(" ")
        if len(subject) > LIMIT:
            found.append(f"{commit[:12]}: {len(subject)} characters: {subject[:LIMIT]}…")
        if commit == added[-1]:
            break
    return found


def main() -> int:
    repository = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parents[1]
    found = long_subjects(repository)
    if found is None:
        print("check_commit_subjects: not a git checkout, nothing to check")
        return 0
    for line in found:
        print(line)
    print(f"check_commit_subjects: {len(found)} subject(s) over {LIMIT} characters: put the detail in the body"
          if found else f"check_commit_subjects: every subject within {LIMIT} characters")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
