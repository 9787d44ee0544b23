# The README's commands. Every target bootstraps what it needs:
#   .venv (pinned wheels, only when a requirements file changed) -> colcon build (only when sources
#   changed). `make demo` installs requirements/runtime.txt only; `make test` adds the extras
#   (test, learning, sweep, browser), each its own stamp file in .venv, and Chromium
#   (scripts/ensure_test_tools.py).
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

.PHONY: all venv venv-sweep venv-test venv-interop venv-judge paths build demo lint docs test bench clean distclean

all: build

venv: $(VENV)/.installed paths
# Ray and the learning environment for scripts/sweep.py --ray (its message names this target).
venv-sweep: $(VENV)/.installed-sweep paths
# Everything the test suite needs.
venv-test: $(VENV)/.installed-test $(VENV)/.installed-sweep $(VENV)/.installed-browser \
  $(VENV)/.installed-interop paths
# maritime-schema (scenario JSON other tools read: scripts/imazu/maritime_schema_io.py).
venv-interop: $(VENV)/.installed-interop paths
# The independent COLREGs judge (scripts/colregs_judge.py): TUM's CommonOcean rule monitor is
# GPL-3.0 and pins packages that conflict with ours, so it gets a venv of its own, which only
# scripts/commonocean_monitor.py runs in (a subprocess exchanging JSON), never imported here.
JUDGE_VENV := .venv-judge
venv-judge: $(JUDGE_VENV)/.installed
$(JUDGE_VENV)/.installed: requirements/judge.txt
	@test -x $(JUDGE_VENV)/bin/python || $(PYTHON) -m venv $(JUDGE_VENV)
	$(JUDGE_VENV)/bin/python -m pip install --disable-pip-version-check -r $<
	@touch $@

# pip without -q: a first install takes minutes and should show what it is doing. Each stage
# ends with one line giving its time and the venv's size.
define pip_stage
	@echo "venv: installing $(1) (pip's output follows)"
	@s=$$SECONDS; $(PY) -m pip install --disable-pip-version-check -r $(1) && \
	  echo "venv: $(1) installed in $$((SECONDS - s)) s; .venv is now $$(du -sh $(VENV) | cut -f1)"
	@touch $@
endef

$(VENV)/.installed: requirements/runtime.txt
	@test -x $(PY) || { echo "venv: creating $(VENV)"; $(PYTHON) -m venv $(VENV); }
	$(call pip_stage,$<)

# The extras (requirements/<name>.txt); each stamp is remade when its file or the runtime changes.
$(VENV)/.installed-%: requirements/%.txt $(VENV)/.installed
	$(call pip_stage,$<)

# The sweep's episodes build on the learning environment (montecarlo.episodes).
$(VENV)/.installed-sweep: $(VENV)/.installed-learning
# Files that others include (-r): a change remakes the stamps of the files that include them.
$(VENV)/.installed-sweep $(VENV)/.installed-docs: requirements/http.txt

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
lint: $(VENV)/.installed-test
	$(VENV)/bin/ruff check .

# The documentation site (mkdocs.yml) into site/: strict, so a broken link, anchor or repository
# path fails it; offline (the theme and its assets come from the wheel).
docs: $(VENV)/.installed-docs paths
	NO_MKDOCS_2_WARNING=1 $(VENV)/bin/mkdocs build --quiet
	@echo "built site/ (open site/index.html)"

# ensure_test_tools.py installs the test tools (Chromium, gpsdecode) as root with apt-get, or says which
# tests will skip and the command that installs it.
test: build venv-test lint docs
	@$(PY) scripts/ensure_test_tools.py
	$(PY) -m pytest $(PYTEST_ARGS)

# The benchmarks use every extra: gymnasium (controllers), Ray (sweep), websockets (live view).
bench: build venv-test
	$(PY) scripts/bench.py

clean:
	rm -rf $(WS)/build $(WS)/install $(WS)/log

distclean: clean
	rm -rf $(VENV) runs site
