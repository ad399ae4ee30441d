#!/usr/bin/env bash
# make test: C++ tests through ctest, then Python tests through pytest, then the MPI tests
# (tests/mpi, also in the serial pytest run) on 2 and 3 ranks. Prints the summaries and exits
# non-zero if any failed. The MPI runs have a time limit, so a hang fails instead of waiting.
set -uo pipefail
cd "$(dirname "$0")/.."
export PATH="$PWD/.venv/bin:$PATH"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1

cpp_status=0
{ cmake -S . -B build/cpp -G Ninja -DSNEDE_BUILD_TESTS=ON -DSNEDE_BUILD_PYTHON=OFF >/dev/null &&
  cmake --build build/cpp; } || cpp_status=$?
if [ $cpp_status -eq 0 ]; then
  ctest --test-dir build/cpp --output-on-failure -j2 | tee build/ctest.log | tail -n 25
  cpp_status=${PIPESTATUS[0]}
fi

.venv/bin/python -m pytest -q tests/python tests/studies tests/mpi 2>&1 | tee build/pytest.log
py_status=${PIPESTATUS[0]}

mpi_status=0
for ranks in 2 3; do
  timeout 600 mpirun -n $ranks .venv/bin/python -m pytest -q --color=no -p no:cacheprovider tests/mpi \
    > build/mpi-$ranks.log 2>&1 || mpi_status=1
done

echo
echo "== summary =="
echo "ctest:  $(grep -E 'tests passed|tests failed' build/ctest.log 2>/dev/null || echo "did not run (build failed, status $cpp_status)")"
echo "pytest: $(grep -v "^\s*$" build/pytest.log | tail -n 1)"
for ranks in 2 3; do
  echo "mpi -n $ranks: $(grep -E "passed|failed|error" build/mpi-$ranks.log | tail -n 1 || echo "no summary: see build/mpi-$ranks.log")"
done
[ $cpp_status -eq 0 ] && [ $py_status -eq 0 ] && [ $mpi_status -eq 0 ]
