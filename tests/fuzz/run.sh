#!/usr/bin/env bash
# tests/fuzz/run.sh [SECONDS] - build the libFuzzer targets into build/fuzz/ and run
# each for SECONDS (default 60), FUZZ_JOBS (default 2) at a time, builds and runs alike: mesh_build,
# lapped, synth (tiled-texture synthesis, seams, 8-bit images), hpm (the
# hierarchy, flattening and tt_hpm_map), polycube (build, colours, mapping,
# UVs), obj (the tool's OBJ reader, when examples/tool_io.c compiles),
# mesh_file (the tool's mesh files: STL, OFF, format detection, welding) and
# image (the tool's image loader through stb_image, and the library's image
# operations). FUZZ_TARGETS="a b" runs only those. Exits non-zero if a target crashed,
# leaked, hit undefined behaviour or broke a contract check; the input that did it
# is saved as build/fuzz/<target>-crash-* (or -leak-, -timeout-, -oom-); exits 2
# when clang cannot build libFuzzer targets, 3 when a target does not build.
#
# The seed corpora in tests/fuzz/corpus_* are copied into build/fuzz/corpus_*
# (which keeps growing from run to run until `make clean`), so the repository's
# seeds are never modified. Needs clang with libFuzzer (FUZZ_CC overrides).
#
# For long campaigns: FUZZ_RUNS=N runs each target to N inputs instead of
# SECONDS, and FUZZ_SANITIZE=0 builds into build/fuzz-plain/ without ASan and
# UBSan (libFuzzer's coverage and the targets' own contract checks only,
# about three times the runs a second; no leak or out-of-bounds detection).
#
# Reproduce a saved input:  build/fuzz/fuzz_obj build/fuzz/fuzz_obj-crash-<sha1>
set -u
secs=${1:-60}
root=$(cd "$(dirname "$0")/../.." && pwd)
cd "$root" || exit 2
out=build/fuzz
[ "${FUZZ_SANITIZE:-1}" = 0 ] && out=build/fuzz-plain
mkdir -p "$out"

cc=${FUZZ_CC:-clang}
# libFuzzer needs clang and its runtime (Debian: clang, libclang-rt-14-dev);
# install them when we may (root with apt-get), as make demo does for stb.
probe=$(mktemp -d)
printf 'int LLVMFuzzerTestOneInput(const unsigned char *d, unsigned long n) { (void)d; (void)n; return 0; }\n' >"$probe/p.c"
if ! "$cc" -fsanitize=fuzzer "$probe/p.c" -o "$probe/p" >/dev/null 2>&1; then
  if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1 && [ -z "${FUZZ_CC:-}" ]; then
    echo "fuzz: installing clang and libclang-rt-14-dev (libFuzzer) ..." >&2
    apt-get install -y -qq clang libclang-rt-14-dev >/dev/null 2>&1 ||
      { apt-get update -qq >/dev/null 2>&1 && apt-get install -y -qq clang libclang-rt-14-dev >/dev/null 2>&1; }
  fi
  if ! "$cc" -fsanitize=fuzzer "$probe/p.c" -o "$probe/p" >/dev/null 2>&1; then
    rm -rf "$probe"
    echo "fuzz: $cc cannot build libFuzzer targets: run  sudo apt-get install clang libclang-rt-14-dev  (or set FUZZ_CC)" >&2
    exit 2
  fi
fi
rm -rf "$probe"
flags="-std=c99 -g -O1 -pthread -fno-omit-frame-pointer -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all"
[ "${FUZZ_SANITIZE:-1}" = 0 ] && flags="-std=c99 -g -O2 -pthread -fsanitize=fuzzer"
warn="-Wall -Wextra -pedantic -Wshadow -Wstrict-prototypes"
# stb as a system header: its own warnings are not ours to fix
stb=$(pkg-config --cflags-only-I stb 2>/dev/null | sed "s/-I/-isystem /g")
[ -n "$stb" ] || stb="-isystem /usr/include/stb"

# The library is compiled once with the sanitizers and libFuzzer's coverage
# (tests/fuzz/fuzz_library.c, over a minute on one core), then each target,
# only its own file and the tool's files it tests, is linked against it.
# Builds run FUZZ_JOBS (default 2) at a time, each into its own log, and are
# checked in order once every build is done.
build_jobs=${FUZZ_JOBS:-2}
[ "$build_jobs" -ge 1 ] 2>/dev/null || build_jobs=2
building=()
build_start() {
  local name=$1
  shift
  while [ "$(jobs -rp | wc -l)" -ge "$build_jobs" ]; do wait -n; done
  rm -f "$out/build_$name.rc"
  ( "$@" >"$out/build_$name.log" 2>&1; echo $? >"$out/build_$name.rc" ) &
  building+=("$name")
}
# polycube links a copy of the library built without libFuzzer's comparison
# tracing: its decisions are on floats, which the tracing does not see, while
# tracing the integer comparisons of its inner loops (sorts, chart and quad
# indices) halved its runs a second.
nocmp="-fno-sanitize-coverage=trace-cmp"
build_library() {   # the object's name, then its extra flags
  local name=$1
  shift
  # shellcheck disable=SC2086  # flags are lists
  $cc $flags "$@" $warn -I. -c tests/fuzz/fuzz_library.c -o "$out/$name.o"
}
build_plain() {   # mesh_build, lapped, synth, hpm: the target alone
  $cc $flags $warn -I. "tests/fuzz/fuzz_$1.c" "$out/fuzz_library.o" -o "$out/fuzz_$1" -lm
}
build_polycube() {
  $cc $flags $nocmp $warn -I. tests/fuzz/fuzz_polycube.c "$out/fuzz_library_nocmp.o" -o "$out/fuzz_polycube" -lm
}
# The tool's OBJ reader (examples/obj.c) with what it uses: tool_io.c (errors,
# files, buffers), format_number.c (the writer's numbers) and executor.c
# (the writer formats its lines on the tool's threads). These are compiled
# as they are.
obj_sources="examples/obj.c examples/tool_io.c examples/format_number.c examples/executor.c"
build_obj() {
  # shellcheck disable=SC2086
  $cc $flags $warn -I. -Iexamples $stb tests/fuzz/fuzz_obj.c $obj_sources "$out/fuzz_library.o" -o "$out/fuzz_obj" -lm
}
# The tool's mesh files (examples/mesh_file.c), with the OBJ reader it hands
# OBJs to and cli.c for its number parsing.
mesh_file_sources="examples/mesh_file.c $obj_sources examples/cli.c"
build_mesh_file() {
  # shellcheck disable=SC2086
  $cc $flags $warn -I. -Iexamples $stb tests/fuzz/fuzz_mesh_file.c $mesh_file_sources "$out/fuzz_library.o" -o "$out/fuzz_mesh_file" -lm
}
# The tool's image loader (examples/image_io.c: stb_image, the size checks,
# the conversion in strips) and the library's image operations.
# image_io.c, which compiles Debian's stb_image (2.27), is built without
# UBSan's shift and signed-overflow checks: on corrupt coded data the JPEG
# decoder shifts its bit buffer by 32 or more and multiplies a DC value by a
# 16-bit quantiser past INT_MAX (upstream checks both from 2.28 on). That is
# the decoder's arithmetic, not its memory, which ASan and the other checks
# still watch; the pre-checks of image_io.c keep out what does touch memory
# (Huffman tables of more than 256 codes or used undefined, PNG chunks past
# the end of the file, PNM sizes over INT_MAX). Every other file keeps every
# check.
image_sources="examples/png_write.c examples/tool_io.c examples/executor.c examples/obj.c examples/format_number.c"
build_image() {
  # shellcheck disable=SC2086
  $cc $flags -fno-sanitize=shift,signed-integer-overflow $warn -I. -Iexamples $stb -c examples/image_io.c \
    -o "$out/image_io.o" &&
    $cc $flags $warn -I. -Iexamples $stb tests/fuzz/fuzz_image.c $image_sources "$out/image_io.o" "$out/fuzz_library.o" \
      -o "$out/fuzz_image" -lm -pthread
}

# A build that failed: its log and exit 3.
build_failed() {
  cat "$out/build_$1.log" >&2
  echo "fuzz: fuzz_$1 does not build" >&2
  exit 3
}
echo "fuzz: building into $out/" >&2
build_start library build_library fuzz_library
build_start library_nocmp build_library fuzz_library_nocmp "$nocmp"
wait
for t in library library_nocmp; do
  [ "$(cat "$out/build_$t.rc" 2>/dev/null)" = 0 ] || build_failed "$t"
done
building=()
for t in mesh_build lapped synth hpm; do build_start "$t" build_plain "$t"; done
build_start polycube build_polycube
if [ -f examples/obj.c ] && [ -f examples/tool_io.c ] && [ -f examples/format_number.c ] && [ -f examples/tool.h ]; then
  build_start obj build_obj
else
  echo "fuzz: SKIPPED fuzz_obj: one of $obj_sources examples/tool.h is missing" >&2
fi
build_start mesh_file build_mesh_file
build_start image build_image
wait
targets=()
for t in "${building[@]}"; do
  if [ "$(cat "$out/build_$t.rc" 2>/dev/null)" = 0 ]; then
    cat "$out/build_$t.log" >&2
    targets+=("$t")
  else
    build_failed "$t"
  fi
done
# FUZZ_BUILD_ONLY=1: build, list the targets on stdout, run nothing (the
# smoke runs of tests/run.sh).
if [ -n "${FUZZ_BUILD_ONLY:-}" ]; then
  echo "${targets[@]}"
  exit 0
fi
# FUZZ_TARGETS="hpm image" builds everything but runs only those.
if [ -n "${FUZZ_TARGETS:-}" ]; then
  only=()
  for t in "${targets[@]}"; do
    case " $FUZZ_TARGETS " in *" $t "*) only+=("$t") ;; esac
  done
  targets=("${only[@]}")
fi

jobs_max=${FUZZ_JOBS:-2}
[ "$jobs_max" -ge 1 ] 2>/dev/null || jobs_max=2
declare -A pid
start() {
  local t=$1 corpus="$out/corpus_$1" extra=()
  mkdir -p "$corpus"
  cp -n tests/fuzz/corpus_"$t"/* "$corpus"/ 2>/dev/null
  [ -f tests/fuzz/"$t".dict ] && extra+=("-dict=tests/fuzz/$t.dict")
  local budget="-max_total_time=$secs"
  [ -n "${FUZZ_RUNS:-}" ] && budget="-runs=$FUZZ_RUNS"
  "$out/fuzz_$t" "$budget" -max_len=4096 -timeout=20 -rss_limit_mb=2048 \
    -print_final_stats=1 -artifact_prefix="$out/fuzz_$t-" "${extra[@]}" "$corpus" \
    >"$out/fuzz_$t.log" 2>&1 &
  pid[$t]=$!
}

# At most jobs_max targets at once (the machine may be shared): target i
# starts when target i - jobs_max has finished.
status=0
n=${#targets[@]}
for ((i = 0; i < n && i < jobs_max; i++)); do start "${targets[$i]}"; done
for ((i = 0; i < n; i++)); do
  t=${targets[$i]}
  wait "${pid[$t]}"
  rc=$?
  [ $((i + jobs_max)) -lt "$n" ] && start "${targets[$((i + jobs_max))]}"
  log="$out/fuzz_$t.log"
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  cov=$(grep -o 'cov: [0-9]* ft: [0-9]* corp: [0-9]*/[^ ]*' "$log" | tail -1)
  deep=$(grep -o '[0-9]* of [0-9]* runs ([0-9.]* %) reached .*' "$log" | tail -1)
  if [ "$rc" = 0 ]; then
    echo "fuzz_$t: ok, ${execs:-?} execs (${rate:-?} a second), $cov${deep:+; $deep}"
  else
    status=1
    echo "fuzz_$t: FAILED (exit $rc) after ${execs:-?} execs; log: $log"
    grep -m1 -E 'ERROR: |contract broken|runtime error|deadly signal' "$log" | sed 's/^/    /'
    grep -E '^(artifact_prefix|Test unit written)' "$log" | sed 's/^/    /'
  fi
done
exit $status
