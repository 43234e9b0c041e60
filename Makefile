# The two commands of the README:
#   make run    install what is missing, run the default scene (summary, HDF5, PNG)
#   make test   install what is missing, run the Fortran unit tests and the pytest suite
.PHONY: run test unit-tests pytest bench clean

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

clean:
	rm -rf build out
