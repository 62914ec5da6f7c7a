# tfloc: the commands of the README are `make quick`, `make bench` and `make test`.
# Each creates .venv on first use and (re)installs when pyproject.toml or requirements.lock changes:
# the exact versions of requirements.lock (hash-checked), then tfloc itself without dependencies.
# The lock is complete (uv's universal resolution), so pip installs it with --no-deps: pip resolves
# nothing against the index (a newer release on PyPI cannot change or break the install), and
# pip check then proves that the installed set satisfies every requirement of every package.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.tfloc-installed
LOCK   := requirements.lock
UV_VERSION := 0.13.9

## The site (tfloc site) is written at the end of make bench (results/site/) and make quick (results/site-quick/).
.PHONY: install lock browser system site quick bench native native-single-scan sequences-single-scan global-full global-offices robustness robustness-full scaling scaling-quick ablation-real test test-cpu test-sweeps test-unit timing lint clean-venv real-data fuzz chaos

$(STAMP): pyproject.toml $(LOCK)
	@test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install -qq --no-deps --require-hashes -r $(LOCK)
	$(BIN)/python -m pip check
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

## A quick first run (about 4 minutes on 2 cores from a fresh clone, 2.5 after the install):
## every single-scan matcher on the first 3 scans of every group of the paper protocol with its
## quick timing pass and report, every tracker along one short sequence, and their site →
## results/site-quick/index.html
quick: $(STAMP)
	$(BIN)/tfloc bench benchmarks/paper-protocol.toml benchmarks/sequences-quick.toml --quick --regenerate
	$(BIN)/tfloc site --only-quick

## The main job: every study below (each file declares its run and the steps that make its tables:
## timing pass, report, robustness section, relations note, the global index), then the site and
## the README's generated tables. About 100 min on 2 cores; run again, it resumes.
STUDIES := paper-protocol real-csail-relations real-scan-to-map tf-readings tf-readings-heldout \
	tfplus-ablation sequences kidnap kidnap-controls robustness scaling-quick global native-csail \
	native-no-truth
bench: $(STAMP) system
	$(BIN)/tfloc bench $(STUDIES:%=benchmarks/%.toml) --regenerate
	$(BIN)/tfloc site --readme
	$(MAKE) --no-print-directory test-sweeps

## The leaderboards' site from the committed runs → results/site/index.html (opens from disk), and
## the README's and docs' generated blocks from the same rows.
site: $(STAMP)
	$(BIN)/tfloc site --readme

## The Debian packages below for make bench and make test, so that the two commands do all the
## set-up; where they cannot be installed (no root), one note, and the browser test and mrpt-pf's
## tests are skipped with that reason (mrpt-pf's rows in make bench: one line naming mrpt-apps).
system:
	@$(MAKE) --no-print-directory browser || echo "note: Debian's chromium, chromium-driver and mrpt-apps could not be installed (apt-get needs root): the browser test and mrpt-pf are skipped"

## Headless Chromium and chromedriver from Debian's packages, for the site's browser test and
## screenshots, and Debian's mrpt-apps (pf-localization, carmen2rawlog, ros-map-yaml2mrpt: the
## external program behind mrpt-pf), each installed when missing (nothing is downloaded at run
## time). .ci/run runs it.
browser:
	@command -v chromium >/dev/null && command -v chromedriver >/dev/null || \
		(apt-get update && apt-get install -y chromium chromium-driver)
	@command -v pf-localization >/dev/null && command -v carmen2rawlog >/dev/null && \
		command -v ros-map-yaml2mrpt >/dev/null || (apt-get update && apt-get install -y mrpt-apps)

## Studies outside make bench, one line each (benchmarks/NAME.toml says what and how long):
## native (every native recording, 22 627 scans, 20-40 min), native-single-scan (the same in the
## single-scan protocol's configuration), sequences-single-scan, global-full (every global scan),
## global-offices, robustness-full (every scan), scaling (the full study), ablation-real.
native native-single-scan sequences-single-scan global-full global-offices robustness robustness-full scaling scaling-quick: $(STAMP)
	$(BIN)/tfloc bench benchmarks/$@.toml --regenerate

ablation-real: $(STAMP)
	$(BIN)/tfloc bench benchmarks/tfplus-ablation-real.toml --regenerate

## Rebuild the real-log datasets and grid maps from data/real/ (deterministic).
real-data: $(STAMP)
	$(BIN)/tfloc real-data --out data

## Unit tests, the accuracy regression guard and a benchmark smoke run (CI), then test-cpu. First
## tests/warm_kernels.py compiles tfloc's kernels into numba's cache, each once, in two processes
## (else both test processes and the commands the tests run compile them again while the cache
## is empty). The tests run in two processes (pytest-xdist), a test file whole in one. The
## longer members of a parametrised check and the full rebuilds (marker sweep) are left to
## make test-sweeps, which make bench runs. The smoke run stays in one process.
XDIST := -n 2 --dist loadfile
test: $(STAMP) system
	$(BIN)/python tests/warm_kernels.py
	$(BIN)/python -m pytest -q $(XDIST) tests
	$(BIN)/python -m pytest -q benchmarks --benchmark-disable
	$(MAKE) --no-print-directory test-cpu

## The sweeps make test leaves out (pytest -m sweep), then those that compare with committed files
## at the CPU levels of test-cpu.
test-sweeps: $(STAMP)
	$(BIN)/python -m pytest -q $(XDIST) -m sweep tests
	$(MAKE) --no-print-directory test-cpu CPU_MARK="sweep and bitwise"

## The tests that compare with committed files or pinned values (marker bitwise) again, as a CPU
## without AVX-512 computes (numpy's dispatch below X86_V4, OpenBLAS's Haswell kernels), then
## one without AVX2 (numpy's baseline, OpenBLAS's Sandybridge kernels): what another CPU of the
## machine's kind would get, shown on this one (tests/cpu_levels.py names the features). A level
## this machine computes at anyway (no AVX-512 on its CPU, OpenBLAS on those kernels) is skipped:
## the plain pass of make test is that pass.
CPU_MARK := bitwise
test-cpu: $(STAMP)
	@for level in no-avx512 no-avx2; do \
		if $(BIN)/python tests/cpu_levels.py --native $$level; then \
			echo "test-cpu $$level: skipped, this machine computes so anyway (tests/cpu_levels.py --native)"; continue; fi; \
		features="$$($(BIN)/python tests/cpu_levels.py $$level)" && \
		coretype="$$($(BIN)/python -c "import sys; sys.path.insert(0, 'tests'); import cpu_levels; print(cpu_levels.OPENBLAS_CORETYPE['$$level'])")" && \
		echo "test-cpu $$level: NPY_DISABLE_CPU_FEATURES='$$features' OPENBLAS_CORETYPE=$$coretype" && \
		TFLOC_CPU_LEVEL=$$level NPY_DISABLE_CPU_FEATURES="$$features" OPENBLAS_CORETYPE=$$coretype \
			$(BIN)/python -m pytest -q $(XDIST) -m "$(CPU_MARK)" tests || exit 1; \
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
