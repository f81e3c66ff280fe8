# sarcli — set-up, demo, tests, benchmarks, lint and batch reprocessing.
# Only Python 3.11 and make are needed; everything else is installed into .venv.

PYTHON ?= $(shell command -v python3.11 2>/dev/null || command -v python3)
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed-stamp
DEMO   := demo
# The tested set: exact versions of every package in .venv (make lock); make install applies it.
LOCK   := requirements/constraints.txt
LOCK_VENV ?= $(VENV)
LATEST := .venv-latest
WARM   := $(VENV)/warm-up

.PHONY: install warm-cache demo test test-latest lock bench lint typecheck clean

$(STAMP): pyproject.toml $(LOCK)
	@test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install -q -c $(LOCK) --upgrade pip
	$(BIN)/python -m pip install -q -c $(LOCK) -e '.[dev]'
	@$(MAKE) --no-print-directory warm-cache
	@touch $@

install: $(STAMP)

## lock: write the exact versions installed in $(LOCK_VENV) to $(LOCK) (see docs/dependencies.md);
##   after a green `make test-latest`: make lock LOCK_VENV=.venv-latest && make install
lock:
	@test -x $(LOCK_VENV)/bin/python || { echo "make lock: no environment $(LOCK_VENV) (run make install)" >&2; exit 2; }
	@mkdir -p $(dir $(LOCK))
	@{ echo "# The tested set: every package of $(LOCK_VENV), exact versions; written by 'make lock', applied by"; \
	   echo "# 'make install' (pip install -c). Python $$($(LOCK_VENV)/bin/python -c 'import platform; print(platform.python_version(), platform.system(), platform.machine())')."; \
	   echo "# Do not edit by hand: see docs/dependencies.md."; \
	   $(LOCK_VENV)/bin/python -m pip freeze --all --exclude-editable | grep -viE '^(sarcli|setuptools|wheel)=='; \
	 } > $(LOCK).tmp && mv $(LOCK).tmp $(LOCK)
	@echo "make lock: $$(grep -vc '^#' $(LOCK)) packages from $(LOCK_VENV) written to $(LOCK)"

## test-latest: a fresh $(LATEST) with the newest releases (no constraints), the whole suite in it,
##   and a report of what is newer than the lock and which tests broke (docs/dependencies.md)
test-latest:
	rm -rf $(LATEST)
	$(PYTHON) -m venv $(LATEST)
	$(LATEST)/bin/python -m pip install -q --upgrade pip
	$(LATEST)/bin/python -m pip install -q --upgrade -e '.[dev]'
	NUMBA_CACHE_DIR=$(CURDIR)/.numba_cache-latest $(LATEST)/bin/python .ci/test_latest.py --lock $(LOCK) \
	  -- -q -n 2 --dist loadfile

## warm-cache: byte-compile the package (an editable install has no .pyc until a run writes them, and none
##   is ever written where PYTHONDONTWRITEBYTECODE is set: 0.4 s of compiling per command), then compile the
##   numba kernels of the main commands into the per-user cache (sarcli/__init__.py) on small samples (CEOS
##   ingest, Doppler with the gain-step search, focus with its GeoTIFF and quicklook, GB-SAR focus), so
##   that the first command after install loads them instead of compiling (run by install; make demo then
##   compiles nothing)
warm-cache:
	@rm -rf $(WARM) && mkdir -p $(WARM)
	$(BIN)/python -m compileall -q sarcli orbit
	$(BIN)/sarcli -q simulate samples/rs1_point.toml -o $(WARM)/raw.h5
	$(BIN)/sarcli -q simulate samples/rs1_point.toml --format ceos -o $(WARM)/ceos
	$(BIN)/sarcli -q ingest $(WARM)/ceos -o $(WARM)/ingested.h5
	$(BIN)/sarcli doppler -q $(WARM)/raw.h5 -o $(WARM)/doppler.h5
	$(BIN)/sarcli doppler -q $(WARM)/raw.h5 --ambiguity data --fr-method mapdrift --gain-steps on
	$(BIN)/sarcli -q focus $(WARM)/raw.h5 --doppler $(WARM)/doppler.h5 -o $(WARM)/slc.h5 \
	  --geotiff $(WARM)/slc.tif --quicklook $(WARM)/slc.png
	@# the phase-only line correction (real data with a Doppler model varying across the block; no small
	@# sample takes that path): a view of a block buffer, as rda.RDFocuser.focus_block passes it
	$(BIN)/python -c "import numpy as np; from sarcli.focus.rda import apply_line_phase as f; \
	  f(np.zeros((4, 9), np.complex64)[:, :8], 0, np.array([0, 4]), np.array([0, 7]), np.zeros((2, 2)))"
	$(BIN)/sarcli -q gbsar simulate samples/gbsar_indoor.toml -o $(WARM)/scan.h5
	for a in auto df rd bp; do $(BIN)/sarcli -q gbsar focus $(WARM)/scan.h5 --algorithm $$a -o $(WARM)/$$a.h5 || exit 1; done
	@rm -rf $(WARM)

## demo: the main job on the embedded default sample (see README "Demo")
demo: $(STAMP)
	@mkdir -p $(DEMO)
	$(BIN)/sarcli simulate samples/rs1_point.toml -o $(DEMO)/raw.h5
	$(BIN)/sarcli simulate samples/rs1_point.toml --format ceos -o $(DEMO)/ceos
	$(BIN)/sarcli ingest $(DEMO)/ceos -o $(DEMO)/ingested.h5
	$(BIN)/sarcli info $(DEMO)/ingested.h5
	$(BIN)/sarcli doppler $(DEMO)/raw.h5 -o $(DEMO)/doppler.h5
	$(BIN)/sarcli focus $(DEMO)/raw.h5 --doppler $(DEMO)/doppler.h5 -o $(DEMO)/slc.h5 --geotiff $(DEMO)/amplitude.tif \
	  --geotiff-slant $(DEMO)/amplitude_slant.tif --quicklook $(DEMO)/quicklook.png
	$(BIN)/sarcli quality $(DEMO)/slc.h5

## test: the whole suite (what CI runs)
test: $(STAMP)
	$(BIN)/python -m pytest -q -n 2 --dist loadfile

## bench: every benchmark in bench/, results in bench/results/
bench: $(STAMP)
	$(BIN)/python -m bench.run_all

lint: $(STAMP)
	$(BIN)/ruff check sarcli orbit tests bench

## typecheck: mypy on the typed public API (the files of [tool.mypy] in pyproject.toml; docs/extending.md)
typecheck: $(STAMP)
	$(BIN)/python -m mypy

## batch: reprocess a folder, raw -> doppler -> slc -> GeoTIFF + quicklook (focus, issue 5):
##   make batch IN=dir OUT=dir [-j N]. IN holds raw products (NAME.h5) and CEOS scene folders
##   (NAME/ with DAT_01.001, ingested first). Only what is missing or older than its inputs is rebuilt;
##   the first bad input stops make with the file's name (sarcli: error: ...).
BATCH_H5    := $(if $(IN),$(wildcard $(IN)/*.h5))
BATCH_CEOS  := $(if $(IN),$(patsubst %/DAT_01.001,%,$(wildcard $(IN)/*/DAT_01.001)))
BATCH_NAMES := $(notdir $(basename $(BATCH_H5))) $(notdir $(BATCH_CEOS))
FOCUS_FLAGS ?=

.PHONY: batch
batch: $(STAMP)
	@test -n "$(IN)" -a -n "$(OUT)" || { echo "usage: make batch IN=dir OUT=dir [-j N]" >&2; exit 2; }
	@test -d "$(IN)" || { echo "make batch: input folder $(IN) does not exist" >&2; exit 2; }
	@test -n "$(strip $(BATCH_NAMES))" || { echo "make batch: no raw products or CEOS folders in $(IN)" >&2; exit 2; }
	@$(MAKE) --no-print-directory $(foreach n,$(BATCH_NAMES),$(OUT)/$(n).tif $(OUT)/$(n).png)

$(OUT):
	@mkdir -p $@

$(OUT)/%.raw.h5: $(IN)/%/DAT_01.001 | $(OUT)
	$(BIN)/sarcli ingest $(IN)/$* -o $@

$(OUT)/%.doppler.h5: $(IN)/%.h5 | $(OUT)
	$(BIN)/sarcli doppler $< -o $@

$(OUT)/%.doppler.h5: $(OUT)/%.raw.h5 | $(OUT)
	$(BIN)/sarcli doppler $< -o $@

$(OUT)/%.slc.h5 $(OUT)/%.tif $(OUT)/%.png: $(IN)/%.h5 $(OUT)/%.doppler.h5
	$(BIN)/sarcli focus $< --doppler $(word 2,$^) -o $(OUT)/$*.slc.h5 --geotiff $(OUT)/$*.tif \
	  --quicklook $(OUT)/$*.png $(FOCUS_FLAGS)

$(OUT)/%.slc.h5 $(OUT)/%.tif $(OUT)/%.png: $(OUT)/%.raw.h5 $(OUT)/%.doppler.h5
	$(BIN)/sarcli focus $< --doppler $(word 2,$^) -o $(OUT)/$*.slc.h5 --geotiff $(OUT)/$*.tif \
	  --quicklook $(OUT)/$*.png $(FOCUS_FLAGS)

.PRECIOUS: $(OUT)/%.raw.h5 $(OUT)/%.doppler.h5 $(OUT)/%.slc.h5

clean:
	rm -rf $(DEMO) .pytest_cache .hypothesis .numba_cache .numba_cache-latest $(LATEST)
	rm -rf $(DEMO) .pytest_cache .hypothesis
