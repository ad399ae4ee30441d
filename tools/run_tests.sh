#!/usr/bin/env bash
# make test: C++ tests through ctest, then Python tests through pytest, then the MPI tests
# (tests/mpi, also in the serial pytest run) on 2 and 3 ranks. Prints the summaries and exits
# non-zero if any failed. The MPI runs have a time limit, so a hang fails instead of waiting.
set -uo pipefail
cd "$(dirname "$0")/.."
export PATH="$PWD/.venv/bin:$PATH"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1

source tools/build_mode.sh  # SNEDE_NATIVE (ON by default) and the build directories' suffix
logs=build/logs$BUILD_SUFFIX
mkdir -p "$logs"

cpp_status=0
{ cmake -S . -B "build/cpp$BUILD_SUFFIX" -G Ninja -DSNEDE_BUILD_TESTS=ON -DSNEDE_BUILD_PYTHON=OFF \
    -DSNEDE_NATIVE="$SNEDE_NATIVE" >/dev/null &&
  cmake --build "build/cpp$BUILD_SUFFIX"; } || cpp_status=$?
if [ $cpp_status -eq 0 ]; then
  ctest --test-dir "build/cpp$BUILD_SUFFIX" --output-on-failure -j2 | tee "$logs/ctest.log" | tail -n 25
  cpp_status=${PIPESTATUS[0]}
fi

.venv/bin/python -m pytest -q tests/python tests/studies tests/mpi 2>&1 | tee "$logs/pytest.log"
py_status=${PIPESTATUS[0]}

mpi_status=0
for ranks in 2 3; do
  timeout 600 mpirun -n $ranks .venv/bin/python -m pytest -q --color=no -p no:cacheprovider tests/mpi \
    > "$logs/mpi-$ranks.log" 2>&1 || mpi_status=1
done

echo
echo "== summary (SNEDE_NATIVE=$SNEDE_NATIVE, logs in $logs) =="
echo "ctest:  $(grep -E 'tests passed|tests failed' "$logs/ctest.log" 2>/dev/null || echo "did not run (build failed, status $cpp_status)")"
echo "pytest: $(grep -v "^\s*$" "$logs/pytest.log" | tail -n 1)"
for ranks in 2 3; do
  echo "mpi -n $ranks: $(grep -E "passed|failed|error" "$logs/mpi-$ranks.log" | tail -n 1 || echo "no summary: see $logs/mpi-$ranks.log")"
done
[ $cpp_status -eq 0 ] && [ $py_status -eq 0 ] && [ $mpi_status -eq 0 ]
