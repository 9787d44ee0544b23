# The README's commands. Every target bootstraps what it needs:
#   .venv (pinned wheels, only when requirements.txt changed) -> colcon build (only when sources changed).
# The venv also gets one .pth file naming the packages' source folders and scripts/, so that
# `.venv/bin/python scripts/X.py` and pytest import ship_* and mission without sys.path edits.
SHELL := /bin/bash
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
WS := ros_ws
SRC_FILES := $(shell find $(WS)/src -type f -not -path '*/__pycache__/*' -not -name '*.pyc' 2>/dev/null)
SCENARIO ?= scenarios/flagship_mariner.yaml
# Folders the venv's shipnav.pth puts on sys.path: every package of ros_ws/src, and scripts/.
PATH_DIRS := $(abspath $(sort $(dir $(wildcard $(WS)/src/*/package.xml))) scripts)
PYTEST_ARGS ?=

.PHONY: all venv paths build demo lint docs test bench clean distclean

all: build

venv: $(VENV)/.installed paths

$(VENV)/.installed: requirements.txt
	@test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --disable-pip-version-check -q -r requirements.txt
	@touch $@

# Runs every time (cheap) and rewrites the .pth only when PATH_DIRS changed (a package added,
# removed or renamed, or the checkout moved). A venv serves one checkout: one shared by several
# checkouts imports from whichever ran make last (the old list is printed when it is replaced).
paths: $(VENV)/.installed
	@pth=$$($(PY) -c 'import sysconfig; print(sysconfig.get_path("purelib"))')/shipnav.pth; \
	  new=$$(printf '%s\n' $(PATH_DIRS)); old=$$(cat $$pth 2>/dev/null); \
	  if [ "$$new" != "$$old" ]; then \
	    printf '%s\n' "$$new" > $$pth && echo "wrote $$pth:" && sed 's/^/  /' $$pth && \
	    if [ -n "$$old" ]; then echo "  (it named:"; echo "$$old" | sed 's/^/  /'; echo "  )"; fi; fi

build: $(WS)/install/.built paths

$(WS)/install/.built: $(VENV)/.installed $(SRC_FILES)
	cd $(WS) && source ../$(VENV)/bin/activate && \
	  colcon --log-base log build --base-paths src --event-handlers console_cohesion- summary- status- \
	  >/dev/null || (cat log/latest_build/*/stdout_stderr.log; exit 1)
	@touch $@
	@echo "built $(WS)/install (source $(WS)/install/setup.bash to use it)"

demo: build
	$(PY) scripts/run_mission.py $(SCENARIO)

# The rules are in ruff.toml.
lint: $(VENV)/.installed
	$(VENV)/bin/ruff check .

# The documentation site (mkdocs.yml): strict, so a broken link, anchor or repository path
# fails it; offline (the theme and its assets come from the wheel).
$(VENV)/.docs-installed: requirements-docs.txt $(VENV)/.installed
	$(PY) -m pip install --disable-pip-version-check -q -r requirements-docs.txt
	@touch $@

docs: $(VENV)/.docs-installed
	NO_MKDOCS_2_WARNING=1 $(VENV)/bin/mkdocs build --quiet
	@echo "built site/ (open site/index.html)"

test: build lint docs
	$(PY) -m pytest $(PYTEST_ARGS)

bench: build
	$(PY) scripts/bench.py

clean:
	rm -rf $(WS)/build $(WS)/install $(WS)/log

distclean: clean
	rm -rf $(VENV) runs site
