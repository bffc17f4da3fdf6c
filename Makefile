# acti_ros2: `make run` sets everything up and runs both nodes; `make test` sets up and tests.
SHELL := /bin/bash
PYTHON ?= python3.11
VENV := .venv
PY := $(VENV)/bin/python
ENV := source tools/env.sh
BUILD_DEPS_STAMP := $(VENV)/.build-deps-stamp
DEPS_STAMP := $(VENV)/.deps-stamp
ACTIVATE_HOOK := $(VENV)/.activate-hook
BUILD_STAMP = install/.build-stamp-cpp-$(ACTI_MSGS_CPP)
COLCON_PATHS := --base-paths . msg_defs
INTERFACES := $(shell find msg_defs -type f -not -name '*~')
# The interface packages are built for Python only (see msg_defs/CMakeLists.txt); ON adds the C++
# headers and type supports that C++ code linking against acti_msgs needs (`make build
# ACTI_MSGS_CPP=ON`; the stamp names the choice, so switching rebuilds).
ACTI_MSGS_CPP ?= OFF
NPROC := $(shell nproc)
# Every core for make (colcon's default -l also stops new jobs while the machine is busy), one
# package per core, and ccache (from requirements-build.txt) keeping compiled objects between builds
# and clones: paths relative to the checkout, so another clone hits the same entries.
BUILD_ENV := MAKEFLAGS=-j$(NPROC) CCACHE_BASEDIR=$(CURDIR) CCACHE_NOHASHDIR=true
CMAKE_ARGS := -DBUILD_TESTING=OFF -DPython3_EXECUTABLE=$(abspath $(PY)) \
  -DACTI_MSGS_CPP=$(ACTI_MSGS_CPP) -DCMAKE_C_COMPILER_LAUNCHER=ccache \
  -DCMAKE_CXX_COMPILER_LAUNCHER=ccache

BROWSER := /usr/lib/chromium/chromium-headless-shell /usr/bin/chromedriver

.PHONY: build setup stage-interfaces stage-wheels run test bench clean browser

build: $(BUILD_STAMP)

# Everything run and test need, in stages: the terminal shows a line a stage with its time
# (tools/stage.sh), what they print goes to log/setup/<stage>.log. The interface packages need
# only requirements-build.txt, so the rest of the venv (PyBullet, Pinocchio, viser: most of the
# download) is installed while they build: two jobs, whatever -j make was given.
SETUP_LOG := log/setup
STAGE := tools/stage.sh
SUBMAKE := $(MAKE) --no-print-directory
setup:
	@echo "setup: each stage's output goes to $(SETUP_LOG)/"
	+@start=$$SECONDS && \
	$(STAGE) "venv, the build's wheels (ROS 2 Python, colcon, ccache)" $(SETUP_LOG)/venv.log \
	  $(SUBMAKE) $(BUILD_DEPS_STAMP) $(ACTIVATE_HOOK) && \
	$(SUBMAKE) -j2 stage-interfaces stage-wheels && \
	$(STAGE) "the parameters list --help prints (kept in build/usage/)" $(SETUP_LOG)/usage.log \
	  bash -c '$(ENV) && python -m acti_bringup --help' && \
	took=$$((SECONDS - start)) && printf 'setup done in %d:%02d\n' $$((took / 60)) $$((took % 60))

stage-interfaces:
	@+$(STAGE) "interfaces (ours, those PyPI lacks), the C response send" $(SETUP_LOG)/interfaces.log \
	  $(SUBMAKE) $(BUILD_STAMP)

# The CP plan's kernels need only numpy and numba: compiled into numba's cache while the
# interfaces build (~20 s of a fresh checkout's setup; every later start loads them).
stage-wheels:
	@+$(STAGE) "the rest of the venv (PyBullet, Pinocchio, TOPP-RA, viser)" $(SETUP_LOG)/wheels.log \
	  $(SUBMAKE) $(DEPS_STAMP) && \
	$(STAGE) "the CP plan's compiled kernels (numba's cache)" $(SETUP_LOG)/kernels.log \
	  $(PY) -m acti_motion.arm.compiled

# pip's HTTP cache keeps nothing from this registry, so the wheels are kept in a wheelhouse: a new
# venv (another clone, `rm -r .venv`) installs from it without the network; the lock pins every
# wheel. A requirement it lacks sends pip to the registry for the missing ones.
WHEELHOUSE ?= $(HOME)/.cache/acti_ros2/wheels
PIP := $(PY) -m pip --disable-pip-version-check

# Install a requirements file from the wheelhouse; fetch into it what it lacks.
define install_from_wheelhouse
	$(PIP) install --quiet --no-index --find-links $(WHEELHOUSE) -r $(1) -c requirements.lock 2>/dev/null || { \
	  $(PIP) wheel --quiet --find-links $(WHEELHOUSE) -w $(WHEELHOUSE) -r $(1) -c requirements.lock && \
	  $(PIP) install --quiet --no-index --find-links $(WHEELHOUSE) -r $(1) -c requirements.lock; }
endef

$(BUILD_DEPS_STAMP): requirements-build.txt requirements.lock tools/fix_cmake_paths.py
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(call install_from_wheelhouse,requirements-build.txt)
	$(PY) tools/fix_cmake_paths.py $(VENV)
	touch $@

# `source .venv/bin/activate` alone says to source tools/env.sh instead (tools/venv_hint.sh).
$(ACTIVATE_HOOK): $(BUILD_DEPS_STAMP)
	grep -q venv_hint.sh $(VENV)/bin/activate || \
	  echo '[ ! -f "$$VIRTUAL_ENV/../tools/venv_hint.sh" ] || . "$$VIRTUAL_ENV/../tools/venv_hint.sh"' \
	  >> $(VENV)/bin/activate
	touch $@

$(DEPS_STAMP): $(BUILD_DEPS_STAMP) requirements.txt
	$(call install_from_wheelhouse,requirements.txt)
	touch $@

# Python sources need no rebuild: --symlink-install runs them from the tree (its `setup.py
# develop` compiles the C extension in place: acti_bringup/serving/_respond.c). Our tf2_msgs
# (msg_defs/tf2_msgs) and control_msgs (msg_defs/control_msgs) are added only where none is
# installed (tools/own_msgs.py).
$(BUILD_STAMP): $(BUILD_DEPS_STAMP) $(INTERFACES) package.xml setup.py setup.cfg tools/own_msgs.py \
  $(wildcard acti_bringup/serving/*.c)
	$(ENV) && $(BUILD_ENV) colcon --log-base log build $(COLCON_PATHS) $$(python tools/own_msgs.py) \
	  --symlink-install --parallel-workers $(NPROC) --cmake-args $(CMAKE_ARGS)
	touch $@

# The view's test drives Debian's headless Chromium: installed here when missing, never skipped.
browser:
	@for f in $(BROWSER); do test -x $$f || { apt-get update && \
	  DEBIAN_FRONTEND=noninteractive apt-get install -y chromium-headless-shell chromium-driver; \
	  break; }; done

# The job says READY, with the live view's URL (the port it took), once it serves.
run: setup
	@echo "starting the nodes and the live view (python -m acti_bringup):"
	@$(ENV) && exec python -m acti_bringup --ros-args --params-file config/acti_ros2.yaml

test: setup browser
	$(ENV) && colcon --log-base log test $(COLCON_PATHS) --packages-select acti_ros2 \
	  --event-handlers console_direct+ --return-code-on-test-failure \
	  --pytest-args -q -p no:cacheprovider
	$(ENV) && colcon test-result --test-result-base build/acti_ros2 --verbose

bench: setup browser
	$(ENV) && for b in bench/bench_*.py; do echo "== $$b"; python "$$b" || exit 1; done

clean:
	rm -rf build install log
