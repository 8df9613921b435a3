# yade-dda: the two set-up commands are `make demo` and `make test`; each installs
# what it needs on a fresh Debian 12 machine (apt-get, as root), builds and installs.
PYTHON   := /usr/bin/python3
BUILD    := build
JOBS     ?= 2
DEB_PACKAGES := yade cmake g++ make libeigen3-dev libcgal-dev libgmp-dev libmpfr-dev \
                libboost-python-dev python3-dev python3-pytest python3-numpy python3-matplotlib \
                libgtest-dev
SITE_DIR := $(shell $(PYTHON) -c "import sysconfig;print(sysconfig.get_path('purelib','posix_local'))" 2>/dev/null)

.PHONY: deps build install demo test test-cpp test-py bench clean

deps:
	@missing=$$(for p in $(DEB_PACKAGES); do dpkg-query -W -f='$${Status}\n' $$p 2>/dev/null | grep -q 'install ok installed' || echo $$p; done); \
	if [ -n "$$missing" ]; then \
	  echo "installing Debian packages:" $$missing; \
	  if [ "$$(id -u)" != 0 ]; then echo "run as root (or sudo make deps) to apt-get install:" $$missing; exit 1; fi; \
	  apt-get update && DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends $$missing; \
	else echo "Debian packages present"; fi

build: deps
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release -DPYTHON_EXECUTABLE=$(PYTHON) -DPython3_EXECUTABLE=$(PYTHON)
	cmake --build $(BUILD) -j $(JOBS)

install: build
	cmake --install $(BUILD)
	@$(PYTHON) -c "import sys; sys.path.insert(0,'/usr/lib/x86_64-linux-gnu/yade-double/py'); import yade_dda; print('yade_dda installed at', yade_dda.__file__)" 2>&1 | grep -v 'Using python version'

demo: install
	yade -n -x examples/demo.py

test: install
	cd $(BUILD) && ctest --output-on-failure
	$(PYTHON) -m pytest -q tests/py

bench: install
	$(PYTHON) bench/free_blocks.py
	$(PYTHON) bench/contacts.py
	$(PYTHON) bench/colliders.py

clean:
	rm -rf $(BUILD)
