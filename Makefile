# acti_ros2: `make run` sets everything up and runs both nodes; `make test` sets up and tests.
SHELL := /bin/bash
PYTHON ?= python3.11
VENV := .venv
PY := $(VENV)/bin/python
ENV := source tools/env.sh
DEPS_STAMP := $(VENV)/.deps-stamp
BUILD_STAMP := install/.build-stamp
COLCON_PATHS := --base-paths . msg_defs
INTERFACES := $(shell find msg_defs -type f -not -name '*~')

BROWSER := /usr/lib/chromium/chromium-headless-shell /usr/bin/chromedriver
VIEW_URL := http://127.0.0.1:8080/

.PHONY: build run test bench clean browser

build: $(BUILD_STAMP)

$(DEPS_STAMP): requirements.txt requirements.lock tools/fix_cmake_paths.py
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --disable-pip-version-check -r requirements.txt -c requirements.lock
	$(PY) tools/fix_cmake_paths.py $(VENV)
	touch $@

# Python sources need no rebuild: --symlink-install runs them from the tree. Our tf2_msgs
# (msg_defs/tf2_msgs) is added only where no tf2_msgs is installed (tools/own_tf2_msgs.py).
$(BUILD_STAMP): $(DEPS_STAMP) $(INTERFACES) package.xml setup.py setup.cfg tools/own_tf2_msgs.py
	$(ENV) && colcon --log-base log build $(COLCON_PATHS) $$(python tools/own_tf2_msgs.py) --symlink-install \
	  --cmake-args -DBUILD_TESTING=OFF -DPython3_EXECUTABLE=$(abspath $(PY))
	touch $@

# The view's test drives Debian's headless Chromium: installed here when missing, never skipped.
browser:
	@for f in $(BROWSER); do test -x $$f || { apt-get update && \
	  DEBIAN_FRONTEND=noninteractive apt-get install -y chromium-headless-shell chromium-driver; \
	  break; }; done

run: build
	@echo "live view: $(VIEW_URL) (the log says so if that port was taken; view_enabled:=false turns it off)"
	$(ENV) && exec python -m acti_bringup --ros-args --params-file config/acti_ros2.yaml

test: build browser
	$(ENV) && colcon --log-base log test $(COLCON_PATHS) --packages-select acti_ros2 \
	  --event-handlers console_direct+ --return-code-on-test-failure \
	  --pytest-args -q -p no:cacheprovider
	$(ENV) && colcon test-result --test-result-base build/acti_ros2 --verbose

bench: build browser
	$(ENV) && for b in bench/bench_*.py; do echo "== $$b"; python "$$b" || exit 1; done

clean:
	rm -rf build install log
