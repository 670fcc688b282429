# Two commands: `make book` and `make test`.  Both bootstrap .venv from a bare
# python3 (venv + pip), installing the pinned versions in constraints.txt: python3's pip installs
# uv (pinned there too) into a venv made without pip, and uv the project and pip (39 s against pip's 96 s
# on a fresh machine, when both compiled the whole venv's bytecode; see below for why it no longer does).
# The venv's own pip from ensurepip took 4.7 s of a 7 s install; this way the install takes about 4 s.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
# Python caches the bytecode of what it imports (the venv's packages, the project, pytest's rewritten
# tests) at its first import, here even where PYTHONDONTWRITEBYTECODE is set: without the caches each
# test worker compiles them again (4 s more per pytest process), and compiling the whole venv up front
# (uv's --compile-bytecode) costs 22 s of the install, mostly for modules never imported.  Fresh clones,
# .ci/run side by side: 5 min 18 s against 5 min 54 s (install 8 s against 20, make test 121 s against 135).
unexport PYTHONDONTWRITEBYTECODE

.PHONY: book test audit test-baseline-simd bench clean

# MathJax 4, which the site serves itself, comes from the npm registry's tarballs, checked against pinned
# sha512 digests (book/fetch_mathjax.py; no node needed), into book/_vendor.
$(STAMP): pyproject.toml constraints.txt book/fetch_mathjax.py
	$(PYTHON) -m venv --without-pip $(VENV)
	$(PYTHON) -m pip --python $(BIN)/python install --quiet -c constraints.txt uv
	$(BIN)/uv pip install --quiet --python $(BIN)/python -c constraints.txt -e '.[book,test]' pip
	$(BIN)/python book/fetch_mathjax.py
	touch $(STAMP)

# book/_ext/execute_pages.py runs jupyter-book's command line (`jupyter-book build`) with the
# build's own handling of Ctrl-C and SIGTERM from its first instant: one line, exit 130 or 143,
# no process of the build left.  The build takes book/.build.lock: a second one in the tree waits.
# The checks after it only read, and each prints a line naming itself; they run with SIGINT
# ignored, so that a Ctrl-C meanwhile stops make when the check ends, without a traceback.
UNINTERRUPTED := $(BIN)/python -c 'import os, signal, sys; signal.signal(signal.SIGINT, signal.SIG_IGN); os.execv(sys.executable, [sys.executable, *sys.argv[1:]])'
book: $(STAMP)
	$(BIN)/python book/_ext/execute_pages.py build book --warningiserror --keep-going --quiet
	@$(UNINTERRUPTED) book/check_offline.py book/_build/html
	@$(UNINTERRUPTED) book/check_glue.py book/_build/.jupyter_cache book/_build/html
	@echo "$(CURDIR)/book/_build/html/index.html"

# The book first, then the checker and the tests on every CPU; the audits of the built site
# (marked "audit": the tests that read it, tests/conftest.py) are `make audit`'s.  --dist worksteal:
# a worker that runs out takes tests from the other (dealt by module, the process-heavy modules
# left one worker running alone at the end: 140-145 s against 124-137 s on 2 cores).
test: book
	$(BIN)/python -m pytest -n auto --dist worksteal -m "not audit" verify tests

# The built site's audits: the browser tests (Chromium) and the checks that read book/_build/html, dealt
# out one by one but for those sharing a module's page loads (tests/conftest.py's xdist groups): by module,
# the browser tests went to one worker.  One worker more than the CPUs: a worker waiting on its browser
# (a load, a timer, an animation) leaves a CPU to the others (2 CPUs, 4 runs each, alternated: medians
# 116 s with 3 workers, 124 s with 2; make test's workers wait on nothing, and 3 made it slower).
AUDIT_WORKERS := $(shell echo $$(( $$(nproc) + 1 )))
audit: book
	SYMRENDER_BOOK_HTML=$(CURDIR)/book/_build/html $(BIN)/python -m pytest -n $(AUDIT_WORKERS) --dist loadgroup -m audit tests

# The checks whose numbers could depend on the CPU's code paths (marked cpu_dependent: the theorems
# whose checks compare the renderer's outputs with mpmath, and parity with the scalar reference)
# again, with numpy's optional SIMD features (those found on this CPU beyond its baseline) disabled
# and the kernel compiled by numba for a generic x86-64 CPU (into a cache of its own).  The tests
# are dealt out one by one (--dist load): by module, parity's 378 went to one worker.
NUMERIC_TESTS := verify/test_theorems.py tests/test_parity.py
test-baseline-simd: $(STAMP)
	@features="$$($(BIN)/python -c 'from numpy._core._multiarray_umath import __cpu_dispatch__ as d, __cpu_features__ as f; print(" ".join(x for x in d if f[x]))')" \
	  || { echo "test-baseline-simd: cannot list numpy's CPU features" >&2; exit 1; }; \
	echo "NPY_DISABLE_CPU_FEATURES=\"$$features\""; \
	cache="$$(mktemp -d)"; trap 'rm -rf "$$cache"' EXIT; \
	NPY_DISABLE_CPU_FEATURES="$$features" NUMBA_CPU_NAME=generic NUMBA_CACHE_DIR="$$cache" \
	  $(BIN)/python -m pytest -n auto --dist load -m cpu_dependent $(NUMERIC_TESTS) -p no:cacheprovider

bench: $(STAMP)
	$(BIN)/python benchmarks/bench_render.py

clean:
	rm -rf book/_build .pytest_cache .benchmarks
