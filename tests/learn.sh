#!/usr/bin/env bash
# tests/learn.sh TOOL - the learner's programs, examples/learn/*.c (`make learn`;
# `make test` counts it). For each program, one test:
#   - examples/learn/README.md and the program's first comment give its
#     compile command, exactly the one below, and it builds with that command plus -Werror (no warnings);
#   - it is at most 150 lines;
#   - it prints its usage and exits 2 without arguments, and exits 1 with a
#     message for a photo that does not exist;
#   - run on a mesh and photo TOOL generates, it exits 0, prints one line,
#     and writes an OBJ with texture coordinates, its MTL and a PNG;
#   - `TOOL render` draws that OBJ with that PNG (build/learn/NAME_view.png).
# The last line is "N passed, M failed".
set -u
cd "$(dirname "$0")/.." || { echo "0 passed, 1 failed"; exit 1; }
TOOL=${1:-build/tiledtex}
OUT=build/learn
FLAGS="-std=c99 -O1 -Wall -Wextra -pedantic -I."
PROGRAMS="tile lapped hpm polycube"
PASSED=0
FAILED=0
pass() { PASSED=$((PASSED + 1)); echo "ok   $1"; }
fail() {
    FAILED=$((FAILED + 1))
    echo "FAIL $1"
    if [ -n "${2:-}" ]; then printf '%s\n' "$2" | head -n 15 | sed 's/^/     | /'; fi
}
finish() { echo "$PASSED passed, $FAILED failed"; [ "$FAILED" -eq 0 ]; exit; }

mkdir -p "$OUT" || { fail "learn: cannot make $OUT"; finish; }
if ! log=$("$TOOL" -q generate mesh "$OUT/torus.obj" --shape torus 2>&1 &&
    "$TOOL" -q generate mesh "$OUT/sphere.obj" --shape sphere 2>&1 &&
    "$TOOL" -q generate mesh "$OUT/double-torus.obj" --shape double-torus 2>&1 &&
    "$TOOL" -q generate texture "$OUT/photo.png" --size 256 2>&1); then
    fail "learn: $TOOL generate cannot make the inputs" "$log"
    finish
fi

# The builds take most of the time (the whole library in each program):
# two at a time.
for p in $PROGRAMS; do
    while [ "$(jobs -r | wc -l)" -ge 2 ]; do wait -n; done
    # shellcheck disable=SC2086  # FLAGS is a list of flags
    (cc $FLAGS -Werror "examples/learn/$p.c" -o "$OUT/learn_$p" -lm >"$OUT/$p.build.log" 2>&1
        echo $? >"$OUT/$p.build.status") &
done
wait

mesh_of() {
    case $1 in
    tile | hpm) echo torus ;;       # a quad mesh: tile uses it as it is, hpm splits it into triangles
    lapped) echo sphere ;;          # triangles
    polycube) echo double-torus ;;  # genus 2, so the polycube needs its two holes
    esac
}

for p in $PROGRAMS; do
    name="learn: examples/learn/$p.c"
    command="cc $FLAGS examples/learn/$p.c -o learn_$p -lm"
    lines=$(wc -l <"examples/learn/$p.c")
    prefix=$OUT/$p
    rm -f "$prefix.obj" "$prefix.mtl" "$prefix.png" "${prefix}_view.png"
    if ! grep -qF -- "$command" examples/learn/README.md || ! grep -qF -- "$command" "examples/learn/$p.c"; then
        fail "$name: examples/learn/README.md or the program's own comment does not give its compile command: $command"
    elif [ "$(cat "$OUT/$p.build.status")" != 0 ] || [ -s "$OUT/$p.build.log" ]; then
        fail "$name does not build warning-free with: $command -Werror" "$(cat "$OUT/$p.build.log")"
    elif [ "$lines" -gt 150 ]; then
        fail "$name has $lines lines, more than 150"
    elif "$OUT/learn_$p" >/dev/null 2>"$OUT/$p.usage.log" || [ $? != 2 ] || ! grep -q usage "$OUT/$p.usage.log"; then
        fail "$name: without arguments it does not print its usage and exit 2" "$(cat "$OUT/$p.usage.log")"
    elif log=$("$OUT/learn_$p" "$OUT/torus.obj" "$OUT/no-such-photo.png" "$prefix" 2>&1) || [ -z "$log" ]; then
        fail "$name: a photo that does not exist is not an error with a message" "$log"
    elif ! log=$("$OUT/learn_$p" "$OUT/$(mesh_of "$p").obj" "$OUT/photo.png" "$prefix" 2>&1); then
        fail "$name: the run failed" "$log"
    elif [ "$(printf '%s\n' "$log" | wc -l)" != 1 ]; then
        fail "$name: the run printed more than its summary line" "$log"
    elif ! grep -q '^vt ' "$prefix.obj" || ! grep -q '^f ' "$prefix.obj" || ! grep -q '^map_Kd' "$prefix.mtl"; then
        fail "$name: $prefix.obj has no texture coordinates or faces, or $prefix.mtl no map_Kd"
    elif [ "$(head -c 4 "$prefix.png" | od -An -tx1 | tr -d ' \n')" != 89504e47 ]; then
        fail "$name: $prefix.png is not a PNG"
    elif ! render=$("$TOOL" -q render "$prefix.obj" "$prefix.png" "${prefix}_view.png" --size 400x300 2>&1) ||
        [ ! -s "${prefix}_view.png" ]; then
        fail "$name: $TOOL render does not draw $prefix.obj" "$render"
    else
        pass "$name ($lines lines) builds warning-free with README.md's command and textures $(mesh_of "$p").obj: $log"
    fi
done
finish
