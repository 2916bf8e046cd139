# salient: the two commands a newcomer needs are `make run` and `make test`.
#   make run            install missing Debian packages, build, start salientd (data in ./var)
#   make test           install, build (Release), run the whole test suite
#   make test-sanitize  the suite under AddressSanitizer + UndefinedBehaviorSanitizer (less SANITIZE_SKIP)
#   make format-check   every C++ file as .clang-format writes it (CI's first step); make format applies it
#   make fuzz           libFuzzer (clang) on FUZZ_TARGET (mesh_reader_fuzz, gcode_fuzz, toolpath_fuzz, line_codec_fuzz,
#                       marlin_session_fuzz, sim_firmware_fuzz, http_request_fuzz, multipart_fuzz, settings_fuzz,
#                       ws_message_fuzz, config_fuzz, gcode_upload_fuzz)
#   make bench          build and run the benchmarks in tests/bench
#   make deb            the Debian package (salient_VERSION_ARCH.deb in $(BUILD)), checked by lintian
SHELL := /bin/bash
BUILD ?= build
BUILD_ASAN ?= build-asan
BUILD_FUZZ ?= build-fuzz
JOBS ?= $(shell nproc)
MODELS ?= $(abspath ../shared/models)
FUZZ_SECONDS ?= 180
FUZZ_TARGET ?= mesh_reader_fuzz
CMAKE_FLAGS ?=
# Left out of the sanitizer run (the release run keeps them all; CI must stay well inside its 90
# minutes on a cold machine, and stop 29's took 86): four saliency properties over the large shared
# meshes (~12 min of the run's CPU under ASan, LAPACK and CGAL arithmetic that the smaller saliency
# tests and the daemon's spectral jobs run through the same code paths); the per-model x3g peer
# tests (their time is slicing 15 models; the translator runs sanitized in its unit tests and 150
# random programs compared with gpx); the per-model `--objective time` checks (each slices a model
# three times; the time solver and the choice between plans run sanitized in core_slicing_tests and
# every default slice); `--up auto` on the bunny (six candidate slices; the synthetic solids run it
# sanitized); plan/slice --segment on two models (cut and timed the same way by core_segment_tests);
# the planner's properties on four groups of shared models (~4.5 min; the same planner runs
# sanitized on the bunny and the STL/PLY edge cases); three farm e2e runs (~9 min: three nodes
# through a SIGKILL, printers across nodes, the farm-wide queue) and the farm through PostgreSQL's
# freeze, stop and restart (its freeze is timed; the printer's saver and the sessions' host gap
# run sanitized in server_printers_tests and the protocol tests), whose claims, leases, relayed
# events, forwarded printer requests and farm queue run sanitized in server_jobs_pg_tests,
# server_events_pg_tests, server_store_pg_tests, farm_queue_test and the two-slicer-node,
# events-across-nodes and farm-clocks e2e runs.
SANITIZE_SKIP ?= core_saliency_tests:(a 500-face and a 270k-face mesh both work|saliency is invariant to rigid motion|saliency values are in|a map does not follow the tessellation)|peer: export-x3g is byte for byte gpx -m r2x, inside the travel|cli: exact --objective time never takes longer than --objective layers on|core_orient_tests:--up auto stands the Stanford bunny|cli: plan --segment and slice --segment time the same plan alike|e2e: a farm of three nodes on PostgreSQL|hostile clients: a farm through PostgreSQL|e2e: printers across nodes|e2e: farm-wide queue|core_slicing_tests:planner properties: (igea|fandisk|spot|alligator)

.PHONY: deps build run test test-sanitize fuzz bench deb format format-check clean

deps:
	@bash deploy/install-deps.sh

$(BUILD)/build.ninja: | deps
	cmake -S . -B $(BUILD) -G Ninja -DCMAKE_BUILD_TYPE=Release $(CMAKE_FLAGS)

build: deps $(BUILD)/build.ninja
	cmake --build $(BUILD) -j $(JOBS)

LISTEN ?= 127.0.0.1:8080
run: build
	@mkdir -p var
	@echo "salientd: data in ./var, http://$(LISTEN) (loopback only), simulated printer 'sim'; Ctrl-C stops it"
	@if [ -f var/api-key ]; then echo "  API key: $$(cat var/api-key)"; else echo "  API key: printed below at this first start, then kept in var/api-key"; fi
	@echo "  submit: curl -H \"X-Api-Key: \$$(cat var/api-key)\" -F file=@$(MODELS)/stanford-bunny.obj \\"
	@echo "            -F 'settings={\"up\": \"y\", \"height\": 40, \"saliency\": \"spectral\"}' http://$(LISTEN)/api/v1/jobs"
	@echo "  print:  curl -H \"X-Api-Key: \$$(cat var/api-key)\" -d '{\"job\": \"JOB_ID\"}' http://$(LISTEN)/api/v1/printers/sim/print"
	@echo "  or:     $(BUILD)/clients/salient submit $(MODELS)/stanford-bunny.obj --settings '{\"up\": \"y\", \"height\": 40}' --wait --print sim"
	$(BUILD)/server/salientd --data var --listen $(LISTEN)

test: build
	cd $(BUILD) && ctest --output-on-failure --no-tests=error -j $(JOBS)

test-sanitize: deps
	cmake -S . -B $(BUILD_ASAN) -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSALIENT_SANITIZE=ON \
	  "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1 -DNDEBUG" -DSALIENT_BENCH=OFF $(CMAKE_FLAGS)
	cmake --build $(BUILD_ASAN) -j $(JOBS)
	cd $(BUILD_ASAN) && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
	  ctest --output-on-failure --no-tests=error -j $(JOBS) -E '$(SANITIZE_SKIP)'

fuzz: deps
	CC=clang CXX=clang++ cmake -S . -B $(BUILD_FUZZ) -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
	  -DSALIENT_FUZZ=ON -DSALIENT_BENCH=OFF $(CMAKE_FLAGS)
	cmake --build $(BUILD_FUZZ) -j $(JOBS) --target $(FUZZ_TARGET)
	mkdir -p $(BUILD_FUZZ)/corpus/$(FUZZ_TARGET) && cp -n $(MODELS)/*.* $(MODELS)/invalid/* config/printers/* \
	  config/salientd.toml $(wildcard tests/fuzz/seeds/$(FUZZ_TARGET)/*) $(BUILD_FUZZ)/corpus/$(FUZZ_TARGET)/ 2>/dev/null || true
	UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 $(BUILD_FUZZ)/tests/fuzz/$(FUZZ_TARGET) \
	  -max_total_time=$(FUZZ_SECONDS) -max_len=65536 -timeout=30 -rss_limit_mb=2048 -print_final_stats=1 \
	  $(BUILD_FUZZ)/corpus/$(FUZZ_TARGET)

bench: build
	cmake --build $(BUILD) -j $(JOBS) --target benchmarks
	bash tests/bench/run_benchmarks.sh $(BUILD)

# The package of this build (deploy/debian/package.cmake): install it with apt install ./FILE.deb.
deb: build
	rm -f $(BUILD)/salient_*.deb
	cd $(BUILD) && cpack -G DEB
	lintian --fail-on error,warning $(BUILD)/salient_*.deb

format:
	git ls-files '*.cpp' '*.hpp' | xargs clang-format -i

# CI's check that every C++ file is as .clang-format (Debian 12's clang-format 14) writes it.
format-check:
	git ls-files '*.cpp' '*.hpp' | xargs clang-format --dry-run -Werror

clean:
	rm -rf $(BUILD) $(BUILD_ASAN) $(BUILD_FUZZ)
