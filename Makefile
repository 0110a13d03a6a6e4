# The two commands a user needs: `make run` and `make test`. Both create .venv when missing.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
ENDPOINT ?= tcp://127.0.0.1:5555
# make run ADS=0.0.0.0:48898 DATA_DIR=/srv/cnc: where ADS clients connect (HOST[:PORT], off
# disables ADS) and the data directory (programs/ and output/); empty: the service's default.
ADS      ?=
DATA_DIR ?=
# make run OPCUA=off: where OPC UA clients connect (opc.tcp://HOST[:PORT], off disables
# it); empty: the service's default, opc.tcp://127.0.0.1:4840 (docs/opcua.md).
OPCUA    ?=
# make run CONFIG=machine.toml: the machine configuration (TOML, laid over the default;
# docs/configuration.md); empty: the embedded default machine.
CONFIG   ?=

.PHONY: run test bench soak clean generate coverage

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip

# Stamp files record which extras are installed, so a changed pyproject reinstalls.
$(VENV)/.installed: pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e '.[plot,native]'
	$(BIN)/python tools/build_native.py
	touch $@

$(VENV)/.installed-test: pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e '.[test,plot,native]'
	$(BIN)/python tools/build_native.py
	touch $@ $(VENV)/.installed

# The kernel's hot path compiled with mypyc (tools/build_native.py; issue 37): again
# whenever one of its sources changes. Never fails: without a compiler it warns, and the
# service runs the same code as pure Python.
NATIVE_SOURCES := $(wildcard service/kernel/path/*.py) service/kernel/contour_lookahead.py \
	tools/build_native.py
$(VENV)/.native: $(NATIVE_SOURCES) | $(VENV)/.installed
	$(BIN)/python tools/build_native.py
	touch $@

# The OPC UA nodesets imported once, where the service keeps its address space cache
# (service/opcua/prepare.py; docs/opcua.md "Start-up"): the service's first start is a
# warm one. Without it (a cache that cannot be written) the first start imports them.
$(VENV)/.opcua-cache: $(wildcard service/opcua/nodesets/*.xml) $(VENV)/.installed
	-$(BIN)/python -m cnc_objects.service.opcua.prepare
	touch $@

# `make run` starts the web HMI cnc-web beside the service, on http://127.0.0.1:$(WEB_PORT)
# (loopback only); WEB=0 leaves it out. It ends with the service (Ctrl-C).
WEB      ?= 1
WEB_PORT ?= 8080

run: $(VENV)/.installed $(VENV)/.native $(if $(filter off,$(OPCUA)),,$(VENV)/.opcua-cache)
ifeq ($(WEB),0)
	$(BIN)/cnc-service --endpoint $(ENDPOINT) $(if $(ADS),--ads $(ADS)) $(if $(OPCUA),--opcua $(OPCUA)) \
		$(if $(DATA_DIR),--data-dir $(DATA_DIR)) $(if $(CONFIG),--config $(CONFIG)) $(if $(MACHINE),--machine $(MACHINE))
else
	$(BIN)/cnc-web --endpoint $(ENDPOINT) --port $(WEB_PORT) & web=$$!; \
	trap 'kill $$web 2>/dev/null' EXIT INT TERM; \
	$(BIN)/cnc-service --endpoint $(ENDPOINT) $(if $(ADS),--ads $(ADS)) $(if $(OPCUA),--opcua $(OPCUA)) \
		$(if $(DATA_DIR),--data-dir $(DATA_DIR)) $(if $(CONFIG),--config $(CONFIG)) $(if $(MACHINE),--machine $(MACHINE))
endif

# The checkers first (ruff: lint and import order; mypy, strict: tools/typecheck.py), then
# the tests in TEST_WORKERS processes (pytest-xdist; most tests wait on a service, a
# browser or a subprocess, so 4 workers keep 2 cores busy), without the slow reruns that
# `make soak` runs (marker soak); worksteal: an idle worker takes queued tests from a busy
# one, so the long tests do not end the run alone. TEST_WORKERS=0: one process, in order.
TEST_WORKERS ?= 4
test: $(VENV)/.installed-test $(VENV)/.native
	$(BIN)/ruff check .
	$(BIN)/python tools/typecheck.py
	$(BIN)/python -m pytest -n $(TEST_WORKERS) --dist worksteal -m "not soak" $(PYTEST_ARGS)

# The tests of `make test` with line coverage of the package (services, cnc-web and cnc
# subprocesses included): a table of what is missed, and build/coverage.json, which
# tools/coverage_diff.py compares with the report of an earlier commit.
coverage: $(VENV)/.installed-test $(VENV)/.native
	rm -f .coverage .coverage.*
	$(BIN)/python -m pytest -n $(TEST_WORKERS) -m "not soak" --cov --cov-report=term:skip-covered \
		--cov-report=json:build/coverage.json $(PYTEST_ARGS)

bench: $(VENV)/.installed-test $(VENV)/.native
	$(BIN)/python -m bench

# The long form of tests/reliability (100 000 fuzzed frames, 640 NC mutants, 1.5 M load
# requests, 20 restarts of each kind): bounded, about 16 minutes on a 2-core machine; and
# 300 programs run under both virtual clocks (event speed against stepping), and the
# equality properties of issue 37 with many new examples (docs/testing.md); then the slow
# reruns marked soak (the decoder's tests again with its plain constructors).
soak: $(VENV)/.installed-test
	$(BIN)/python -m pytest tests/reliability tests/service/kernel/test_event_speed_clock.py \
		tests/service/kernel/test_equality_properties.py tests/e2e/test_repeatable_properties.py \
		-q --soak $(PYTEST_ARGS)
	$(BIN)/python -m pytest -q -m soak $(PYTEST_ARGS)

# Code made from other code: the blocking Client from AsyncClient's methods, and the typed
# object names (clients/names.py) from the catalog. A test fails when either is stale.
generate: $(VENV)/.installed
	$(BIN)/python tools/gen_blocking_client.py
	$(BIN)/python tools/gen_names.py

clean:
	rm -rf $(VENV) build *.egg-info .pytest_cache
