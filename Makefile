# Two entry points for humans: `make demo` and `make test`.
PYTHON ?= python3
VENV   := .venv
STAMP  := $(VENV)/.installed

.PHONY: venv demo test

venv: $(STAMP)

# torch is installed first and on its own so pip keeps the CPU wheel instead of
# resolving a CUDA build while solving the whole dependency set.
$(STAMP): pyproject.toml
	test -x $(VENV)/bin/python || $(PYTHON) -m venv $(VENV)
	$(VENV)/bin/pip install torch==2.13.0
	$(VENV)/bin/pip install -e '.[test]'
	touch $(STAMP)

demo: venv
	$(VENV)/bin/twin demo

test: venv
	$(VENV)/bin/python -m pytest
