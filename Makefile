# yade-dda: the two set-up commands are `make demo` and `make test`; each installs
# what it needs on a fresh Debian 12 machine (apt-get, as root), builds and installs.
PYTHON   := /usr/bin/python3
BUILD    := build
JOBS     ?= 2
DEB_PACKAGES := yade cmake g++ make libeigen3-dev libcgal-dev libgmp-dev libmpfr-dev \
                libboost-python-dev python3-dev python3-pytest python3-numpy python3-matplotlib python3-vtk9 \
                python3-distributed libgtest-dev
SITE_DIR := $(shell $(PYTHON) -c "import sysconfig;print(sysconfig.get_path('purelib','posix_local'))" 2>/dev/null)

.PHONY: deps build install demo test test-hard test-cpp test-py bench bench-scale bench-pile200 fingerprints docs regress regress-quick regress-run sweep fuzz mutations clean

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
	yade -n -x examples/paper/hexahedra_drop.py --collider MSC --steps 400
	yade -n -x examples/compare_colliders.py --scene hexahedra_drop --steps 300

test: install
	cd $(BUILD) && ctest --output-on-failure
	$(PYTHON) -m pytest -q tests/py

# Everything `test` runs plus the cases marked slow (pytest.ini deselects them by default), and the
# narrow-phase oracle (tests/cpp/contact/test_narrow_phase_oracle.cpp) on 2,000,000 random pairs instead of
# 100,000 (about 6 minutes; DDA_ORACLE_SEED picks another sample).
ORACLE_PAIRS ?= 2000000
test-hard: install
	cd $(BUILD) && DDA_ORACLE_PAIRS=$(ORACLE_PAIRS) ctest --output-on-failure --timeout 3000
	$(PYTHON) -m pytest -q -m "slow or not slow" tests/py

bench: install
	$(PYTHON) bench/free_blocks.py
	$(PYTHON) bench/contacts.py
	$(PYTHON) bench/colliders.py
	$(PYTHON) bench/accuracy.py
	$(PYTHON) bench/friction_startup.py
	$(PYTHON) bench/effects.py
	$(PYTHON) bench/energy.py
	$(PYTHON) bench/bounce.py

# The speed and scale table (bench/out/scale.json, scale_steps.png): detection against YADE's collider,
# the full step on 1 and 2 threads and the sync's share at 1,000 to 50,000 blocks, the paper's drop
# in steps per second. About half an hour (YADE's 50,000-block steps take seconds); needs a quiet machine.
bench-scale: install
	$(PYTHON) bench/scale.py

# The slow energy test's 200-cube pile at 1e5..1e11 Pa (bench/out/energy_pile200.json): about half an hour
# on one core, so not in `bench`.
bench-pile200: install
	$(PYTHON) bench/energy.py --pile200 --threads 1

# The parameter reference doc/parameters.md, generated from the settings' one declaration
# (pkg/dda/solver/Settings.def) through the built module by tools/gen_docs.py;
# tests/py/package/test_parameter_reference.py fails when it is stale.
docs: build
	YADE_DDA_BUILD=$(abspath $(BUILD))/py $(PYTHON) tools/gen_docs.py
	YADE_DDA_BUILD=$(abspath $(BUILD))/py $(PYTHON) tools/gen_api.py

# Step-by-step fingerprints of every regression and paper scene (bench/out/fingerprints.json), for a
# refactor that must leave them bitwise: compare with bench/fingerprints.py --compare A B. About 2 minutes.
fingerprints: install
	$(PYTHON) bench/fingerprints.py

# Batch regressions (doc/guide/how-to.md, "Batch regressions"): yade-batch runs every row of a table in
# examples/regression, each scene writes a record, check.py compares them with closed forms and
# stored references and exits non-zero on any failure. Logs and records go to $(REGRESS_OUT)/<table>.
REGRESS_OUT := $(BUILD)/regress
YADE_BATCH  := yade-batch

regress: install
	$(MAKE) --no-print-directory regress-run TABLE=full

regress-quick: install
	$(MAKE) --no-print-directory regress-run TABLE=quick

# Runs TABLE (quick or full) with whatever yade_dda YADE imports (the installed one; set
# PYTHONPATH=$(BUILD)/py for the build tree). CHECK_ARGS are passed to check.py (e.g. --update).
TABLE ?= quick
regress-run:
	@out=$(abspath $(REGRESS_OUT))/$(TABLE); rm -rf $$out && mkdir -p $$out && \
	echo "yade-batch $(TABLE).table: logs and records in $$out" && \
	(cd examples/regression && YADE_DDA_RECORDS=$$out $(YADE_BATCH) -j $(JOBS) --disable-pynotify \
	    --log "$$out/@.log" $(TABLE).table 2>&1) | tee $$out/yade-batch.log | grep --line-buffered -E '^#[0-9]+ \('; true
	$(PYTHON) examples/regression/check.py examples/regression/$(TABLE).table $(abspath $(REGRESS_OUT))/$(TABLE) $(CHECK_ARGS)

# Sweeps on a cluster (doc/guide/how-to.md, "Sweeps on a cluster"): every row of a yade-batch table as its own
# YADE process on Dask distributed (python3 -m yade_dda.tools.sweep), with the build tree's yade_dda; a local
# cluster of JOBS single-threaded workers unless SWEEP_ARGS says otherwise (--scheduler tcp://HOST:8786,
# --workers N, --timeout S). TABLE is a path or the name of a table in examples/regression (default quick).
# Records and logs go to $(SWEEP_OUT)/<table>; a table of examples/regression is then checked by check.py.
SWEEP_OUT  := $(BUILD)/sweep
SWEEP_ARGS ?= --workers $(JOBS)
sweep: build
	@table=$(TABLE); [ -f "$$table" ] || table=examples/regression/$(TABLE).table; \
	out=$(abspath $(SWEEP_OUT))/$$(basename $$table .table); mkdir -p $$out; \
	{ PYTHONPATH=$(abspath $(BUILD))/py $(PYTHON) -m yade_dda.tools.sweep $$table --out $$out $(SWEEP_ARGS) 2>&1; \
	  echo $$? > $$out/sweep.status; } | grep --line-buffered -v '^Using python version' | tee $$out/sweep.log; \
	status=$$(cat $$out/sweep.status); \
	if [ "$$(cd $$(dirname $$table) && pwd)" = "$(abspath examples/regression)" ]; then \
	  $(PYTHON) examples/regression/check.py $$table $$out $(CHECK_ARGS) || status=1; fi; exit $$status

# Longer fuzzing of the geometry and contact kernels (doc/testing.md, "Fuzzing"): tests/fuzz's target built
# with AddressSanitizer and UBSan in its own build tree, fed by the plain driver for FUZZ_SECONDS with
# a seed from the clock (printed; findings are written to $(FUZZ_BUILD)/crashes). ctest runs the same
# target for 20 s without sanitizers.
FUZZ_SECONDS ?= 600
FUZZ_BUILD   := build-fuzz
fuzz: deps
	cmake -S . -B $(FUZZ_BUILD) -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPYTHON_EXECUTABLE=$(PYTHON) -DPython3_EXECUTABLE=$(PYTHON) \
	    -DCMAKE_CXX_FLAGS="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
	cmake --build $(FUZZ_BUILD) -j $(JOBS) --target fuzz_kernels_driver
	mkdir -p $(FUZZ_BUILD)/crashes
	ASAN_OPTIONS=detect_leaks=0 $(FUZZ_BUILD)/fuzz_kernels_driver --seconds $(FUZZ_SECONDS) --seed $$(date +%s) \
	    --crash-dir $(FUZZ_BUILD)/crashes tests/fuzz/corpus

# Mutation checks of the hard-case suite (doc/testing.md, "Mutation checks"): each patch in tests/mutations
# removes one core protection; run.py builds the module for the unmutated tree, then for each patch,
# in one incremental build tree ($(MUTATION_BUILD)), and runs the tests the patch names: the
# unmutated tree must pass them and each mutation must make one fail. Long (a build per mutation),
# so not part of `test`. MUTATION_ARGS go to run.py (e.g. --only wedge-fs-1).
MUTATION_BUILD := build-mutations
mutations: deps
	$(PYTHON) tests/mutations/run.py --build-dir $(MUTATION_BUILD) --jobs $(JOBS) $(MUTATION_ARGS)

clean:
	rm -rf $(BUILD) $(FUZZ_BUILD) $(MUTATION_BUILD)
