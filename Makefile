# tfloc: the commands of the README are `make quick`, `make bench` and `make test`.
# Each creates .venv on first use and (re)installs when pyproject.toml or requirements.lock changes:
# the exact versions of requirements.lock (hash-checked), then tfloc itself without dependencies.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.tfloc-installed
JOBS   ?= 2
LOCK   := requirements.lock
UV_VERSION := 0.13.9

## The site (tfloc site) is written at the end of make bench (results/site/) and make quick (results/site-quick/).
.PHONY: install lock browser site quick bench native global-full global-offices robustness robustness-full scaling scaling-quick ablation-real test test-cpu test-unit timing lint clean-venv real-data fuzz chaos

$(STAMP): pyproject.toml $(LOCK)
	@test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install -qq --require-hashes -r $(LOCK)
	$(BIN)/python -m pip install -qq --no-deps --no-build-isolation -e .
	@$(BIN)/python -c 'import sys; v = sys.version_info[:2]; v < (3, 12) or print("note: matcher karto left out: karto-scanmatcher has wheels for Python 3.8-3.11 only, this is Python %d.%d" % v)'
	@touch $(STAMP)

## Refresh the lock deliberately: resolve pyproject.toml's bounds (every extra) anew, exact versions
## with the hashes of every file of each, for every Python ≥ 3.11 (uv's universal resolution, in a
## throwaway environment). Commit the new requirements.lock with the results it makes.
lock:
	@d=$$(mktemp -d) && $(PYTHON) -m venv $$d && $$d/bin/python -m pip install --quiet 'uv==$(UV_VERSION)' && \
	printf 'pip\nsetuptools>=68\nwheel\n' | $$d/bin/uv pip compile pyproject.toml - --all-extras --universal \
		--python-version 3.11 --generate-hashes --custom-compile-command "make lock" --quiet -o $(LOCK).new && \
	rm -rf $$d && mv $(LOCK).new $(LOCK) && echo "wrote $(LOCK): $$(grep -c '==' $(LOCK)) pinned versions"

install: $(STAMP)

## A quick first run (a few minutes): every matcher on the first 3 scans of every group of the
## paper protocol, a quiet re-timing, and the full report → results/paper-protocol-quick/report.md;
## one short simulated sequence tracked; their site → results/site-quick/index.html
quick: $(STAMP)
	$(BIN)/tfloc bench benchmarks/paper-protocol.toml --quick --jobs $(JOBS) --regenerate
	$(BIN)/tfloc timing results/paper-protocol-quick --per-stratum 1
	$(BIN)/tfloc report results/paper-protocol-quick
	$(BIN)/tfloc bench benchmarks/sequences-quick.toml --jobs $(JOBS) --regenerate
	$(BIN)/tfloc report results/sequences-quick
	$(BIN)/tfloc site --only-quick

## The main job: every registered matcher on the bundled scenarios, a side-by-side timing pass
## of each run (timing.md), and the reports; then the reading study of the paper's method and the
## tf-plus ablation. About 80 min on 2 cores (README).
bench: $(STAMP)
	$(BIN)/tfloc bench benchmarks/paper-protocol.toml --jobs $(JOBS) --regenerate
	$(BIN)/tfloc timing results/paper-protocol
	$(BIN)/tfloc report results/paper-protocol
	$(BIN)/tfloc bench benchmarks/real-csail-relations.toml --jobs $(JOBS) --regenerate
	$(BIN)/tfloc timing results/real-csail-relations
	$(BIN)/tfloc report results/real-csail-relations
	$(BIN)/tfloc real-note results/real-csail-relations
	$(BIN)/tfloc bench benchmarks/real-scan-to-map.toml --jobs $(JOBS) --regenerate
	$(BIN)/tfloc timing results/real-scan-to-map
	$(BIN)/tfloc report results/real-scan-to-map
	$(BIN)/tfloc bench benchmarks/tf-readings.toml --jobs $(JOBS) --regenerate
	$(BIN)/tfloc report results/tf-readings
	$(BIN)/tfloc bench benchmarks/tf-readings-heldout.toml --jobs $(JOBS) --regenerate
	$(BIN)/tfloc report results/tf-readings-heldout
	$(BIN)/tfloc bench benchmarks/tfplus-ablation.toml --jobs $(JOBS) --regenerate
	$(BIN)/tfloc report results/tf-plus-ablation
	$(BIN)/tfloc bench benchmarks/sequences.toml --jobs $(JOBS) --regenerate
	$(BIN)/tfloc report results/sequences
	$(BIN)/tfloc bench benchmarks/kidnap.toml --jobs $(JOBS) --regenerate
	$(BIN)/tfloc report results/kidnap
	$(BIN)/tfloc bench benchmarks/kidnap-controls.toml --jobs $(JOBS) --regenerate
	$(BIN)/tfloc report results/kidnap-controls
	$(BIN)/tfloc bench benchmarks/robustness.toml --jobs $(JOBS) --regenerate
	$(BIN)/tfloc timing results/robustness
	$(BIN)/tfloc report results/robustness
	$(BIN)/tfloc robustness results/robustness
	$(MAKE) scaling-quick
	for d in global-office-1 global-office-2 global-office-3 real-intel-global real-csail-global real-aces-global; do \
		$(BIN)/tfloc index --dataset data/scenarios/$$d || exit 1; done
	$(BIN)/tfloc bench benchmarks/global.toml --jobs $(JOBS) --regenerate
	$(BIN)/tfloc report results/global
	$(BIN)/tfloc bench benchmarks/native.toml --datasets real-csail-native --out results/native-csail --jobs $(JOBS) --regenerate
	$(BIN)/tfloc report results/native-csail
	$(BIN)/tfloc site --readme

## The leaderboards' site from the committed runs → results/site/index.html (opens from disk), and
## the README's and docs' generated blocks from the same rows.
site: $(STAMP)
	$(BIN)/tfloc site --readme

## Headless Chromium and chromedriver from Debian's packages, for the site's browser test and
## screenshots (installed when missing; no browser is downloaded at run time). .ci/run runs it.
browser:
	@command -v chromium >/dev/null && command -v chromedriver >/dev/null || \
		(apt-get update && apt-get install -y chromium chromium-driver)

## Tracking the robots' own recordings at their native rate, every matcher, all three logs
## (22 627 scans) → results/native/ (benchmarks/native.toml; 20-40 min on 2 cores). make bench
## runs its fixed subsample, MIT CSAIL only (1927 scans, with the relations), → results/native-csail/.
native: $(STAMP)
	$(BIN)/tfloc bench benchmarks/native.toml --jobs $(JOBS) --regenerate
	$(BIN)/tfloc report results/native

## Global localization on every scan of the global sets (issue 24) → results/global-full/.
global-full: $(STAMP)
	for d in global-office-1 global-office-2 global-office-3 real-intel-global real-csail-global real-aces-global; do \
		$(BIN)/tfloc index --dataset data/scenarios/$$d || exit 1; done
	$(BIN)/tfloc bench benchmarks/global-full.toml --jobs $(JOBS) --regenerate
	$(BIN)/tfloc report results/global-full

## tf-global against bnb-global on every scan of the three office global sets → results/global-offices/.
global-offices: $(STAMP)
	$(BIN)/tfloc bench benchmarks/global-offices.toml --jobs $(JOBS) --regenerate
	$(BIN)/tfloc report results/global-offices

## Issue 25: every matcher on every map style of the real logs and every changed world of the
## simulated office (10 scans per offset group of each dataset; ~12 min on 2 quiet cores)
## → results/robustness/robustness.md. robustness-full: every scan (~30 min).
robustness: $(STAMP)
	$(BIN)/tfloc bench benchmarks/robustness.toml --jobs $(JOBS) --regenerate
	$(BIN)/tfloc timing results/robustness
	$(BIN)/tfloc report results/robustness
	$(BIN)/tfloc robustness results/robustness

robustness-full: $(STAMP)
	$(BIN)/tfloc bench benchmarks/robustness-full.toml --jobs $(JOBS) --regenerate
	$(BIN)/tfloc timing results/robustness-full
	$(BIN)/tfloc report results/robustness-full
	$(BIN)/tfloc robustness results/robustness-full

## The scaling study (tfloc scaling): every matcher's CPU per scan against map area (300-20 000 m²,
## vector and 5 cm grid), beam count (181-1081) and initial offset, and each map's preparation
## time and memory → results/scaling/ (README.md, scaling.png, run.json; ~15 min CPU, one pinned
## core; resumed if interrupted).
scaling: $(STAMP)
	$(BIN)/tfloc scaling --out results/scaling --regenerate

## Its fixed subsample, part of make bench: every axis and level, 9 scans per level, 9 per
## offset bin → results/scaling-quick/ (~3 min CPU).
scaling-quick: $(STAMP)
	$(BIN)/tfloc scaling --quick --out results/scaling-quick --regenerate

## tf-plus's stages switched off in turn on the real logs, as-built and thickened grids, csm-corr
## beside it → results/tf-plus-ablation-real/ (benchmarks/tfplus-ablation-real.toml; ~10 min).
ablation-real: $(STAMP)
	$(BIN)/tfloc bench benchmarks/tfplus-ablation-real.toml --jobs $(JOBS) --regenerate
	$(BIN)/tfloc report results/tf-plus-ablation-real

## Rebuild the real-log datasets and grid maps from data/real/ (deterministic).
real-data: $(STAMP)
	$(BIN)/tfloc real-data --out data

## Unit tests, the accuracy regression guard and a benchmark smoke run (CI), then test-cpu.
test: $(STAMP)
	$(BIN)/python -m pytest -q tests
	$(BIN)/python -m pytest -q benchmarks --benchmark-disable
	$(MAKE) --no-print-directory test-cpu

## The tests that compare with committed files or pinned values (marker bitwise) again, as a CPU
## without AVX-512 computes (numpy's dispatch below X86_V4, OpenBLAS's Haswell kernels), then
## one without AVX2 (numpy's baseline, OpenBLAS's Sandybridge kernels): what another CPU of the
## machine's kind would get, shown on this one (tests/cpu_levels.py names the features).
test-cpu: $(STAMP)
	@for level in no-avx512 no-avx2; do \
		features="$$($(BIN)/python tests/cpu_levels.py $$level)" && \
		coretype="$$($(BIN)/python -c "import sys; sys.path.insert(0, 'tests'); import cpu_levels; print(cpu_levels.OPENBLAS_CORETYPE['$$level'])")" && \
		echo "test-cpu $$level: NPY_DISABLE_CPU_FEATURES='$$features' OPENBLAS_CORETYPE=$$coretype" && \
		TFLOC_CPU_LEVEL=$$level NPY_DISABLE_CPU_FEATURES="$$features" OPENBLAS_CORETYPE=$$coretype \
			$(BIN)/python -m pytest -q -m bitwise tests || exit 1; \
	done

## Every reader against thousands of damaged inputs, and every matcher parameter against bad
## values (make test runs a few hundred per reader); prints how many inputs each reader tried.
fuzz: $(STAMP)
	TFLOC_FUZZ_EXAMPLES=$${TFLOC_FUZZ_EXAMPLES:-3000} TFLOC_FUZZ_RANDOM=1 $(BIN)/python -m pytest -q -s \
		tests/io/test_fuzz_readers.py tests/core/test_matcher_params.py

## The long kill tests: runs of 240 tasks killed with SIGKILL 10 times (local pool and Dask).
chaos: $(STAMP)
	$(BIN)/python -m pytest -q -m slow tests/toolchain/test_chaos.py

## Full pytest-benchmark timing (pinned to 2 cores); not part of CI.
timing: $(STAMP)
	$(BIN)/python -m pytest benchmarks --benchmark-only --benchmark-autosave

lint: $(STAMP)
	$(BIN)/ruff check .

clean-venv:
	rm -rf $(VENV)
