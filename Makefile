# frac — build, test, sanitizer pass, goldens, gallery, benchmarks.
#
#   make            build build/frac (optimised)
#   make test       build and run every test (unit, language, REPL, golden)
#   make asan       the whole suite under AddressSanitizer + UBSan (build-asan/)
#   make golden     regenerate tests/golden/ from examples/ (review the diff!)
#   make gallery    render every example into gallery/index.html
#   make bench      build and run the benchmarks in bench/
#   make fuzz       libFuzzer harnesses (clang); make fuzz-smoke is the ~60 s CI run
#                   (tests/fuzz/README.md)
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

.PHONY: all test asan golden gallery bench clean unit
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

# test_fileio_fsync sees (and fails) every fsync of the runtime through --wrap.
$(BUILD)/tests/test_fileio_fsync: tests/unit/test_fileio_fsync.c $(BUILD)/libfracrt.a tests/unit/check.h
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) -Itests/unit $< $(BUILD)/libfracrt.a $(LDLIBS) -Wl,--wrap=fsync -o $@

# test_lexer compiles interp/lexer.c into itself (the scanner needs only rt_alloc)
$(BUILD)/tests/test_lexer: interp/lexer.c interp/lexer.h

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

# Fuzzing with libFuzzer (clang with libclang-rt-14-dev; not part of test).
# See tests/fuzz/README.md. Objects are built in build-fuzz/ with ASan +
# UBSan (UBSan errors abort) and coverage instrumentation; the harnesses
# link them with -fsanitize=fuzzer.
#   make fuzz              build everything, then run the script harness FUZZ_SECONDS
#   make fuzz-NAME         run one harness (script shard png inflate pnm ifs nrrd vtk ply obj stl apng recipe)
#   make fuzz-smoke        build, replay tests/fuzz/regressions, run each harness briefly
#   make fuzz-seeds        (re)make the seed corpora in build-fuzz/corpus/
FUZZ_SECONDS ?= 60
FUZZ_LOADERS := png inflate pnm ifs nrrd vtk ply obj stl apng recipe
FUZZ_HARNESSES := script shard $(FUZZ_LOADERS)
FUZZ_SAN = -fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer \
           -fsanitize-coverage-ignorelist=tests/fuzz/engines.ignorelist
FUZZ_FLAGS = -timeout=10 -rss_limit_mb=1536 -malloc_limit_mb=1024 -print_final_stats=1
FUZZ_SCRIPT_OBJ := $(filter-out $(BUILD)/interp/main.o $(BUILD)/interp/cli_%.o,$(IN_OBJ))
FUZZ_DIR := build-fuzz
# test_fuzz_script runs the script harness's own code (tests/fuzz/fuzz_script.c) without
# libFuzzer, linked as the harness is, to check its work caps in make test.
$(BUILD)/tests/test_fuzz_script: tests/unit/test_fuzz_script.c tests/fuzz/fuzz_script.c $(FUZZ_SCRIPT_OBJ) \
                                 $(BUILD)/libfracrt.a tests/unit/check.h
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) -Itests/unit $< $(FUZZ_SCRIPT_OBJ) $(BUILD)/libfracrt.a $(LDLIBS) \
	    -Wl,--wrap=fileio_write_atomic,--wrap=fileio_read_all -o $@
# test_interp_counts and test_pending_image run scripts in the interpreter (linked as the fuzz harness is).
$(BUILD)/tests/test_interp_counts $(BUILD)/tests/test_pending_image: $(BUILD)/tests/%: tests/unit/%.c $(FUZZ_SCRIPT_OBJ) $(BUILD)/libfracrt.a \
                                   tests/unit/check.h
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) -Itests/unit $< $(FUZZ_SCRIPT_OBJ) $(BUILD)/libfracrt.a $(LDLIBS) -o $@
.PHONY: fuzz fuzz-build fuzz-bins fuzz-seeds fuzz-smoke $(FUZZ_HARNESSES:%=fuzz-%)
# a changed ignorelist rebuilds the fuzz objects (it decides what is instrumented)
$(RT_SRC:%.c=$(FUZZ_DIR)/%.o) $(IN_SRC:%.c=$(FUZZ_DIR)/%.o): tests/fuzz/engines.ignorelist

$(BUILD)/fuzz/fuzz_script: tests/fuzz/fuzz_script.c $(FUZZ_SCRIPT_OBJ) $(BUILD)/libfracrt.a
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) -fsanitize=fuzzer $< $(FUZZ_SCRIPT_OBJ) $(BUILD)/libfracrt.a $(LDLIBS) \
	    -Wl,--wrap=fileio_write_atomic,--wrap=fileio_read_all -o $@

$(BUILD)/fuzz/fuzz_shard: tests/fuzz/fuzz_shard.c $(FUZZ_SCRIPT_OBJ) $(BUILD)/libfracrt.a
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) -fsanitize=fuzzer $< $(FUZZ_SCRIPT_OBJ) $(BUILD)/libfracrt.a $(LDLIBS) -o $@

$(BUILD)/fuzz/fuzz_%: tests/fuzz/fuzz_loaders.c $(BUILD)/libfracrt.a $(BUILD)/interp/recipe.o
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) -fsanitize=fuzzer -DFUZZ_LOADER=$* $< $(BUILD)/interp/recipe.o $(BUILD)/libfracrt.a $(LDLIBS) -o $@

$(BUILD)/fuzzgen: tools/fuzzgen.c $(BUILD)/libfracrt.a
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_BASE) -O1 -Iruntime $< $(BUILD)/libfracrt.a $(LDLIBS) -o $@

fuzz-bins: $(FUZZ_HARNESSES:%=$(BUILD)/fuzz/fuzz_%)

fuzz-build:
	$(MAKE) BUILD=$(FUZZ_DIR) CC=clang OPT=-O1 SAN="$(FUZZ_SAN)" fuzz-bins
	$(MAKE) $(BUILD)/fuzzgen

# Seeds: the examples and language tests for the script harness, plus the
# deep and wide inputs and the small valid files tools/fuzzgen writes.
fuzz-seeds: $(BUILD)/fuzzgen $(BUILD)/frac
	@mkdir -p $(FUZZ_DIR)/corpus/script
	@for f in examples/*.frac tests/lang/*/*.frac tests/regression/*.frac; do \
	    cp "$$f" $(FUZZ_DIR)/corpus/script/$$(echo $$f | tr / _); done
	$(BUILD)/fuzzgen $(FUZZ_DIR)/corpus
	@mkdir -p $(FUZZ_DIR)/corpus/shard $(FUZZ_DIR)/corpus/recipe && rm -rf $(FUZZ_DIR)/shard-seeds && \
	for f in tests/fuzz/shard_seed.frac; do for n in 1 2 3; do \
	    i=0; while [ $$i -lt $$n ]; do $(BUILD)/frac run -q --threads 1 --shard $$i/$$n -o $(FUZZ_DIR)/shard-seeds $$f \
	        || exit 1; i=$$((i + 1)); done; done; done; \
	cd $(FUZZ_DIR)/shard-seeds && for p in *.part; do cp $$p ../corpus/shard/seed_$$p; done; \
	for b in shard_seed; do cat $$b.shard-*-of-2.part > ../corpus/shard/seed_$$b.all-of-2; \
	    cat $$b.shard-*-of-3.part > ../corpus/shard/seed_$$b.all-of-3; done
	@rm -rf $(FUZZ_DIR)/recipe-seeds && $(BUILD)/frac -q --seed 7 -o $(FUZZ_DIR)/recipe-seeds \
	    tests/cli/data/recipe_scene.frac -D size=8 arg1 > /dev/null && \
	for f in $(FUZZ_DIR)/recipe-seeds/*; do cp $$f $(FUZZ_DIR)/corpus/recipe/seed_$${f##*/}; done

fuzz: fuzz-build fuzz-seeds
	$(MAKE) fuzz-script

$(FUZZ_HARNESSES:%=fuzz-%): fuzz-%:
	@mkdir -p $(FUZZ_DIR)/corpus/$* $(FUZZ_DIR)/findings/$*
	$(FUZZ_DIR)/fuzz/fuzz_$* $(FUZZ_FLAGS) -max_total_time=$(FUZZ_SECONDS) \
	    -dict=tests/fuzz/$(if $(filter script,$*),frac,formats).dict \
	    -artifact_prefix=$(FUZZ_DIR)/findings/$*/ $(FUZZ_DIR)/corpus/$*

# CI: about 60 s in all; fails on any crash. Replays every kept finding
# first (tests/fuzz/regressions/HARNESS/*), then fuzzes each harness from
# its seeds for a few seconds into a scratch corpus.
FUZZ_SMOKE_SECONDS ?= 5
fuzz-smoke: fuzz-build fuzz-seeds
	@for h in $(FUZZ_HARNESSES); do \
	    if [ -n "$$(ls tests/fuzz/regressions/$$h 2>/dev/null)" ]; then \
	        $(FUZZ_DIR)/fuzz/fuzz_$$h tests/fuzz/regressions/$$h/* > $(FUZZ_DIR)/replay-$$h.log 2>&1 \
	        || { tail -n 40 $(FUZZ_DIR)/replay-$$h.log; echo "fuzz-smoke: a kept $$h finding fails again"; exit 1; }; \
	        echo "fuzz-smoke: replayed $$(ls tests/fuzz/regressions/$$h | wc -l) $$h regression(s)"; fi; \
	done
	@for h in $(FUZZ_HARNESSES); do \
	    t=$(FUZZ_SMOKE_SECONDS); [ $$h = script ] && t=$$((2 * $(FUZZ_SMOKE_SECONDS))); \
	    rm -rf $(FUZZ_DIR)/smoke/$$h; mkdir -p $(FUZZ_DIR)/smoke/$$h $(FUZZ_DIR)/findings/$$h; \
	    d=formats; [ $$h = script ] && d=frac; \
	    $(FUZZ_DIR)/fuzz/fuzz_$$h $(FUZZ_FLAGS) -max_total_time=$$t -dict=tests/fuzz/$$d.dict \
	        -artifact_prefix=$(FUZZ_DIR)/findings/$$h/ \
	        $(FUZZ_DIR)/smoke/$$h $(FUZZ_DIR)/corpus/$$h > $(FUZZ_DIR)/smoke/$$h.log 2>&1; rc=$$?; \
	    echo "fuzz-smoke $$h ($$t s): $$(grep -E '^#[0-9]+' $(FUZZ_DIR)/smoke/$$h.log | tail -n 1)"; \
	    if [ $$rc -ne 0 ]; then tail -n 40 $(FUZZ_DIR)/smoke/$$h.log; \
	        echo "fuzz-smoke: $$h failed (exit $$rc), see $(FUZZ_DIR)/findings/$$h/"; exit 1; fi; \
	done

clean:
	rm -rf build build-asan build-fuzz gallery

-include $(RT_OBJ:.o=.d) $(IN_OBJ:.o=.d)
