# sarcli — set-up, demo, tests, benchmarks, lint and batch reprocessing.
# Only Python 3.11 and make are needed; everything else is installed into .venv.

PYTHON ?= $(shell command -v python3.11 2>/dev/null || command -v python3)
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed-stamp
DEMO   := demo
export NUMBA_CACHE_DIR ?= $(CURDIR)/.numba_cache

.PHONY: install demo test test-fast bench lint clean

$(STAMP): pyproject.toml
	@test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install -q --upgrade pip
	$(BIN)/python -m pip install -q -e '.[dev]'
	@touch $@

install: $(STAMP)

## demo: the main job on the embedded default sample (see README "Demo")
demo: $(STAMP)
	@mkdir -p $(DEMO)
	$(BIN)/sarcli simulate samples/rs1_point.toml -o $(DEMO)/raw.h5
	$(BIN)/sarcli simulate samples/rs1_point.toml --format ceos -o $(DEMO)/ceos
	$(BIN)/sarcli ingest $(DEMO)/ceos -o $(DEMO)/ingested.h5
	$(BIN)/sarcli info $(DEMO)/ingested.h5

## test: the whole suite (what CI runs)
test: $(STAMP)
	$(BIN)/python -m pytest -q -n 2 --dist loadfile

## bench: every benchmark in bench/, results in bench/results/
bench: $(STAMP)
	$(BIN)/python -m bench.run_all

lint: $(STAMP)
	$(BIN)/ruff check sarcli orbit tests bench

clean:
	rm -rf $(DEMO) .pytest_cache .hypothesis .numba_cache
