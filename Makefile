# The README's commands. Every target bootstraps what it needs:
#   .venv (pinned wheels, only when a requirements file changed) -> colcon build (only when sources
#   changed). `make demo` installs requirements/runtime.txt only; `make test` adds the extras
#   (test, learning, sweep, browser), each its own stamp file in .venv, and Chromium
#   (scripts/ensure_test_tools.py).
# Imports (doc/guide/install.md): scripts import the ship_* packages from the colcon install, so
# the targets that run them source install/setup.bash first ($(WITH_INSTALL)); pytest imports
# them from the source folders pytest.ini names (tests/conftest.py hands the same to the
# processes tests start).
SHELL := /bin/bash
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
WS := ros_ws
SRC_FILES := $(shell find $(WS)/src -type f -not -path '*/__pycache__/*' -not -name '*.pyc' 2>/dev/null)
SCENARIO ?= scenarios/flagship_mariner.yaml
# What `source install/setup.bash` gives a shell (PYTHONPATH, AMENT_PREFIX_PATH, ...), for a recipe.
WITH_INSTALL := source $(WS)/install/setup.bash &&
PYTEST_ARGS ?=
# pytest worker processes for `make test` (pytest-xdist; 2 by default, 0 for the suite in one
# process). With --dist loadgroup every integration file that starts a graph goes to one
# worker, so no two graph tests run at a time, and every other file stays whole on a worker, so
# its module-scoped runs are made once (the scheduler: tests/conftest.py).
TEST_JOBS ?= 2

.PHONY: all venv venv-sweep venv-test venv-interop venv-judge build demo lint docs test bench clean distclean

all: build

venv: $(VENV)/.installed
# Ray and the learning environment for scripts/sweep.py --ray (its message names this target).
venv-sweep: $(VENV)/.installed-sweep
# Everything the test suite needs (kernels: numba, so the tests run both kernel backends).
venv-test: $(VENV)/.installed-test $(VENV)/.installed-kernels $(VENV)/.installed-sweep \
  $(VENV)/.installed-browser $(VENV)/.installed-interop
# maritime-schema (scenario JSON other tools read: scripts/imazu/maritime_schema_io.py).
venv-interop: $(VENV)/.installed-interop
# The independent COLREGs judge (scripts/colregs_judge.py): TUM's CommonOcean rule monitor is
# GPL-3.0 and pins packages that conflict with ours, so it gets a venv of its own, which only
# scripts/commonocean_monitor.py runs in (a subprocess exchanging JSON), never imported here.
JUDGE_VENV := .venv-judge
venv-judge: $(JUDGE_VENV)/.installed
$(JUDGE_VENV)/.installed: requirements-judge.txt
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
$(VENV)/.installed-docs $(VENV)/.installed-interop: requirements/jinja.txt

# A venv made before the imports went through the install may still hold the shipnav.pth that
# put the source folders on every interpreter's path: removed, so that nothing imports by it.
build: $(WS)/install/.built
	@rm -f $(VENV)/lib/python3*/site-packages/shipnav.pth

$(WS)/install/.built: $(VENV)/.installed $(SRC_FILES)
	cd $(WS) && source ../$(VENV)/bin/activate && \
	  colcon --log-base log build --base-paths src --event-handlers console_cohesion- summary- status- \
	  >/dev/null || (cat log/latest_build/*/stdout_stderr.log; exit 1)
	@touch $@
	@echo "built $(WS)/install (source $(WS)/install/setup.bash to use it)"

demo: build
	$(WITH_INSTALL) $(PY) scripts/run_mission.py $(SCENARIO)

# The rules are in ruff.toml.
lint: $(VENV)/.installed-test
	$(VENV)/bin/ruff check .

# The documentation site (mkdocs.yml) into site/: strict, so a broken link, anchor or repository
# path fails it; offline (the theme and its assets come from the wheel). Not --quiet: it raises
# mkdocs' log level above WARNING, so warnings are neither shown nor counted and strict mode
# passed a broken link; the INFO lines are filtered instead (pipefail keeps mkdocs' exit code).
docs: build $(VENV)/.installed-docs
	set -o pipefail; $(WITH_INSTALL) NO_MKDOCS_2_WARNING=1 $(VENV)/bin/mkdocs build 2>&1 | { grep -v '^INFO ' || true; }
	@echo "built site/ (open site/index.html)"

# ensure_test_tools.py installs the test tools (Chromium, gpsdecode) as root with apt-get, or says which
# tests will skip and the command that installs it.
test: build venv-test lint docs
	@$(WITH_INSTALL) $(PY) scripts/ensure_test_tools.py
	$(PY) -m pytest -n $(TEST_JOBS) --dist loadgroup $(PYTEST_ARGS)

# The benchmarks use every extra: gymnasium (controllers), Ray (sweep), websockets (live view).
bench: build venv-test
	$(WITH_INSTALL) $(PY) scripts/bench.py

clean:
	rm -rf $(WS)/build $(WS)/install $(WS)/log

distclean: clean
	rm -rf $(VENV) runs site
