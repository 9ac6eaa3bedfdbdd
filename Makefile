# pray — build, test and render. Plain make; no probing of the host.
#   make            the command-line program ./pray
#   make examples   render every examples/*.ray into out/
#   make textures   the examples' TIFF textures, rendered by examples/maketex.ray into examples/tex/
#   make gallery    render every example into docs/gallery/ and write docs/gallery.md (tools/gallery.sh)
#   make test       the quick tier: a little of every layer of check, in a couple of minutes
#   make check      build and run all tests (installs the test packages if missing)
#   make sections   the line budget of each [SECTION] of pray.cpp (tests/sections.sh)
#   make matrix     compile pray.cpp under every configuration macro and language level, g++ and clang++
#   make bench      the acceleration benchmarks (bench/run.sh), results in docs/benchmarks.md
#   make pov        pray against POV-Ray 3.7 (bench/pov.sh; installs povray)
#   make suite      the benchmark suite against POV-Ray (bench/suite/run.sh; ARGS=--quick: default == --brute;
#                   ARGS=--scaling: time and memory against 10^3 .. 10^6 primitives)
#   make charts     speed against accuracy and the benchmarks, drawn (bench/charts.sh), docs/images/bench-*.png
#   make ports      build, run and compare every port (ports/check; installs cross compilers, qemu, wine)
#   make wasm       the wasm32-wasi port, run under Node and compared with ./pray (ports/check wasm)
#   make playground the PRAY playground page in ports/build/playground/ (docs/playground.md)
#   make playground-check  the playground in headless Chromium, compared with ./pray (installs chromium)
#   make check-bad  the catalogue of bad inputs (tests/bad/run.sh); the last step of check
#   make cmake-check  pray as a CMake and pkg-config package: tests/cmake/run.sh builds a consumer
#   make mpi        the MPI front end ./pray-mpi (ports/mpi; installs OpenMPI if missing)
#   make check-mpi  pray-mpi, --part/--join, --frames and the recipes of docs/distributed.md
#                   against one ./pray, byte for byte (tests/distributed.sh)
#   make sanitize   the tests and the bad inputs under AddressSanitizer and UBSan
#   make tsan       ThreadSanitizer: a render cancelled from another thread, two contexts at once
#   make fuzz       build the libFuzzer harness and fuzz for FUZZ_SECONDS (needs clang)
#   make fuzz-tiff  the same for the TIFF reader (textures and font atlases)
#   make fuzz-join  the same for the row parts that pray --join reads
#   make fuzz-long  the program harness on long inputs, from generated chains of 20000 operators
#   make clean

CXX      ?= c++
EXE      ?=
RUN      ?=
# -O3 and no errno from the maths functions (pray never reads it): 4-5 % faster than -O2 on
# the benchmark scenes, the same images
OPT      ?= -O3 -fno-math-errno
WARN     := -Wall -Wextra -pedantic
override CXXFLAGS := $(OPT) $(WARN) -fno-exceptions -fno-rtti $(CXXFLAGS)
LDLIBS   ?= -lm
TESTFLAGS = -std=c++17 -O1 -g -Wall -Wextra -DPRAY_CHECKS
PACKAGES  = doctest-dev libstb-dev python3 python3-pil libtiff-tools

PRAY  = pray$(EXE)
TESTS = tests/pray_tests$(EXE)
TESTS_FLOAT = tests/pray_tests_float$(EXE)
TEST_SRC = $(wildcard tests/test_*.cpp)

.PHONY: FORCE all examples test sections check deps matrix clean embed bench check-bad sanitize fuzz fuzz-tiff fuzz-join fuzz-long textures gallery ports wasm playground playground-check pov suite charts mpi mpi-deps check-mpi

all: $(PRAY)

$(PRAY): pray.cpp pray.hpp build/png
	$(CXX) -std=c++98 $(CXXFLAGS) -DPRAY_MAIN pray.cpp -o $@ $(LDLIBS)

# pray writes PNG when the compiler finds <stb/stb_image_write.h> (Debian libstb-dev). build/png
# says whether it does, and changes (so everything is built again) when the header comes or goes,
# e.g. when make check has installed it after make examples.
build/png: FORCE
	@mkdir -p build; \
	if echo '#include <stb/stb_image_write.h>' | $(CXX) -E -x c++ - >/dev/null 2>&1; then s=yes; else s=no; fi; \
	[ "$$(cat $@ 2>/dev/null)" = $$s ] || echo $$s >$@
FORCE:

# Install what the tests need when it is missing (Debian/Ubuntu; as root or through sudo).
deps:
	@missing=""; for p in $(PACKAGES); do dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
	if [ -n "$$missing" ]; then \
	  echo "installing:$$missing"; \
	  if [ "$$(id -u)" = 0 ]; then SUDO=; else SUDO=sudo; fi; \
	  $$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq $$missing >/dev/null; \
	fi

examples: $(PRAY) textures
	@mkdir -p out
	@for f in examples/*.ray; do \
	  n=$$(basename $$f .ray); \
	  case $$n in redsphx) continue;; esac; \
	  ext=png; ./$(PRAY) --version | grep -q png || ext=tif; \
	  printf '%-12s' $$n; $(RUN) ./$(PRAY) --quiet -o out/$$n.$$ext $$f >/dev/null || exit 1; echo " -> out/$$n.$$ext"; \
	done

# Each test file is compiled on its own (make -j builds them side by side; the packages first);
# only tests/test_internal.cpp includes pray.cpp, and with it the whole library.
TEST_HDR = tests/*.hpp pray.hpp build/png
build/tests/%.o: tests/%.cpp $(TEST_HDR) | deps
	@mkdir -p build/tests
	$(CXX) $(TESTFLAGS) -c $< -o $@
$(TESTS): $(TEST_SRC:tests/%.cpp=build/tests/%.o)
	$(CXX) $(TESTFLAGS) $^ -o $@ $(LDLIBS) -lpthread

# The same tests with the renderer in single precision (PRAY_REAL=float).
build/tests-float/%.o: tests/%.cpp $(TEST_HDR) | deps
	@mkdir -p build/tests-float
	$(CXX) $(TESTFLAGS) -DPRAY_REAL=float -c $< -o $@
$(TESTS_FLOAT): $(TEST_SRC:tests/%.cpp=build/tests-float/%.o)
	$(CXX) $(TESTFLAGS) -DPRAY_REAL=float $^ -o $@ $(LDLIBS) -lpthread

build/tests/test_internal.o build/tests-float/test_internal.o build/sanitize/test_internal.o: pray.cpp

# A build without file access (PRAY_NO_STDIO): rendering into buffers and textures the host
# registers, which such builds use instead of files (tests/test_buffers.cpp).
TESTS_NOSTDIO = tests/pray_tests_nostdio$(EXE)
$(TESTS_NOSTDIO): tests/test_main.cpp tests/test_buffers.cpp tests/*.hpp pray.cpp pray.hpp
	$(CXX) $(TESTFLAGS) -DPRAY_NO_STDIO tests/test_main.cpp tests/test_buffers.cpp pray.cpp -o $@ $(LDLIBS) -lpthread

# The C example, built as the README says: pray.hpp is usable from C, and pray.cpp compiled with
# the C++ compiler's defaults (exceptions on) links with the C compiler, needing no C++ runtime.
tests/embed$(EXE): examples/embed.c pray.cpp pray.hpp build/png
	$(CC) -std=c99 -pedantic -Wall -Wextra -Werror -I. -c examples/embed.c -o tests/embed.o
	$(CXX) -c pray.cpp -o tests/pray.o
	$(CC) tests/embed.o tests/pray.o -o $@ $(LDLIBS)
embed: tests/embed$(EXE)

check: sections deps $(PRAY) textures $(TESTS) $(TESTS_FLOAT) $(TESTS_NOSTDIO) tests/embed$(EXE)
	$(RUN) ./tests/embed$(EXE) tests/embed.ppm
	CC="$(CC)" CXX="$(CXX)" RUN="$(RUN)" sh tests/manual_examples.sh
	RUN="$(RUN)" sh tests/options.sh ./$(PRAY)
	@echo "== tests of rendering into buffers, without file access (PRAY_NO_STDIO)"
	$(RUN) ./$(TESTS_NOSTDIO)
	@echo "== tests, PRAY_REAL=float"
	$(RUN) ./$(TESTS_FLOAT)
	@echo "== tests, PRAY_REAL=double"
	$(RUN) ./$(TESTS)
	@$(MAKE) --no-print-directory check-bad

# The line budgets of pray.cpp's sections, given in its index comment (docs/testing.md).
sections:
	@sh tests/sections.sh -q

# The quick tier (docs/testing.md): every layer of check, lightly. The line budgets; ./pray as for
# check; the test files built without optimisation (compiling dominates): most of them in double
# precision, three in float, test_buffers.cpp without file access, each run as tests/quick.sh
# chooses; the C example; the programs of the manual; the options as --help and the manual
# present them; every fifth case of the bad inputs.
QUICK_TESTS = test_main test_internal test_smoke test_lang test_lang2 test_lang3 test_render test_sampling \
              test_accel test_coherence test_gallery test_docs test_buffers test_image test_texture \
              test_api test_limits test_interfaces
QUICK_FLOAT = test_main test_smoke test_render test_gallery test_lang3
QUICKFLAGS = -std=c++17 -O0 -Wall -Wextra -DPRAY_CHECKS
QUICK = build/quick/pray_tests$(EXE) build/quick/pray_tests_float$(EXE) build/quick/pray_tests_nostdio$(EXE)
build/quick/%.o: tests/%.cpp $(TEST_HDR) | deps
	@mkdir -p build/quick
	$(CXX) $(QUICKFLAGS) -c $< -o $@
build/quick/test_internal.o: pray.cpp
build/quick/pray_tests$(EXE): $(QUICK_TESTS:%=build/quick/%.o)
	$(CXX) $(QUICKFLAGS) $^ -o $@ $(LDLIBS) -lpthread
build/quick/float/%.o: tests/%.cpp $(TEST_HDR) | deps
	@mkdir -p build/quick/float
	$(CXX) $(QUICKFLAGS) -DPRAY_REAL=float -c $< -o $@
build/quick/float/pray.o: pray.cpp pray.hpp build/png
	@mkdir -p build/quick/float
	$(CXX) $(QUICKFLAGS) -DPRAY_REAL=float -c pray.cpp -o $@
build/quick/pray_tests_float$(EXE): $(QUICK_FLOAT:%=build/quick/float/%.o) build/quick/float/pray.o
	$(CXX) $(QUICKFLAGS) $^ -o $@ $(LDLIBS) -lpthread
build/quick/nostdio/%.o: tests/%.cpp $(TEST_HDR) | deps
	@mkdir -p build/quick/nostdio
	$(CXX) $(QUICKFLAGS) -DPRAY_NO_STDIO -c $< -o $@
build/quick/nostdio/pray.o: pray.cpp pray.hpp
	@mkdir -p build/quick/nostdio
	$(CXX) $(QUICKFLAGS) -DPRAY_NO_STDIO -c pray.cpp -o $@
build/quick/pray_tests_nostdio$(EXE): build/quick/test_main.o build/quick/nostdio/test_buffers.o build/quick/nostdio/pray.o
	$(CXX) $(QUICKFLAGS) $^ -o $@ $(LDLIBS) -lpthread

test: sections deps $(PRAY) textures $(QUICK) tests/embed$(EXE)
	$(RUN) ./tests/embed$(EXE) tests/embed.ppm
	CC="$(CC)" CXX="$(CXX)" RUN="$(RUN)" sh tests/manual_examples.sh
	RUN="$(RUN)" sh tests/options.sh ./$(PRAY)
	RUN="$(RUN)" sh tests/quick.sh build/quick
	@echo "== bad inputs, every fifth case (tests/bad: the numbers ending in 0 or 5)"
	PRAY=./$(PRAY) tests/bad/run.sh 0- 5-

# Bad inputs: exact messages and exit statuses, nothing left behind (docs/testing.md).
check-bad: $(PRAY)
	@echo "== bad inputs (tests/bad)"
	PRAY=./$(PRAY) tests/bad/run.sh

# The MPI front end (ports/mpi/pray-mpi.cpp), a host of the library: the library compiled as for
# ./pray, the front end with the MPI compiler wrapper. OpenMPI comes from Debian when missing.
MPICXX ?= mpicxx
MPI_PACKAGES = libopenmpi-dev openmpi-bin
PRAY_MPI = pray-mpi$(EXE)
mpi-deps:
	@missing=""; for p in $(MPI_PACKAGES) $(MPI_MORE); do dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
	if [ -n "$$missing" ]; then \
	  echo "installing:$$missing"; \
	  if [ "$$(id -u)" = 0 ]; then SUDO=; else SUDO=sudo; fi; \
	  $$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq $$missing >/dev/null; \
	fi
mpi: mpi-deps
	@$(MAKE) --no-print-directory $(PRAY_MPI)
build/mpi/pray.o: pray.cpp pray.hpp build/png
	@mkdir -p build/mpi
	$(CXX) -std=c++98 $(CXXFLAGS) -c pray.cpp -o $@
$(PRAY_MPI): ports/mpi/pray-mpi.cpp build/mpi/pray.o pray.hpp
	$(MPICXX) -std=c++11 $(OPT) $(WARN) -DOMPI_SKIP_MPICXX -DMPICH_SKIP_MPICXX -I. ports/mpi/pray-mpi.cpp build/mpi/pray.o -o $@ $(LDLIBS) -lpthread

# pray-mpi, the row parts and --join, --frames, and the recipes of docs/distributed.md (GNU
# parallel, a Slurm job array, mpirun), each compared byte for byte with one ./pray.
check-mpi: $(PRAY) textures
	@$(MAKE) --no-print-directory mpi MPI_MORE=parallel
	sh tests/distributed.sh

# The consumer of tests/cmake/ built with add_subdirectory, find_package and pkg-config, in a
# temporary directory (needs cmake and pkg-config).
.PHONY: cmake-check
cmake-check:
	tests/cmake/run.sh

# The doctest suite and ./pray built with AddressSanitizer and UBSan into build/sanitize/, then
# the suite (whose command-line tests use the plain ./pray) and the bad inputs run with them.
# float-cast-overflow: part of clang's "undefined" but not of GCC's.
SANFLAGS = -fsanitize=address,undefined,float-cast-overflow -fno-sanitize-recover=undefined,float-cast-overflow -O1 -g
build/sanitize/%.o: tests/%.cpp $(TEST_HDR) | deps
	@mkdir -p build/sanitize
	$(CXX) $(TESTFLAGS) $(SANFLAGS) -c $< -o $@
build/sanitize/pray_tests: $(TEST_SRC:tests/%.cpp=build/sanitize/%.o)
	$(CXX) $(TESTFLAGS) $(SANFLAGS) $^ -o $@ $(LDLIBS) -lpthread
sanitize: deps $(PRAY) textures
	@mkdir -p build/sanitize
	$(CXX) -std=c++98 $(SANFLAGS) $(WARN) -fno-exceptions -fno-rtti -DPRAY_MAIN pray.cpp -o build/sanitize/pray $(LDLIBS)
	@$(MAKE) --no-print-directory build/sanitize/pray_tests
	@echo "== tests under the sanitizers"
	./build/sanitize/pray_tests
	@echo "== bad inputs under the sanitizers"
	PRAY=build/sanitize/pray tests/bad/run.sh

# ThreadSanitizer (GCC's, which sees a plain flag written by one thread and read by another): a
# render on two threads cancelled from a third, and two contexts rendering at once; a race makes
# the program exit non-zero.
.PHONY: tsan
build/tsan/%: tests/tsan/%.cpp pray.cpp pray.hpp
	@mkdir -p build/tsan
	g++ -std=c++11 -g -O1 -fsanitize=thread -I. $< pray.cpp -o $@ -lpthread
tsan: build/tsan/cancel build/tsan/shared
	TSAN_OPTIONS=halt_on_error=1 ./build/tsan/cancel
	TSAN_OPTIONS=halt_on_error=1 ./build/tsan/shared

# libFuzzer (clang; on Debian the runtime is in libclang-rt-14-dev): the harness runs fuzz inputs
# as PRAY programs. New inputs go to build/fuzz/corpus, crashes to build/fuzz/artifacts/; the seeds
# and the regression inputs of tests/fuzz/ are read, never written.
FUZZ_CXX ?= clang++
FUZZ_SECONDS ?= 60
FUZZFLAGS = -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined
build/fuzz/fuzz_program: tests/fuzz/fuzz_program.cpp pray.cpp pray.hpp
	@mkdir -p build/fuzz
	$(FUZZ_CXX) $(FUZZFLAGS) -I. tests/fuzz/fuzz_program.cpp pray.cpp -o $@
fuzz: build/fuzz/fuzz_program
	@mkdir -p build/fuzz/corpus build/fuzz/artifacts
	build/fuzz/fuzz_program -max_total_time=$(FUZZ_SECONDS) -max_len=4096 -timeout=10 \
	  -dict=tests/fuzz/pray.dict -artifact_prefix=build/fuzz/artifacts/ \
	  build/fuzz/corpus tests/fuzz/corpus tests/fuzz/crashes
# Long inputs (up to 256 KiB): the seeds are generated into build/fuzz/seeds_long by
# tests/fuzz/long_seeds.sh, new inputs go to build/fuzz/corpus_long.
fuzz-long: build/fuzz/fuzz_program
	@mkdir -p build/fuzz/corpus_long build/fuzz/artifacts
	tests/fuzz/long_seeds.sh build/fuzz/seeds_long
	build/fuzz/fuzz_program -max_total_time=$(FUZZ_SECONDS) -max_len=262144 -timeout=10 \
	  -dict=tests/fuzz/pray.dict -artifact_prefix=build/fuzz/artifacts/long- \
	  build/fuzz/corpus_long build/fuzz/seeds_long tests/fuzz/crashes
build/fuzz/fuzz_tiff: tests/fuzz/fuzz_tiff.cpp pray.cpp pray.hpp
	@mkdir -p build/fuzz
	$(FUZZ_CXX) $(FUZZFLAGS) -I. tests/fuzz/fuzz_tiff.cpp pray.cpp -o $@
fuzz-tiff: build/fuzz/fuzz_tiff
	@mkdir -p build/fuzz/corpus_tiff build/fuzz/artifacts
	build/fuzz/fuzz_tiff -max_total_time=$(FUZZ_SECONDS) -max_len=65536 -timeout=10 \
	  -artifact_prefix=build/fuzz/artifacts/tiff- build/fuzz/corpus_tiff tests/fuzz/corpus_tiff tests/fuzz/crashes
# --join: the input cut into row parts at "<part>", joined by the command line's main (the
# harness includes pray.cpp with PRAY_MAIN).
build/fuzz/fuzz_join: tests/fuzz/fuzz_join.cpp pray.cpp pray.hpp
	@mkdir -p build/fuzz
	$(FUZZ_CXX) $(FUZZFLAGS) -I. tests/fuzz/fuzz_join.cpp -o $@
fuzz-join: build/fuzz/fuzz_join
	@mkdir -p build/fuzz/corpus_join build/fuzz/artifacts
	build/fuzz/fuzz_join -max_total_time=$(FUZZ_SECONDS) -max_len=16384 -timeout=10 -dict=tests/fuzz/join.dict \
	  -artifact_prefix=build/fuzz/artifacts/join- build/fuzz/corpus_join tests/fuzz/corpus_join

# The textures of the examples, made by pray itself.
textures: $(PRAY)
	@mkdir -p examples/tex
	cd examples/tex && $(RUN) ../../$(PRAY) --quiet ../maketex.ray

# The gallery: every example rendered at 256 x 256 with its statistics (docs/gallery.md).
gallery: $(PRAY) textures
	tools/gallery.sh

# Benchmarks print tables; they are never part of check.
bench: $(PRAY)
	bench/run.sh

pov: $(PRAY)
	bench/pov.sh

# The suite's scenes against POV-Ray (docs/benchmarks.md); ARGS=--quick checks default == --brute.
suite: $(PRAY) textures
	bench/suite/run.sh $(ARGS)

# Time against error (undersampling, antialias, grid, float), threads, Table 3.6.1 and scaling, drawn.
charts: $(PRAY) textures
	bench/charts.sh

# Every configuration macro and port configuration at C++98 and the newest level, the levels
# between with the default one, under g++ and clang++, warnings as errors (tests/matrix.sh).
matrix:
	sh tests/matrix.sh

# Every port built, run under qemu-user or wine, its images compared with ./pray's (ports/README.md).
ports:
	sh ports/check

# The wasm32-wasi port alone: built with clang, run under Node, compared with ./pray.
wasm:
	sh ports/check wasm

# The playground (ports/wasm/playground, docs/playground.md), and its test in headless Chromium.
playground: $(PRAY)
	sh ports/wasm/playground.sh
playground-check: $(PRAY)
	sh ports/wasm/playground-check.sh

clean:
	rm -rf $(PRAY) $(PRAY_MPI) build/mpi build/tests build/tests-float build/sanitize build/quick $(TESTS) $(TESTS_FLOAT) \
	  $(TESTS_NOSTDIO) tests/embed$(EXE) tests/*.o tests/*.ppm out
