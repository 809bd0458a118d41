# The two commands of the README: `make demo` and `make test`. Both create .venv on first use.
# `make test-blender`: the real-Blender tier (Debian's Blender 4.3 in a chroot under .cache/; root).
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed

.PHONY: demo test test-blender lint extension clean

$(STAMP): requirements.txt
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -r requirements.txt
	touch $(STAMP)

demo: $(STAMP)
	$(PY) -m addon demo --out out/demo

test: $(STAMP)
	$(PY) -m pytest -q

test-blender: $(STAMP)
	$(PY) tools/real_blender.py setup
	BOUNCE_REAL_BLENDER=1 $(PY) -m pytest -q tests/real_blender

lint: $(STAMP)
	$(PY) -m ruff check .

extension: $(STAMP)
	$(PY) tools/build_extension.py --out dist

clean:
	rm -rf out dist .pytest_cache
