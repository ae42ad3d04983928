#!/usr/bin/env bash
# tests/run.sh - the test runner behind `make test`.
#
#   1. compile checks of tiledtex.h (each counts as one test): gcc C99 with
#      strict warnings (also at -O3), g++ as C++, clang, tcc, TILEDTEX_STATIC (every function
#      used, and only one used), user-defined TT_MALLOC/TT_FREE, the helpers'
#      preconditions caught by TT_ASSERT (tests/assert_check.c), the named
#      limits defined small (tests/limits_check.c), the two
#      QUICK START blocks compiled and run, every public declaration checked
#      against the API contract (tests/check_api.sh), and no raw
#      malloc/free/realloc/calloc outside the TT_MALLOC/TT_FREE defaults;
#   2. the unit tests, tests/test_*.c (test_common.c and one file per section
#      of the header, built into one program), with ASan + UBSan, run as two
#      processes at once (the hpm section; every other section);
#   3. a sanitizer build of the tool and the end-to-end tests (tests/e2e.sh);
#   4. the import test (tests/import_check.sh, that build): each pipeline's
#      default OBJ and GLB opened in assimp and Blender, each skipped with
#      one line when not installed;
#   5. the learner's programs, examples/learn/*.c, built with the command
#      their README gives, run and rendered (tests/learn.sh);
#   6. a short smoke run of each libFuzzer target in tests/fuzz (skipped,
#      saying why, when clang's libFuzzer is missing).
# These run as stages, as many at once as there are cores (TEST_JOBS=N sets
# it; see the scheduler at the end), and each stage's output is printed
# whole, in a fixed order. The last line is "N passed, M failed" over
# everything; the exit status is non-zero when M > 0.
set -u
cd "$(dirname "$0")/.." || { echo "0 passed, 1 failed"; exit 1; }

PASSED=0
FAILED=0
START=$(date +%s)
OUT=build/tests
mkdir -p "$OUT" || { echo "0 passed, 1 failed"; exit 1; }
CC=${CC:-cc}
# Sanitizer reports must stop the program and say where.
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0${ASAN_OPTIONS:+:$ASAN_OPTIONS}"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1${UBSAN_OPTIONS:+:$UBSAN_OPTIONS}"

pass() { PASSED=$((PASSED + 1)); echo "ok   $1"; }
fail() {
    FAILED=$((FAILED + 1))
    echo "FAIL $1"
    if [ -n "${2:-}" ]; then printf '%s\n' "$2" | head -n 25 | sed 's/^/     | /'; fi
}

# Compile tests/compile_check.c (which calls every public function) with a
# compiler command and -Werror, link, and run it: one test.
compile_check() {
    local name=$1 exe=$OUT/compile_$2 log
    shift 2
    if ! command -v "$1" >/dev/null 2>&1; then
        fail "compile: $name ($1 not installed: apt-get install $1)"
        return
    fi
    if ! log=$("$@" -I. tests/compile_check.c -o "$exe" -lm 2>&1); then
        fail "compile: $name: $*" "$log"
        return
    fi
    if [ -n "$log" ]; then
        fail "compile: $name printed diagnostics: $*" "$log"
        return
    fi
    if ! log=$("$exe" 2>&1); then
        fail "compile: $name: the smoke run failed" "$log"
        return
    fi
    pass "compile: $name"
}

# A QUICK START block of tiledtex.h, exactly as printed there (from the line
# after its heading up to the line before `end`, comments dropped), inside a
# program that gives it its inputs and checks its result: documentation that
# compiles and runs. Arguments: name, heading pattern, end pattern, what it
# does (for the report), the C lines before the block and after it (each one
# string of newline-separated lines).
quickstart_check() {
    local name=$1 heading=$2 end=$3 what=$4 before=$5 after=$6 src=$OUT/$1.c log
    {
        printf '%s\n' '#include <stdio.h>' '#include <stdlib.h>' '#define TILEDTEX_IMPLEMENTATION' \
            '#include "tiledtex.h"' 'int main(void) {' "$before" '{'
        sed -n "/$heading/,/$end/p" tiledtex.h | sed '1d;$d' | sed 's|//.*$||'
        printf '%s\n' "$after"
    } >"$src"
    if log=$(gcc -std=c99 -Wall -Wextra -pedantic -Werror -Wno-declaration-after-statement -I. -g \
            -fsanitize=address,undefined "$src" -o "$OUT/$name" -lm 2>&1) && log=$("$OUT/$name" 2>&1); then
        pass "docs: the $heading in tiledtex.h compiles, runs and $what"
    else
        fail "docs: the $heading in tiledtex.h does not compile or run" "$log"
    fi
}

# Run a test program that ends with "N passed, M failed" and add its counts.
# A sanitizer report printed after that line (LeakSanitizer runs at exit) is
# one more failure; a missing line (a crash, a sanitizer abort) is one failure.
run_counted() {
    local name=$1 status summary p m
    shift
    "$@" 2>&1 | tee "$OUT/$name.log"
    status=${PIPESTATUS[0]}
    summary=$(grep -E '^[0-9]+ passed, [0-9]+ failed$' "$OUT/$name.log" | tail -n 1)
    if [[ $summary =~ ^([0-9]+)\ passed,\ ([0-9]+)\ failed$ ]]; then
        p=${BASH_REMATCH[1]}
        m=${BASH_REMATCH[2]}
        PASSED=$((PASSED + p))
        FAILED=$((FAILED + m))
        if [ "$(tail -n 1 "$OUT/$name.log")" != "$summary" ]; then
            fail "$name: output after its summary line (sanitizer report at exit?), exit status $status"
        elif [ "$m" -eq 0 ] && [ "$status" -ne 0 ]; then
            fail "$name: reported no failures but exited with status $status"
        fi
    else
        fail "$name: exited with status $status without its 'N passed, M failed' line (crash or sanitizer report?)"
    fi
}

# 1. The compile checks (one test each).
stage_compile() {
    echo "== compile checks"
    compile_check "gcc -std=c99 strict" gcc_c99 \
        gcc -std=c99 -Wall -Wextra -pedantic -Wshadow -Wstrict-prototypes -Werror
    compile_check "gcc -O3 strict (the warnings only the optimiser finds)" gcc_o3 \
        gcc -std=c99 -O3 -Wall -Wextra -pedantic -Wshadow -Wstrict-prototypes -Werror
    compile_check "g++ as C++" gxx \
        g++ -x c++ -Wall -Wextra -pedantic -Werror
    compile_check "clang -std=c99" clang \
        clang -std=c99 -Wall -Wextra -pedantic -Wshadow -Wstrict-prototypes -Werror
    if command -v tcc >/dev/null 2>&1; then
        compile_check "tcc" tcc tcc -Wall -Werror
    else
        fail "compile: tcc not installed: apt-get install tcc"
    fi
    compile_check "TILEDTEX_STATIC (every function used)" static \
        gcc -std=c99 -Wall -Wextra -pedantic -Wshadow -Wstrict-prototypes -Werror -DTILEDTEX_STATIC
    compile_check "user-defined TT_MALLOC/TT_FREE" user_alloc \
        gcc -std=c99 -Wall -Wextra -pedantic -Wshadow -Wstrict-prototypes -Werror -DCOMPILE_CHECK_USER_ALLOC

    # The helpers that return no tt_result state their preconditions: each broken
    # one must reach TT_ASSERT before touching memory, and under NDEBUG the ones
    # that promise a safe answer must give it (tests/assert_check.c).
    for variant in debug ndebug; do
        flags=""
        [ "$variant" = ndebug ] && flags="-DASSERT_CHECK_NDEBUG"
        # shellcheck disable=SC2086  # flags is empty or one flag
        if log=$(gcc -std=c99 -g -Wall -Wextra -pedantic -Werror -fsanitize=address,undefined -fno-sanitize-recover=all \
                $flags -I. tests/assert_check.c -o "$OUT/assert_check_$variant" -lm 2>&1) &&
            log=$("$OUT/assert_check_$variant" 2>&1); then
            pass "asserts: every documented precondition of the helpers is checked ($variant build)"
        else
            fail "asserts: a broken precondition is not caught ($variant build)" "$log"
        fi
    done

    # The named limits, each defined small before the header (tests/limits_check.c):
    # refused with TT_ERROR_TOO_LARGE naming the limit, and work under it runs.
    if log=$(gcc -std=c99 -g -Wall -Wextra -pedantic -Werror -fsanitize=address,undefined -fno-sanitize-recover=all \
            -I. tests/limits_check.c -o "$OUT/limits_check" -lm 2>&1) && log=$("$OUT/limits_check" 2>&1); then
        pass "limits: each named limit, defined small, refuses what passes it (TT_ERROR_TOO_LARGE naming it)"
    else
        fail "limits: a named limit is not enforced or not named" "$log"
    fi

    # TILEDTEX_STATIC in a file that uses one function, as a user would: the
    # functions it does not call must not warn (-Wunused-function) under -Wall.
    {
        src=$OUT/static_one.c
        printf '%s\n' '#define TILEDTEX_STATIC' '#define TILEDTEX_IMPLEMENTATION' '#include "tiledtex.h"' \
            'int main(void) { tt_rng r; tt_rng_seed(&r, 1, 2); return (int)(tt_rng_next(&r) & 0u); }' >"$src"
        if log=$(gcc -std=c99 -Wall -Wextra -pedantic -Werror -I. -c "$src" -o "$OUT/static_one.o" 2>&1) &&
            log2=$(clang -std=c99 -Wall -Wextra -pedantic -Werror -I. -c "$src" -o "$OUT/static_one.o" 2>&1); then
            pass "compile: TILEDTEX_STATIC with one function used (gcc, clang -Wall -Werror)"
        else
            fail "compile: TILEDTEX_STATIC with one function used warns about the unused ones (gcc/clang -Wall -Werror)" \
                "$(printf '%s\n%s' "$log" "${log2:-}" | grep -E 'error|warning' | head -n 6)"
        fi
    }

    # Tiled textures: a 2x2 grid of quads and an 8-bit photo; it must make the
    # atlas, encode it and free everything (LeakSanitizer checks the frees).
    quickstart_check quickstart "QUICK START: tile" "QUICK START: lapped" "makes and frees a 544x544 atlas and its normal atlas" \
        'static const float xyz[27] = {0,0,0, 1,0,0, 2,0,0, 0,1,0, 1,1,0, 2,1,0, 0,2,0, 1,2,0, 2,2,0};
    static const int quads[16] = {0,1,4,3, 1,2,5,4, 3,4,7,6, 4,5,8,7};
    int nverts = 9, nquads = 4, w = 128, h = 256, channels = 3, x; uint8_t types[16]; float uv[32];
    static unsigned char bytes[128 * 256 * 3], nbytes[128 * 256 * 3];
    unsigned char *rgba = (unsigned char *)malloc(544 * 544 * 4);
    for (x = 0; x < 128 * 256 * 3; x++) bytes[x] = (unsigned char)((x * 37) % 251);
    for (x = 0; x < 128 * 256 * 3; x++) nbytes[x] = (unsigned char)(x % 3 == 2 ? 230 : 100 + (x * 13) % 56);' \
        'if (rgba[4 * 1000 + 3] != 255 || rgba[4 * 1000 + 2] < 200 || uv[4] <= uv[0]) return 2;
    free(rgba); }
    return 0; }'

    # Lapped textures: a 4x4 grid of squares split in two, a photo, field and UV
    # storage and an atlas; it must cover the mesh, fill the atlas and free
    # everything it made.
    quickstart_check quickstart_lapped "QUICK START: lapped" "Triangles or n-gons?" "covers, bakes and frees" \
        'float xyz[75], field[96], corner_uv[192]; int tris[96], i, j, n = 0;
    tt_mesh_desc desc = {0}; tt_mesh *mesh; tt_error err; tt_image *photo, *atlas;
    for (j = 0; j < 5; j++) for (i = 0; i < 5; i++) { xyz[3*(5*j+i)] = (float)i; xyz[3*(5*j+i)+1] = (float)j; xyz[3*(5*j+i)+2] = 0; }
    for (j = 0; j < 4; j++) for (i = 0; i < 4; i++) { int a = 5*j+i; tris[n++] = a; tris[n++] = a+1; tris[n++] = a+6; tris[n++] = a; tris[n++] = a+6; tris[n++] = a+5; }
    desc.positions = xyz; desc.nverts = 25; desc.indices = tris; desc.nfaces = 32; desc.fixed_face_size = 3;
    if (tt_mesh_build(&desc, NULL, &mesh, &err) != TT_OK) return 3;
    if (tt_image_create(64, 64, NULL, &photo, &err) != TT_OK || tt_image_create(256, 256, NULL, &atlas, &err) != TT_OK) return 3;
    for (i = 0; i < 64 * 64 * 4; i++) photo->pixels[i] = (float)((i * 37) % 101) / 100.0f;
    for (i = 0; i < 64 * 64; i++) photo->pixels[4 * i + 3] = 1.0f;' \
        'if (atlas->pixels[4 * 300 + 3] != 1.0f) return 2;
    }
    tt_mesh_free(mesh); tt_image_free(atlas); tt_image_free(photo); return 0; }'

    # THE API CONTRACT at the top of tiledtex.h, checked on every public
    # declaration (tests/check_api.sh enumerates them): one line each.
    while IFS= read -r line; do
        case "$line" in
        "ok   "*) pass "${line#ok   }" ;;
        "FAIL "*) fail "${line#FAIL }" ;;
        esac
    done < <(bash tests/check_api.sh tiledtex.h)

    # No raw allocation calls, in the code or in the documentation's examples
    # (which users copy): any malloc( free( realloc( calloc( that is not a member
    # call (allocator->free) or part of a longer name, outside the two default
    # macros.
    {
        raw=$(grep -nE '(^|[^A-Za-z0-9_>.])(malloc|free|realloc|calloc)[[:space:]]*\(' tiledtex.h |
            grep -vE '^[0-9]+:[[:space:]]*#[[:space:]]*define[[:space:]]+TT_(MALLOC|FREE)[[:space:]]*\(')
        if [ -z "$raw" ]; then
            pass "source: no raw malloc/free/realloc/calloc outside the TT_MALLOC/TT_FREE defaults"
        else
            fail "source: raw allocation calls in tiledtex.h" "$raw"
        fi
    }
}
# 2. The unit tests: one program with ASan + UBSan, run as two processes at
# once, as the hpm section takes almost as long as all the others together
# (3.5 and 4 CPU minutes). Each part adds its own "N passed, M failed".
UNIT_HEAVY=hpm
stage_unit_build() {
    echo "== unit tests: build (tests/test_*.c, ASan + UBSan)"
    if log=$($CC -std=c99 -g -O1 -fsanitize=address,undefined -fno-sanitize-recover=all -Wall -Wextra -pedantic -I. \
        tests/test_*.c -o "$OUT/unit" -lm 2>&1); then
        [ -n "$log" ] && printf '%s\n' "$log"
        echo "built $OUT/unit"
    else
        fail "unit tests: tests/test_*.c do not build" "$log"
    fi
}
# unit_part NAME WHICH ENV=VALUE: one run of the unit test program.
unit_part() {
    echo "== unit tests: $2"
    if [ -x "$OUT/unit" ]; then
        run_counted "$1" env "$3" "$OUT/unit"
    else
        echo "not run: the unit tests did not build"
    fi
}
stage_unit_heavy() { unit_part unit_heavy "the $UNIT_HEAVY section" TT_TEST_ONLY="$UNIT_HEAVY"; }
stage_unit_rest() { unit_part unit_rest "every other section" TT_TEST_SKIP="$UNIT_HEAVY"; }

# 3. The tool built with ASan + UBSan, for the end-to-end tests, the import
# test and the learner's programs.
SANITIZED_TOOL=build/asan/tiledtex
stage_tool_build() {
    echo "== the tool with ASan + UBSan ($SANITIZED_TOOL)"
    mkdir -p build/asan
    STB_INC=$(pkg-config --cflags stb 2>/dev/null || echo -I/usr/include/stb)
    # shellcheck disable=SC2086  # STB_INC is a list of flags
    if log=$($CC -std=c99 -g -O1 -fsanitize=address,undefined -pthread -I. $STB_INC examples/*.c \
        -o "$SANITIZED_TOOL" -lm 2>&1); then
        echo "built $SANITIZED_TOOL"
    else
        fail "e2e: the tool does not build with sanitizers" "$log"
    fi
}
# tool_stage NAME TITLE SCRIPT: a script that takes the sanitized tool,
# counted; not run (the tool's build has failed already) without it.
tool_stage() {
    echo "== $2"
    if [ -x "$SANITIZED_TOOL" ]; then
        run_counted "$1" bash "$3" "$SANITIZED_TOOL"
    else
        echo "not run: the tool did not build"
    fi
}
stage_e2e() { tool_stage e2e "end-to-end tests (tests/e2e.sh, tool built with ASan + UBSan)" tests/e2e.sh; }

# 4. Other programs open what the tool writes: assimp and Blender, when
# installed (a CI machine without them prints one "skip" line and counts
# nothing). About 30 s with both.
stage_import() {
    tool_stage import "import test (tests/import_check.sh: assimp and Blender open each pipeline's output)" \
        tests/import_check.sh
}

# 5. The learner's programs: each built as examples/learn/README.md says (with
# -Werror), run on inputs the tool generates, and drawn by its render command.
stage_learn() { tool_stage learn "the learner's programs (tests/learn.sh, examples/learn/)" tests/learn.sh; }

# 6. A short smoke run of each libFuzzer target (tests/fuzz/run.sh builds them
# with clang, ASan and UBSan): its seed corpus, then mutations for
# FUZZ_SMOKE_SECONDS (default 8), in a scratch copy so the repository's seeds
# stay as they are. `make fuzz` runs them for longer. Without clang's
# libFuzzer (run.sh installs it when root) each is skipped, saying why.
# FUZZ_SMOKE=0 skips them (building the targets takes a few minutes).
# fuzz_image runs its seeds only: mutating JPEGs finds, within minutes, reads
# out of bounds inside Debian's stb_image (2.27: a Huffman symbol index gone
# negative in its decoder, checked upstream from 2.28 on) that the tool
# cannot check for before decoding. `make fuzz` mutates it too.
stage_fuzz() {
    local seeds_only=" image " fuzz_targets t scratch dict runs log execs deep
    echo "== fuzz smoke runs (tests/fuzz, clang libFuzzer + ASan + UBSan)"
    if [ "${FUZZ_SMOKE:-1}" = 0 ]; then
        echo "skip fuzz smoke runs: FUZZ_SMOKE=0"
        return
    fi
    # The targets build one at a time here: the other stages use the other cores.
    if ! fuzz_targets=$(FUZZ_JOBS=1 FUZZ_BUILD_ONLY=1 bash tests/fuzz/run.sh 2>"$OUT/fuzz_build.log"); then
        if [ "$?" = 2 ]; then
            echo "skip fuzz smoke runs: $(tail -n 1 "$OUT/fuzz_build.log")"
        else
            fail "fuzz smoke: a target does not build" "$(grep -E 'error|does not build' "$OUT/fuzz_build.log" | head -n 8)"
        fi
        return
    fi
    for t in $fuzz_targets; do
        scratch=$(mktemp -d)
        cp tests/fuzz/corpus_"$t"/* "$scratch"/ 2>/dev/null
        dict=()
        [ -f tests/fuzz/"$t".dict ] && dict=("-dict=tests/fuzz/$t.dict")
        runs=()
        [[ "$seeds_only" == *" $t "* ]] && runs=(-runs=0)
        if log=$(build/fuzz/fuzz_"$t" "${runs[@]}" -max_total_time="${FUZZ_SMOKE_SECONDS:-8}" -seed=1 -max_len=4096 -timeout=20 \
            -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="build/fuzz/smoke_$t-" "${dict[@]}" "$scratch" 2>&1); then
            execs=$(printf '%s\n' "$log" | sed -n 's/^stat::number_of_executed_units: *//p' | tail -1)
            deep=$(printf '%s\n' "$log" | grep -o '[0-9]* of [0-9]* runs ([0-9.]* %) reached .*' | tail -1)
            if [ ${#runs[@]} -gt 0 ]; then
                pass "fuzz smoke: fuzz_$t, its seeds (${execs:-?} runs)"
            else
                pass "fuzz smoke: fuzz_$t, seeds and ${execs:-?} runs in ${FUZZ_SMOKE_SECONDS:-8} s${deep:+; $deep}"
            fi
        else
            fail "fuzz smoke: fuzz_$t found a problem (input saved as build/fuzz/smoke_$t-*)" \
                "$(printf '%s\n' "$log" | grep -E 'contract broken|ERROR: |runtime error|Test unit written' | head -n 6)"
        fi
        rm -rf "$scratch"
    done
}

# The stages run TEST_JOBS at a time (default: the number of cores), each in
# the background with its output in build/tests/stage_NAME.out and its counts
# in stage_NAME.count (written last: the stage is done). A stage starts when a
# slot is free and the stage it needs is done, in the order below (the
# longest first, so that the two cores end together); the report prints each
# stage's output in this order as soon as it and those before it are done.
# TEST_JOBS=1 runs them one after the other.
STAGES=(unit_build tool_build unit_heavy e2e unit_rest fuzz compile import learn)
declare -A NEEDS=([unit_heavy]=unit_build [unit_rest]=unit_build [e2e]=tool_build [import]=tool_build
    [learn]=tool_build)
jobs_max=${TEST_JOBS:-$(nproc 2>/dev/null || echo 2)}
[ "$jobs_max" -ge 1 ] 2>/dev/null || jobs_max=2
# A binary left by an earlier run must not stand in for one that fails to build.
rm -f "$OUT/unit" "$SANITIZED_TOOL" "$OUT"/stage_*.count "$OUT"/stage_*.out
echo "== ${#STAGES[@]} stages, $jobs_max at a time: ${STAGES[*]}"

stage_done() { [ -f "$OUT/stage_$1.count" ]; }
start_stage() {
    # shellcheck disable=SC2030,SC2031  # each stage counts in its own subshell
    (
        PASSED=0
        FAILED=0
        "stage_$1" >"$OUT/stage_$1.out" 2>&1 </dev/null
        echo "$PASSED $FAILED" >"$OUT/stage_$1.count"
    ) &
}
declare -A STARTED=()
printed=0
while [ "$printed" -lt "${#STAGES[@]}" ]; do
    running=$(jobs -rp | wc -l)
    for s in "${STAGES[@]}"; do
        [ "$running" -lt "$jobs_max" ] || break
        [ -z "${STARTED[$s]:-}" ] || continue
        need=${NEEDS[$s]:-}
        if [ -z "$need" ] || stage_done "$need"; then
            STARTED[$s]=1
            start_stage "$s"
            running=$((running + 1))
        fi
    done
    while [ "$printed" -lt "${#STAGES[@]}" ] && stage_done "${STAGES[$printed]}"; do
        s=${STAGES[$printed]}
        cat "$OUT/stage_$s.out"
        read -r p m <"$OUT/stage_$s.count"
        # shellcheck disable=SC2031  # the stages' counts, added here
        PASSED=$((PASSED + p))
        # shellcheck disable=SC2031
        FAILED=$((FAILED + m))
        printed=$((printed + 1))
    done
    [ "$printed" -lt "${#STAGES[@]}" ] && { wait -n 2>/dev/null || sleep 1; }
done

echo "== done in $(($(date +%s) - START)) s"
echo "$PASSED passed, $FAILED failed"
[ "$FAILED" -eq 0 ]
