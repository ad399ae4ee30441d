#!/usr/bin/env bash
# A build of snede at a git revision, for compare_builds.py: a worktree of REV built with
# the .venv's pybind11 and Debian's PETSc into OUT (OUT/snede holds the package and _snede).
#   bash studies/benchmarks/package_build.sh REV OUT
set -euo pipefail
[ $# -eq 2 ] || { echo "usage: $0 REV OUT" >&2; exit 2; }
rev=$1; out=$(realpath -m "$2")
root=$(cd "$(dirname "$0")/../.." && pwd)
python=$root/.venv/bin/python
export PETSC_DIR=/usr/lib/petscdir/petsc3.18/x86_64-linux-gnu-real
source_tree=$out/source
rm -rf "$out"
git -C "$root" worktree add --detach -f "$source_tree" "$rev" >/dev/null
cmake -S "$source_tree" -B "$out/build" -G Ninja -DSNEDE_BUILD_PYTHON=ON -DSNEDE_BUILD_TESTS=OFF \
  -DSNEDE_BUILD_BENCHMARKS=OFF -DCMAKE_BUILD_TYPE=Release -DPython_EXECUTABLE="$python" \
  -Dpybind11_DIR="$("$python" -m pybind11 --cmakedir)" >/dev/null
cmake --build "$out/build"
cp -r "$source_tree/python/snede" "$out/snede"
cp "$out/build"/_snede*.so "$out/snede/"
git -C "$root" worktree remove --force "$source_tree"
echo "$out: snede at $(git -C "$root" rev-parse --short "$rev")"
