# The two commands a user needs: `make demo` and `make test` (both set up first if needed).
.PHONY: setup demo test test-cpp test-python meshes benchmark clean

setup:
	@bash tools/setup.sh

demo: setup
	@.venv/bin/python -m snede demo

test: setup
	@bash tools/run_tests.sh

meshes: setup
	@.venv/bin/python tools/canonical_meshes.py

benchmark: setup
	@.venv/bin/python studies/benchmarks/connectivity_build.py
	@.venv/bin/python studies/benchmarks/fem_throughput.py

clean:
	rm -rf build
