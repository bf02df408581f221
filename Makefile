# bksim: `make` builds libbksim.a and ./bksim; `make test` runs every cmocka program once on
# the plain build.  CI (.ci/run) adds the AddressSanitizer + UndefinedBehaviorSanitizer build
# (make test-asan), valgrind (make test-valgrind), the long statistical tests (make
# test-long), make lint, make fuzz-replay and make test-slurm.

CC       ?= gcc
PKGS     := hdf5-serial gsl inih lapacke
SUNDIALS := -lsundials_cvode -lsundials_ida -lsundials_arkode -lsundials_nvecserial \
            -lsundials_sunmatrixdense -lsundials_sunmatrixband \
            -lsundials_sunlinsoldense -lsundials_sunlinsolband \
            -lsundials_sunnonlinsolnewton -lsundials_sunnonlinsolfixedpoint

WARN     := -Wall -Wextra -Werror -Wshadow -Wconversion -Wstrict-prototypes \
            -Wmissing-prototypes -Wformat=2
CPPFLAGS := -Iinclude -Isrc -D_POSIX_C_SOURCE=200809L $(shell pkg-config --cflags $(PKGS))
CFLAGS   ?= -O2 -g
CFLAGS   += -std=c11 $(WARN)
LDLIBS   := $(shell pkg-config --libs $(PKGS)) $(SUNDIALS) -lm
TEST_LIBS := $(shell pkg-config --libs cmocka)
SAN      := -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all

LIB_SRC  := $(wildcard src/*.c src/friction/*.c src/solver/*.c src/output/*.c)
CLI_SRC  := $(wildcard src/cli/*.c)
TEST_SRC := $(wildcard tests/test_*.c)
# Helpers shared by the tests, written once and linked into every test program.
TEST_SUPPORT := $(wildcard tests/support/*.c)

# $(call objs,BUILD_DIR,SOURCES)
objs = $(patsubst %.c,$(1)/%.o,$(2))

.SECONDARY:
.PHONY: all test test-plain test-long test-asan test-valgrind test-slurm lint clean paper bench install fuzz fuzz-replay
all: bksim

build/libbksim.a: $(call objs,build,$(LIB_SRC))
	rm -f $@
	$(AR) rcs $@ $^
build-asan/libbksim.a: $(call objs,build-asan,$(LIB_SRC))
	rm -f $@
	$(AR) rcs $@ $^

bksim: $(call objs,build,$(CLI_SRC)) build/libbksim.a
	$(CC) $(CFLAGS) -o $@ $^ $(LDLIBS)
build-asan/bksim: $(call objs,build-asan,$(CLI_SRC)) build-asan/libbksim.a
	$(CC) $(CFLAGS) $(SAN) -o $@ $^ $(LDLIBS)

build/%.o: %.c
	@mkdir -p $(dir $@)
	$(CC) $(CPPFLAGS) $(CFLAGS) -MMD -MP -c -o $@ $<
build-asan/%.o: %.c
	@mkdir -p $(dir $@)
	$(CC) $(CPPFLAGS) $(CFLAGS) $(SAN) -O1 -MMD -MP -c -o $@ $<
# Tests include their support headers by name ("recorder.h").
build/tests/%.o build-asan/tests/%.o: CPPFLAGS += -Itests/support

TESTS      := $(patsubst tests/%.c,build/tests/%,$(TEST_SRC))
TESTS_ASAN := $(patsubst tests/%.c,build-asan/tests/%,$(TEST_SRC))

build/tests/test_%: build/tests/test_%.o $(call objs,build,$(TEST_SUPPORT)) build/libbksim.a
	$(CC) $(CFLAGS) -o $@ $^ $(TEST_LIBS) $(LDLIBS)
build-asan/tests/test_%: build-asan/tests/test_%.o $(call objs,build-asan,$(TEST_SUPPORT)) build-asan/libbksim.a
	$(CC) $(CFLAGS) $(SAN) -o $@ $^ $(TEST_LIBS) $(LDLIBS)

# Tests too long for make test (statistics of long runs), run by CI as make test-long.
LONG_TESTS := $(patsubst tests/long/%.c,build/tests/long/%,$(wildcard tests/long/test_*.c))
build/tests/long/test_%: build/tests/long/test_%.o $(call objs,build,$(TEST_SUPPORT)) build/libbksim.a
	$(CC) $(CFLAGS) -o $@ $^ $(TEST_LIBS) $(LDLIBS)
test-long: $(LONG_TESTS)
	@scripts/run_tests.sh long $(LONG_TESTS)

# Tests run from the repository root (they read configs/ and need ./bksim for CLI tests).
test: test-plain
# Two programs at a time (a 2-core machine's), those that time kills and wall clocks against
# the machine alone after them, as test-valgrind does.
test-plain: bksim build/bench/bksim_bench build/bench/h5_plain build/bench/exact_rows $(TESTS)
	@TEST_JOBS=2 TEST_ALONE="test_cli_restart test_sweep test_extremes test_h5_writer test_cli_extend" \
	 scripts/run_tests.sh build/tests $(TESTS)
# Every program again under the sanitizers (CI runs it); the CLI tests run the sanitizer
# build of bksim too (BKSIM, relative to the repository root).
test-asan: build-asan/bksim build/bench/bksim_bench build/bench/h5_plain build/bench/exact_rows $(TESTS_ASAN)
	@BKSIM=build-asan/bksim BK_TEST_TIME_SCALE=10 ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 \
	 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
	 LSAN_OPTIONS=suppressions=$(CURDIR)/tests/lsan.supp \
	 scripts/run_tests.sh build-asan/tests $(TESTS_ASAN)

# The whole suite under valgrind memcheck (CI runs it once): no leaks, no invalid access.
# Two programs at a time, the longest first (245 s and 138 s of the 760 s in a row); those
# that time kills and wall clocks against the machine run alone after them.
VALGRIND_FIRST := build/tests/test_run_catalog build/tests/test_backends
test-valgrind: bksim $(TESTS)
	@TEST_JOBS=2 TEST_ALONE="test_cli_restart test_sweep test_extremes test_h5_writer test_cli_extend" BK_TEST_TIME_SCALE=200 \
	 VALGRIND="valgrind -q --error-exitcode=9 --leak-check=full --errors-for-leak-kinds=definite,indirect,possible --show-leak-kinds=definite,indirect,possible" \
	 scripts/run_tests.sh valgrind $(filter $(VALGRIND_FIRST),$(TESTS)) $(filter-out $(VALGRIND_FIRST),$(TESTS))

# The sweep's SLURM job array on a single-node cluster the script starts (root; CI runs it).
test-slurm: bksim
	scripts/test_slurm.sh

# Static analysis (options and suppressions in tests/cppcheck.cfg), then the library's
# namespace (every symbol libbksim.a exports starts with bk_) and its layers (no two files
# call each other, directly or round a circle: scripts/lint_calls.sh).
lint: build/libbksim.a
	cppcheck $$(cat tests/cppcheck.cfg) -Iinclude -Isrc -Itests/support src tests/*.c tests/support/*.c \
	    tests/long/*.c tests/fuzz/*.c bench/*.c
	@bad=$$(nm -g --defined-only build/libbksim.a | awk 'NF == 3 && $$3 !~ /^bk_/ {print $$3}'); \
	 if [ -n "$$bad" ]; then echo "lint: symbols of libbksim.a without the bk_ prefix:" $$bad >&2; exit 1; fi; \
	 echo "lint: every exported symbol of libbksim.a starts with bk_"
	@scripts/lint_calls.sh $(call objs,build,$(LIB_SRC))

paper: bksim
	scripts/run_paper.sh

# The work-precision benchmark (not in CI; a --quick smoke run is part of make test).
build/bench/bksim_bench: bench/bench.c build/libbksim.a
	@mkdir -p $(dir $@)
	$(CC) $(CPPFLAGS) $(CFLAGS) -o $@ $< build/libbksim.a $(LDLIBS)
# The writer's yardstick: a plain HDF5 program writing the same datasets (bench/h5_plain.c).
build/bench/h5_plain: bench/h5_plain.c
	@mkdir -p $(dir $@)
	$(CC) $(CPPFLAGS) $(CFLAGS) -o $@ $< $(LDLIBS)
# The exact stepper's rows on one long slipping cluster: the series against the modal sum.
build/bench/exact_rows: bench/exact_rows.c tests/support/linear_chain.c build/libbksim.a
	@mkdir -p $(dir $@)
	$(CC) $(CPPFLAGS) -Itests/support $(CFLAGS) -o $@ $^ $(LDLIBS)
bench: bksim build/bench/bksim_bench build/bench/h5_plain build/bench/exact_rows
	scripts/bench.sh

# Fuzz the config loader with libFuzzer (clang): make fuzz FUZZ_SECONDS=600.  The working
# corpus lives in build-fuzz/; crashers go to build-fuzz/artifacts/ (keep them as
# regressions in tests/fuzz/regressions/).
FUZZ_SECONDS ?= 60
FUZZ_SRC := $(filter-out src/output/h5_%,$(LIB_SRC))
# Two harnesses: fuzz_config (text -> model) and fuzz_run (text -> a short run);
# make fuzz FUZZ_TARGET=fuzz_run.
FUZZ_TARGET ?= fuzz_config
build-fuzz/%: tests/fuzz/%.c $(FUZZ_SRC) $(wildcard include/bksim/*.h src/*.h)
	@mkdir -p build-fuzz
	clang -std=c11 -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all $(CPPFLAGS) \
	    -o $@ $< $(FUZZ_SRC) $(LDLIBS)
fuzz: build-fuzz/$(FUZZ_TARGET)
	@mkdir -p build-fuzz/corpus-$(FUZZ_TARGET) build-fuzz/artifacts
	cp configs/*/*.ini tests/fuzz/regressions/*.ini build-fuzz/corpus-$(FUZZ_TARGET)/ 2>/dev/null || true
	build-fuzz/$(FUZZ_TARGET) -max_total_time=$(FUZZ_SECONDS) -max_len=4096 -timeout=20 \
	    -artifact_prefix=build-fuzz/artifacts/$(FUZZ_TARGET)- -dict=tests/fuzz/config.dict \
	    build-fuzz/corpus-$(FUZZ_TARGET)

# CI: build both harnesses and run every seed (configs/) and regression input through them
# once: the harnesses stay buildable and their oracles hold on the corpus.
fuzz-replay: build-fuzz/fuzz_config build-fuzz/fuzz_run
	build-fuzz/fuzz_config -runs=0 configs/*/*.ini tests/fuzz/regressions/*.ini
	build-fuzz/fuzz_run -runs=0 -timeout=20 configs/*/*.ini tests/fuzz/regressions/*.ini

clean:
	rm -rf build build-asan build-fuzz bksim

PREFIX ?= /usr/local
install: bksim build/libbksim.a
	install -d $(DESTDIR)$(PREFIX)/bin $(DESTDIR)$(PREFIX)/lib $(DESTDIR)$(PREFIX)/include/bksim
	install -m 755 bksim $(DESTDIR)$(PREFIX)/bin/
	install -m 644 build/libbksim.a $(DESTDIR)$(PREFIX)/lib/
	install -m 644 include/bksim/*.h $(DESTDIR)$(PREFIX)/include/bksim/

-include $(shell find build build-asan -name '*.d' 2>/dev/null)
