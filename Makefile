# Two commands: `make book` and `make test`.  Both bootstrap .venv from a bare
# python3 (venv + pip), installing the pinned versions in constraints.txt.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed

.PHONY: book test bench clean

$(STAMP): pyproject.toml constraints.txt
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet -c constraints.txt -e '.[book,test]'
	touch $(STAMP)

book: $(STAMP)
	$(BIN)/jupyter-book build book --warningiserror --keep-going --quiet
	$(BIN)/python book/check_offline.py book/_build/html
	@echo "$(CURDIR)/book/_build/html/index.html"

test: $(STAMP)
	$(BIN)/python -m pytest verify tests

bench: $(STAMP)
	$(BIN)/python benchmarks/bench_render.py

clean:
	rm -rf book/_build .pytest_cache .benchmarks
