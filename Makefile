# The README's commands. Every target bootstraps what it needs:
#   .venv (pinned wheels, only when requirements.txt changed) -> colcon build (only when sources changed).
SHELL := /bin/bash
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
WS := ros_ws
SRC_FILES := $(shell find $(WS)/src -type f -not -path '*/__pycache__/*' -not -name '*.pyc' 2>/dev/null)
SCENARIO ?= scenarios/flagship_mariner.yaml
PYTEST_ARGS ?=

.PHONY: all venv build demo test bench clean distclean

all: build

venv: $(VENV)/.installed

$(VENV)/.installed: requirements.txt
	@test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --disable-pip-version-check -q -r requirements.txt
	@touch $@

build: $(WS)/install/.built

$(WS)/install/.built: $(VENV)/.installed $(SRC_FILES)
	cd $(WS) && source ../$(VENV)/bin/activate && \
	  colcon --log-base log build --base-paths src --event-handlers console_cohesion- summary- status- \
	  >/dev/null || (cat log/latest_build/*/stdout_stderr.log; exit 1)
	@touch $@
	@echo "built $(WS)/install (source $(WS)/install/setup.bash to use it)"

demo: build
	$(PY) scripts/run_mission.py $(SCENARIO)

test: build
	$(PY) -m pytest $(PYTEST_ARGS)

bench: build
	$(PY) scripts/bench.py

clean:
	rm -rf $(WS)/build $(WS)/install $(WS)/log

distclean: clean
	rm -rf $(VENV) runs
