# The two commands of the README:
#   make run    install what is missing, run the default scene (summary, HDF5, PNG)
#   make test   install what is missing, run the Fortran unit tests and the pytest suite
.PHONY: run test unit-tests pytest test-baseline bench clean

VENV := .venv
PY := $(VENV)/bin/python

run:
	@./tools/bootstrap.sh
	$(PY) -m layercontact run inputs/default.nml

test: unit-tests pytest

unit-tests:
	@./tools/bootstrap.sh
	@PATH=$(CURDIR)/$(VENV)/bin:$$PATH; \
	  [ -f build/unit/build.ninja ] || meson setup build/unit -Dunit_tests=true --buildtype=debugoptimized >/dev/null; \
	  meson test -C build/unit --print-errorlogs

pytest:
	@./tools/bootstrap.sh
	$(PY) -m pytest tests

# The solver tests on the portable core (the package picks the x86-64-v3 one where the
# processor runs it): both builds must pass on any x86-64 machine.
BASELINE_TESTS := tests/test_solver.py tests/test_kernel_branches.py tests/test_build.py \
	tests/test_viscoelastic.py tests/test_areal_reference.py tests/test_gfmd.py tests/test_threads.py
test-baseline:
	@./tools/bootstrap.sh
	LAYERCONTACT_ISA=baseline $(PY) -m pytest $(BASELINE_TESTS)

clean:
	rm -rf build out
