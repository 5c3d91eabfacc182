# frac — build, test, sanitizer pass, goldens, gallery, benchmarks.
#
#   make            build build/frac (optimised)
#   make test       build and run every test (unit, language, REPL, golden)
#   make asan       the whole suite under AddressSanitizer + UBSan (build-asan/)
#   make golden     regenerate tests/golden/ from examples/ (review the diff!)
#   make gallery    render every example into gallery/index.html
#   make bench      build and run the benchmarks in bench/
#
# Floating point must give identical results at every optimisation level and
# under the sanitizers (goldens are compared exactly): no -ffast-math, no
# -march=native, and FP contraction off so no fused multiply-add is formed.

CC      ?= cc
BUILD   ?= build
OPT     ?= -O2
SAN     ?=
CFLAGS_BASE = -std=c11 -D_POSIX_C_SOURCE=200809L -Wall -Wextra -Werror -Wshadow \
              -Wstrict-prototypes -Wmissing-prototypes -ffp-contract=off -fno-fast-math \
              -fno-strict-aliasing -g
CFLAGS  = $(CFLAGS_BASE) $(OPT) $(SAN) -Iruntime -Iinterp -I$(BUILD)
LDLIBS  = -lm -lpthread

RT_SRC  := $(sort $(wildcard runtime/*.c))
IN_SRC  := $(sort $(wildcard interp/*.c))
STDLIB  := $(sort $(wildcard stdlib/*.frac))
UNIT_SRC:= $(sort $(wildcard tests/unit/test_*.c))

RT_OBJ  := $(RT_SRC:%.c=$(BUILD)/%.o)
IN_OBJ  := $(IN_SRC:%.c=$(BUILD)/%.o) $(BUILD)/stdlib_gen.o
UNIT_BIN:= $(UNIT_SRC:tests/unit/%.c=$(BUILD)/tests/%)

.PHONY: all test asan golden gallery bench clean unit fuzz
all: $(BUILD)/frac

$(BUILD)/%.o: %.c
	@mkdir -p $(dir $@)
	@echo "CC $<"
	@$(CC) $(CFLAGS) -MMD -MP -c $< -o $@

$(BUILD)/libfracrt.a: $(RT_OBJ)
	rm -f $@
	ar rcs $@ $^

# The stdlib/ .frac files are compiled into the binary (see tools/embed.c).
$(BUILD)/embed: tools/embed.c
	@mkdir -p $(BUILD)
	$(CC) -std=c11 -O1 -Wall -Wextra -Werror $< -o $@

$(BUILD)/stdlib_gen.c: $(BUILD)/embed $(STDLIB)
	$(BUILD)/embed $@ $(STDLIB)

$(BUILD)/stdlib_gen.o: $(BUILD)/stdlib_gen.c
	$(CC) $(CFLAGS) -c $< -o $@

$(BUILD)/frac: $(IN_OBJ) $(BUILD)/libfracrt.a
	$(CC) $(CFLAGS) $(IN_OBJ) $(BUILD)/libfracrt.a $(LDLIBS) -o $@

$(BUILD)/tests/%: tests/unit/%.c $(BUILD)/libfracrt.a tests/unit/check.h
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) -Itests/unit $< $(BUILD)/libfracrt.a $(LDLIBS) -o $@

# The runner is the harness, not the product: built without sanitizers.
$(BUILD)/runner: tests/runner.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_BASE) -O1 $< -o $@ $(LDLIBS)

# Drives interactive programs on a pseudo-terminal (REPL tests).
$(BUILD)/ptyrun: tests/ptyrun.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_BASE) -O1 $< -o $@

unit: $(UNIT_BIN)

test: $(BUILD)/frac $(UNIT_BIN) $(BUILD)/runner $(BUILD)/ptyrun
	$(BUILD)/runner --frac $(BUILD)/frac --unit $(BUILD)/tests --ptyrun $(BUILD)/ptyrun

asan:
	$(MAKE) BUILD=build-asan OPT=-O1 SAN="-fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer" test

golden: $(BUILD)/frac $(BUILD)/runner
	$(BUILD)/runner --frac $(BUILD)/frac --update-golden

gallery: $(BUILD)/frac
	bash tools/gallery.sh $(BUILD)/frac

BENCH_SRC := $(sort $(wildcard bench/*.c))
BENCH_BIN := $(BENCH_SRC:bench/%.c=$(BUILD)/bench/%)
$(BUILD)/bench/%: bench/%.c $(BUILD)/libfracrt.a
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $< $(BUILD)/libfracrt.a $(LDLIBS) -o $@

bench: $(BUILD)/frac $(BENCH_BIN)
	bash bench/run.sh $(BUILD)

# Fuzz the whole interpreter with libFuzzer (needs clang; not part of test).
FUZZ_SECONDS ?= 60
fuzz:
	@mkdir -p build-fuzz /tmp/frac-fuzz-out build-fuzz/corpus
	$(MAKE) BUILD=build-fuzz build-fuzz/stdlib_gen.c
	clang -std=c11 -D_POSIX_C_SOURCE=200809L -g -O1 -fsanitize=fuzzer,address,undefined \
	    -Iruntime -Iinterp -Ibuild-fuzz $(RT_SRC) $(filter-out interp/main.c,$(IN_SRC)) \
	    build-fuzz/stdlib_gen.c tests/fuzz/fuzz_script.c -lm -lpthread -o build-fuzz/fuzz_script
	for f in examples/*.frac tests/lang/*/*.frac; do cp "$$f" build-fuzz/corpus/$$(echo $$f | tr / _); done
	build-fuzz/fuzz_script -max_total_time=$(FUZZ_SECONDS) -max_len=4096 -timeout=30 \
	    -rss_limit_mb=4096 build-fuzz/corpus

clean:
	rm -rf build build-asan build-fuzz gallery

-include $(RT_OBJ:.o=.d) $(IN_OBJ:.o=.d)
