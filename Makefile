# tiledtex - make / make demo / make test / make learn / make bench / make bench-build / make bench-scale / make fuzz
CC      ?= cc
CFLAGS  ?= -O2 -g
WARN    := -std=c99 -Wall -Wextra -pedantic -Wshadow -Wstrict-prototypes
STB_INC := $(shell pkg-config --cflags stb 2>/dev/null || echo -I/usr/include/stb)
TOOL_SRC := $(wildcard examples/*.c)
TOOL_HDR := $(wildcard examples/*.h) tiledtex.h
# The tool's thread pool (examples/executor.c, -j N) uses POSIX threads.

.PHONY: all demo test learn bench bench-build bench-scale fuzz clean deps test-deps

all: build/tiledtex

build/tiledtex: $(TOOL_SRC) $(TOOL_HDR) | build
	$(CC) $(CFLAGS) $(WARN) -pthread -I. $(STB_INC) $(TOOL_SRC) -o $@ -lm

build:
	mkdir -p build

# Install what is missing when we may (root with apt-get), otherwise say the
# one command to run: libstb-dev for the tool; clang and tcc for the tests.
deps:
	@bash tests/ensure_deps.sh demo

test-deps:
	@bash tests/ensure_deps.sh test

demo: deps build/tiledtex
	@bash examples/demo.sh

test: test-deps
	@bash tests/run.sh

# The learner's programs (examples/learn/): each built as its README says, run
# on generated inputs, and its OBJ rendered to build/learn/NAME_view.png.
learn: deps build/tiledtex
	@bash tests/learn.sh build/tiledtex

build/bench: bench/bench.c bench/bench_clock.h tiledtex.h | build
	$(CC) -O2 -g $(WARN) -I. bench/bench.c -o $@ -lm

build/bench_cg: bench/bench_cg.c bench/bench_cg_problem.h bench/bench_clock.h tiledtex.h | build
	$(CC) -O2 -g $(WARN) -I. bench/bench_cg.c -o $@ -lm

# The optional peer: the same CG system solved by Eigen, when Debian's
# libeigen3-dev is installed (the target is ours within 1.1x of it).
EIGEN_INC := $(wildcard /usr/include/eigen3)
build/bench_cg_eigen: bench/bench_cg_eigen.cpp bench/bench_cg_problem.h | build
	$(CXX) -O2 -DNDEBUG -I$(EIGEN_INC) -Ibench bench/bench_cg_eigen.cpp -o $@

build/bench_fft: bench/bench_fft.c bench/bench_clock.h tiledtex.h | build
	$(CC) -O2 -g $(WARN) -I. bench/bench_fft.c -o $@ -lm

# The optional peer: the same transforms through FFTW's FFTW_MEASURE plans,
# timed in the same process, when Debian's libfftw3-dev is installed (the
# target is ours within 3x of it). FFTW is GPL: a bench peer only.
FFTW_INC := $(wildcard /usr/include/fftw3.h)
build/bench_fft_fftw: bench/bench_fft.c bench/bench_clock.h tiledtex.h | build
	$(CC) -O2 -g $(WARN) -I. -DBENCH_FFTW bench/bench_fft.c -o $@ -lfftw3 -lm

build/bench_build: bench/bench_build.c bench/bench_build_meshes.h bench/bench_clock.h bench/bench_radix_pairing.h tiledtex.h | build
	$(CC) -O2 -g $(WARN) -I. bench/bench_build.c -o $@ -lm

# The optional peer of bench_build: CGAL's Surface_mesh built from the same
# meshes, when Debian's libcgal-dev is installed (the target is tiledtex 2x
# faster on the grid and soup meshes, 1.5x on the shuffled one).
CGAL_INC := $(wildcard /usr/include/CGAL)
build/bench_build_cgal: bench/bench_build_cgal.cpp bench/bench_build_meshes.h bench/bench_clock.h tiledtex.h | build
	$(CXX) -O2 -DNDEBUG -I. -Ibench bench/bench_build_cgal.cpp -o $@

build/bench_run: bench/bench_run.c bench/bench_clock.h | build
	$(CC) -O2 $(WARN) bench/bench_run.c -o $@

# The scale figures (bench/bench_scale.sh): every pipeline on a real scan and
# on it cut 1-to-4 and 1-to-16, at -j 1 and -j 2, beside v0.3.0 built from its
# commit. About 25 minutes; BENCH_SCALES="1 4" for a shorter run.
bench-scale: deps build/bench_run build/tiledtex
	@bash bench/bench_scale.sh build/tiledtex

bench: deps build/bench build/bench_run build/bench_cg $(if $(EIGEN_INC),build/bench_cg_eigen) $(if $(FFTW_INC),build/bench_fft_fftw,build/bench_fft) build/bench_build $(if $(CGAL_INC),build/bench_build_cgal) build/tiledtex
	@./build/bench
	@./build/bench_cg
	@$(if $(EIGEN_INC),./build/bench_cg_eigen,echo "(no Eigen peer: apt-get install libeigen3-dev)" >&2)
	@$(if $(FFTW_INC),./build/bench_fft_fftw,./build/bench_fft; echo "(no FFTW peer: apt-get install libfftw3-dev)" >&2)
	@./build/bench_build
	@$(if $(CGAL_INC),./build/bench_build_cgal,echo "(no CGAL peer: apt-get install libcgal-dev)" >&2)
	@bash bench/bench_scale.sh build/tiledtex

# Only the mesh-build figures (a few seconds each).
bench-build: build/bench_build $(if $(CGAL_INC),build/bench_build_cgal)
	@./build/bench_build
	@$(if $(CGAL_INC),./build/bench_build_cgal,echo "(no CGAL peer: apt-get install libcgal-dev)" >&2)

# tests/fuzz/run.sh builds the libFuzzer targets (mesh builder, OBJ reader,
# STL/OFF mesh files, lapped textures, tile synthesis) and runs them two at a time (FUZZ_JOBS),
# FUZZ_SECONDS each.
FUZZ_SECONDS ?= 60
fuzz: deps
	@bash tests/fuzz/run.sh $(FUZZ_SECONDS)

clean:
	rm -rf build
