#!/usr/bin/env bash
# tests/e2e.sh - end-to-end tests of the `tiledtex` command-line tool.
#
#   bash tests/e2e.sh TOOL        (e.g. build/asan/tiledtex)
#
# Runs the tool on generated and hand-written inputs in a temporary directory
# (removed at the end). Prints one line per failed check and, as its last
# line, "N passed, M failed"; exits non-zero when M > 0. Any AddressSanitizer /
# UndefinedBehaviorSanitizer report on stderr is a failure.
set -u

if [ $# -ne 1 ] || [ -z "$1" ]; then
    echo "usage: bash tests/e2e.sh TOOL" >&2
    echo "0 passed, 1 failed"
    exit 2
fi
TOOL=$1
# the repository (test helpers compile examples/ sources)
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
case $TOOL in
    */*) TOOL=$(cd "$(dirname "$TOOL")" 2>/dev/null && pwd)/$(basename "$TOOL") ;;
    *) TOOL=$(command -v "$TOOL" || echo "$TOOL") ;;
esac
if [ ! -x "$TOOL" ]; then
    echo "FAIL tool | cmd: test -x $1 | expected: an executable | got: not found / not executable"
    echo "0 passed, 1 failed"
    exit 1
fi

W=$(mktemp -d "${TMPDIR:-/tmp}/tiledtex-e2e.XXXXXX") || exit 1
trap 'cd /; rm -rf "$W"' EXIT
export LC_ALL=C
# Make sure a sanitizer finding is printed (the caller may add more options).
export UBSAN_OPTIONS="print_stacktrace=1${UBSAN_OPTIONS:+:$UBSAN_OPTIONS}"

PASS=0
FAIL=0
RUNS=0
SANITIZER_REPORTS=0

# One line: newlines shown as '\n', cut to a readable length.
oneline() {
    local s
    s=$(printf '%s' "$1" | tr -d '\r' | awk 'BEGIN{ORS="\\n"} {print}' | sed 's/\\n$//')
    if [ ${#s} -gt 400 ]; then s="${s:0:400}..."; fi
    printf '%s' "$s"
}

pass() { PASS=$((PASS + 1)); }
# fail WHAT COMMAND EXPECTED GOT
fail() {
    FAIL=$((FAIL + 1))
    printf 'FAIL %s | cmd: %s | expected: %s | got: %s\n' "$1" "$2" "$3" "$(oneline "$4")"
}
# check WHAT EXPECTED GOT CONDITION-STATUS (0 = ok); command is $CMD
check() {
    if [ "$4" = 0 ]; then pass; else fail "$1" "$CMD" "$2" "$3"; fi
}

# run ARGS... : runs the tool in the current directory with stdout/stderr in
# $W/out and $W/err; sets RC, CMD, OUT, ERR. A sanitizer report is a failure.
run() {
    CMD="tiledtex $*"
    RUNS=$((RUNS + 1))
    timeout 60 "$TOOL" "$@" >"$W/out" 2>"$W/err" </dev/null
    RC=$?
    OUT=$(tr -d '\000' <"$W/out")   # binary output ("-") holds NUL bytes
    ERR=$(cat "$W/err")
    if grep -qE 'ERROR: (AddressSanitizer|LeakSanitizer)|runtime error:|SUMMARY: [A-Za-z]*Sanitizer' "$W/err"; then
        SANITIZER_REPORTS=$((SANITIZER_REPORTS + 1))
        fail "sanitizer report" "$CMD (in $(basename "$PWD"))" "no ASan/UBSan report" \
            "$(grep -m3 -E 'ERROR: |runtime error:|SUMMARY:|#[0-3] ' "$W/err")"
    fi
    if [ $RC -eq 124 ]; then
        fail "timeout" "$CMD" "finishes within 60 s" "killed after 60 s"
    fi
}

# expect_ok WHAT ARGS... : exit status 0 (one counted check)
expect_ok() {
    local what=$1
    shift
    run "$@"
    check "$what: exit status" "0" "exit $RC, stderr: $ERR" "$([ $RC -eq 0 ]; echo $?)"
}

# A fresh, empty directory under $W; cd's into it. Inputs are in ../in.
NEWDIR_N=0
newdir() {
    NEWDIR_N=$((NEWDIR_N + 1))
    mkdir -p "$W/d$NEWDIR_N" && cd "$W/d$NEWDIR_N" || exit 1
}

# expect_error WHAT ARGS... : in a fresh empty directory, the tool must fail
# with a non-zero status, exactly one stderr line starting with "tiledtex",
# and leave no file behind. Three counted checks. $ERR holds the message.
expect_error() {
    local what=$1 left
    shift
    newdir
    run "$@"
    check "$what: exit status" "non-zero (not a crash)" "exit $RC" \
        "$([ $RC -ne 0 ] && [ $RC -lt 124 ]; echo $?)"
    check "$what: stderr" "exactly one line starting with 'tiledtex'" \
        "$(wc -l <"$W/err") line(s): $ERR" \
        "$([ "$(wc -l <"$W/err")" -eq 1 ] && head -c 8 "$W/err" | grep -qx 'tiledtex'; echo $?)"
    left=$(ls -A)
    check "$what: no output left" "empty directory" "files: $left" "$([ -z "$left" ]; echo $?)"
    cd "$W" || exit 1
}

# stderr of the last run contains a pattern (extended regex, case-insensitive)
err_mentions() {
    check "$1" "stderr matching /$2/" "$ERR" "$(printf '%s' "$ERR" | grep -qiE "$2"; echo $?)"
}

# png_size FILE -> "W H" (from the IHDR chunk, bytes 16-23)
png_size() {
    od -An -tu1 -j16 -N8 "$1" 2>/dev/null |
        awk 'NF == 8 { printf "%d %d", (($1*256+$2)*256+$3)*256+$4, (($5*256+$6)*256+$7)*256+$8 }'
}
is_png() {
    [ "$(od -An -tx1 -N8 "$1" 2>/dev/null | tr -d ' \n')" = "89504e470d0a1a0a" ]
}

# obj_report FILE -> "corners vts nonquads badcorners baduv faces"
#   corners: corners on f lines; vts: vt lines; nonquads: f lines without 4
#   corners; badcorners: corners whose vertex or vt index is missing or out of
#   range; baduv: vt values that are not numbers in [0,1].
obj_report() {
    awk '
        function isnum(s) { return s ~ /^[-+]?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][-+]?[0-9]+)?$/ }
        $1 == "v"  { nv++ }
        $1 == "vt" { nvt++
                     for (i = 2; i <= 3; i++)
                         if (!isnum($i) || $i + 0 < 0 || $i + 0 > 1) baduv++ }
        $1 == "f"  { nf++
                     if (NF - 1 != 4) nonquad++
                     for (i = 2; i <= NF; i++) { corners++; c[corners] = $i } }
        END {
            for (k = 1; k <= corners; k++) {
                n = split(c[k], p, "/")
                if (n < 2 || p[1] !~ /^[0-9]+$/ || p[2] !~ /^[0-9]+$/ ||
                    p[1] + 0 < 1 || p[1] + 0 > nv || p[2] + 0 < 1 || p[2] + 0 > nvt) badc++
            }
            printf "%d %d %d %d %d %d\n", corners, nvt, nonquad, badc, baduv, nf
        }' "$1" 2>/dev/null
}

# normals_report FILE: "corners vn bad creased": face corners, vn lines, corners
# without a vn index in range or with a vn not of unit length, and vertices
# whose corners carry more than one normal (a crease: 0 on a smooth surface)
normals_report() {
    awk '
        $1 == "vn" { nvn++; x[nvn] = $2; y[nvn] = $3; z[nvn] = $4 }
        $1 == "f"  { for (i = 2; i <= NF; i++) { corners++; c[corners] = $i } }
        END {
            for (k = 1; k <= corners; k++) {
                n = split(c[k], p, "/")
                if (n < 3 || p[3] !~ /^[0-9]+$/ || p[3] + 0 < 1 || p[3] + 0 > nvn) { bad++; continue }
                q = p[3] + 0
                len = x[q] * x[q] + y[q] * y[q] + z[q] * z[q]
                if (len < 0.998 || len > 1.002) bad++
                key = sprintf("%.3f %.3f %.3f", x[q], y[q], z[q])
                if (!(p[1] in first)) first[p[1]] = key
                else if (first[p[1]] != key && !(p[1] in creased)) { creased[p[1]] = 1; ncreased++ }
            }
            printf "%d %d %d %d\n", corners, nvn, bad, ncreased
        }' "$1" 2>/dev/null
}

# check_normals WHAT FILE: a unit vn for every face corner (1 check); the
# corners may share vn lines (tile and map write each distinct one once)
check_normals() {
    local corners nvn bad creased
    read -r corners nvn bad creased <<<"$(normals_report "$2")"
    check "$1: a unit normal (vn) at every face corner" "every corner's vn index in range, of unit length" \
        "$nvn vn, $corners corners, $bad bad" \
        "$([ "${corners:-0}" -gt 0 ] && [ "${nvn:-0}" -gt 0 ] && [ "${nvn:-0}" -le "${corners:-0}" ] &&
            [ "${bad:-1}" = 0 ]; echo $?)"
}

# check_obj WHAT FILE : a vt at every corner, all quads, UVs in [0,1] (4 checks)
check_obj() {
    local r corners nvt nonquad badc baduv nf
    r=$(obj_report "$2")
    read -r corners nvt nonquad badc baduv nf <<<"$r"
    check "$1: OBJ has faces" "> 0 f lines" "$nf" "$([ "${nf:-0}" -gt 0 ]; echo $?)"
    check "$1: a vt at every face corner" "every corner v/vt with indices in range, vt lines <= corners" \
        "$nvt vt lines, $corners corners, $badc bad corners" \
        "$([ "${nvt:-0}" -gt 0 ] && [ "${nvt:-0}" -le "${corners:-0}" ] && [ "${badc:-1}" -eq 0 ]; echo $?)"
    check "$1: all faces quads" "0 non-quad f lines" "$nonquad" "$([ "${nonquad:-1}" -eq 0 ]; echo $?)"
    check "$1: UVs in [0,1]" "0 bad vt values" "$baduv" "$([ "${baduv:-1}" -eq 0 ]; echo $?)"
}

# numbers from the summary line(s) on stdout ($OUT)
summary_genus() { printf '%s\n' "$OUT" | grep -oE 'genus -?[0-9]+' | head -1 | awk '{print $2}'; }
summary_seam() { printf '%s\n' "$OUT" | grep -oE 'seam score -?[0-9.]+([eE][-+]?[0-9]+)?' | head -1 | awk '{print $3}'; }

nonempty() { [ -s "$1" ]; }

# test helpers (small C programs) are compiled with these
HELPER_CC=${CC:-cc}
STB_INC=$(pkg-config --cflags stb 2>/dev/null || echo -I/usr/include/stb)

# ======================================================================
# Inputs
# ======================================================================
mkdir -p "$W/in"
cd "$W/in" || exit 1

# --help everywhere
for sub in synth map tile lapped hpm polycube render generate; do
    run $sub --help
    check "$sub --help" "exit 0 and usage on stdout" "exit $RC, stdout ${#OUT} bytes, stderr: $ERR" \
        "$([ $RC -eq 0 ] && [ -n "$OUT" ]; echo $?)"
done
# the commands that read a mesh say which formats MESH may be (not MESH.obj)
for sub in map tile lapped hpm polycube render; do
    run help $sub
    check "help $sub: MESH is OBJ, STL or OFF" "'usage: tiledtex $sub MESH ', the three formats, no 'MESH.obj'" \
        "$(printf '%s\n' "$OUT" | grep -E 'usage|MESH' | head -3)" \
        "$(printf '%s' "$OUT" | grep -q "^usage: tiledtex $sub MESH " &&
            printf '%s' "$OUT" | grep -q 'MESH is a Wavefront OBJ, an STL (ASCII or binary) or an OFF file' &&
            ! printf '%s' "$OUT" | grep -q 'MESH\.obj'; echo $?)"
done
run tile
check "tile without arguments: the usage error names MESH, not MESH.obj" "'needs MESH, IMAGE and OUT_PREFIX'" "$ERR" \
    "$(printf '%s' "$ERR" | grep -q 'needs MESH, IMAGE and OUT_PREFIX'; echo $?)"
run --help
check "--help" "exit 0 and usage on stdout" "exit $RC, stdout ${#OUT} bytes" "$([ $RC -eq 0 ] && [ -n "$OUT" ]; echo $?)"
run help tile
check "help tile" "exit 0 and usage on stdout" "exit $RC, stdout ${#OUT} bytes" "$([ $RC -eq 0 ] && [ -n "$OUT" ]; echo $?)"

expect_ok "generate texture" generate texture tex.png --size 256 --seed 3
check "generate texture: 256x256 PNG" "256 256" "$(png_size tex.png)" "$([ "$(png_size tex.png)" = "256 256" ]; echo $?)"
expect_ok "generate small texture" generate texture small.png --size 64
for shape in double-torus torus sphere grid pair genus3; do
    expect_ok "generate mesh $shape" generate mesh $shape.obj --shape $shape
    check "generate mesh $shape: non-empty" "non-empty $shape.obj" "$(ls -l $shape.obj 2>&1)" "$(nonempty $shape.obj; echo $?)"
done
expect_ok "generate mesh sphere --triangles" generate mesh spheretri.obj --shape sphere --triangles
check "generate mesh: a normal per face corner" "every f corner v//vn, vn lines" \
    "$(grep -c '^vn' spheretri.obj) vn; $(grep -m1 '^f' spheretri.obj)" \
    "$(awk '$1 == "vn" { n++ } $1 == "f" { for (i = 2; i <= NF; i++) if ($i !~ /^[0-9]+\/\/[0-9]+$/) bad++ }
        END { exit !(n > 0 && bad == 0) }' spheretri.obj; echo $?)"
check "generate --triangles: all triangles" "only 3-corner faces" \
    "$(awk '$1=="f"{n[NF-1]++} END{for(k in n) printf "%d-gons:%d ", k, n[k]}' spheretri.obj 2>/dev/null)" \
    "$(awk '$1=="f"{f++; if (NF!=4) bad++} END{exit !(f>0 && bad==0)}' spheretri.obj 2>/dev/null; echo $?)"
cd "$W" || exit 1

# ======================================================================
# Happy paths: tile on generated meshes
# ======================================================================
# tile_case NAME MESH GENUS EXTRA-ARGS...
tile_case() {
    local name=$1 mesh=$2 genus=$3 g
    shift 3
    newdir
    run tile "../in/$mesh" ../in/tex.png out "$@"
    check "tile $name: exit status" "0" "exit $RC, stderr: $ERR" "$([ $RC -eq 0 ]; echo $?)"
    check "tile $name: outputs non-empty" "out.obj out.mtl out.png non-empty" "$(ls -l 2>&1)" \
        "$(nonempty out.obj && nonempty out.mtl && nonempty out.png; echo $?)"
    check "tile $name: atlas is a PNG" "PNG signature" "$(od -An -tx1 -N8 out.png 2>&1)" "$(is_png out.png; echo $?)"
    check_normals "tile $name" out.obj
    check "tile $name: mtl names the atlas" "map_Kd out.png in out.mtl, mtllib out.mtl in out.obj" \
        "$(grep -h -E 'map_Kd|mtllib' out.mtl out.obj 2>&1)" \
        "$(grep -qE '^map_Kd +out\.png' out.mtl 2>/dev/null && grep -qE '^mtllib +out\.mtl' out.obj 2>/dev/null; echo $?)"
    check "tile $name: exactly out.obj, out.mtl, out.png written (no temporaries)" "out.mtl out.obj out.png" \
        "$(ls -A | tr '\n' ' ')" "$([ "$(ls -A | tr '\n' ' ')" = "out.mtl out.obj out.png " ]; echo $?)"
    [ -f out.obj ] && check_obj "tile $name" out.obj
    check "tile $name: each distinct vt and vn written once" "no vt line and no vn line twice" \
        "$(grep -E '^v[tn] ' out.obj | sort | uniq -d | head -2)" \
        "$([ -s out.obj ] && [ -z "$(grep -E '^v[tn] ' out.obj | sort | uniq -d)" ]; echo $?)"
    if [ "$genus" != - ]; then
        g=$(summary_genus)
        check "tile $name: summary genus" "genus $genus" "$OUT" "$([ "$g" = "$genus" ]; echo $?)"
    fi
    cd "$W" || exit 1
}

tile_case double-torus double-torus.obj 2
check "tile double-torus (quads): no advice for triangle meshes" "no 'tiledtex hpm' in stderr" "$ERR" \
    "$(! printf '%s' "$ERR" | grep -q "tiledtex hpm"; echo $?)"
tile_case sphere-triangles spheretri.obj 0
check "tile sphere-triangles: says it quadrangulated" "stderr mentions quadrangulat" "$ERR" \
    "$(printf '%s' "$ERR" | grep -qi quadrangulat; echo $?)"
check "tile sphere-triangles (1280): points to the tools for dense triangle meshes" \
    "one line naming 'tiledtex polycube', 'tiledtex hpm' and 'tiledtex lapped'" "$ERR" \
    "$(printf '%s' "$ERR" | grep -c "'tiledtex polycube', 'tiledtex hpm' or 'tiledtex lapped'" | grep -qx 1; echo $?)"
read -r corners nvn bad creased <<<"$(normals_report "$W/d$NEWDIR_N/out.obj")"
check "tile sphere-triangles: smooth normals (every vertex one normal)" "0 creased vertices" \
    "$creased creased vertices of $corners corners" "$([ "${creased:-1}" = 0 ] && [ "${corners:-0}" -gt 0 ]; echo $?)"
newdir
printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\nf 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n' > cube.obj
expect_ok "tile a cube" tile cube.obj ../in/tex.png out
read -r corners nvn bad creased <<<"$(normals_report out.obj)"
check "tile a cube: its edges stay sharp (each of its 8 vertices has a normal per face)" \
    "8 creased vertices, unit normals" "$creased creased vertices, $bad bad of $corners corners" \
    "$([ "${creased:-0}" = 8 ] && [ "${bad:-1}" = 0 ]; echo $?)"
cd "$W" || exit 1
tile_case grid grid.obj -
check "tile grid: one boundary loop" "'1 boundary loop' in summary" "$OUT" \
    "$(printf '%s' "$OUT" | grep -qE '(^|[^0-9])1 boundary loop'; echo $?)"
tile_case pair pair.obj -
check "tile pair: two components" "'2 components' in summary" "$OUT" \
    "$(printf '%s' "$OUT" | grep -qE '(^|[^0-9])2 components'; echo $?)"
tile_case genus3 genus3.obj 3
tile_case torus-n1 torus.obj 1
s=$(summary_seam)
check "tile torus n=1: seam score <= 0.05" "seam score <= 0.05" "$OUT" \
    "$(awk -v s="${s:-x}" 'BEGIN{exit !(s ~ /^-?[0-9.]+/ && s + 0 <= 0.05)}'; echo $?)"
# tex.png is 256x256: without --tile, tile picks 96-texel tiles (2/5 of 256, a multiple of 8)
check "tile torus n=1: atlas size" "416 416 (4 x (96+2*4))" "$(png_size "$W/d$NEWDIR_N/out.png")" \
    "$([ "$(png_size "$W/d$NEWDIR_N/out.png")" = "416 416" ]; echo $?)"
tile_case torus-n2 torus.obj 1 --colors 2 --tile 32
s=$(summary_seam)
check "tile torus --colors 2 --tile 32: seam score <= 0.05" "seam score <= 0.05" "$OUT" \
    "$(awk -v s="${s:-x}" 'BEGIN{exit !(s ~ /^-?[0-9.]+/ && s + 0 <= 0.05)}'; echo $?)"
s=$(printf '%s' "$OUT" | sed -n "s/.*; near the tiles' corners (within 5 % of an edge's ends) \(-\{0,1\}[0-9.]*\) (.*/\1/p")
check "tile torus --colors 2 --tile 32: seam score near the tiles' corners <= 0.1" \
    "'near the tiles' corners (within 5 % of an edge's ends) X (...)', X <= 0.1" "$OUT" \
    "$(awk -v s="${s:-x}" 'BEGIN{exit !(s ~ /^-?[0-9.]+$/ && s + 0 <= 0.1)}'; echo $?)"
check "tile torus n=2: atlas size" "640 640 (16 x (32+2*4))" "$(png_size "$W/d$NEWDIR_N/out.png")" \
    "$([ "$(png_size "$W/d$NEWDIR_N/out.png")" = "640 640" ]; echo $?)"

# ----------------------------------------------------------------------
# Determinism and seeds
# ----------------------------------------------------------------------
TARGS=(--colors 2 --tile 32 --gutter 2 --seed 7)
mkdir -p "$W/det1" "$W/det2" "$W/det3"
cd "$W/det1" && expect_ok "tile seed 7 (1st)" tile ../in/double-torus.obj ../in/tex.png out "${TARGS[@]}"
cd "$W/det2" && expect_ok "tile seed 7 (2nd)" tile ../in/double-torus.obj ../in/tex.png out "${TARGS[@]}"
CMD="tiledtex tile ../in/double-torus.obj ../in/tex.png out ${TARGS[*]} (twice)"
check "same seed twice: identical .obj" "cmp equal" "$(cmp "$W/det1/out.obj" "$W/det2/out.obj" 2>&1)" \
    "$(cmp -s "$W/det1/out.obj" "$W/det2/out.obj"; echo $?)"
check "same seed twice: identical .png" "cmp equal" "$(cmp "$W/det1/out.png" "$W/det2/out.png" 2>&1)" \
    "$(cmp -s "$W/det1/out.png" "$W/det2/out.png"; echo $?)"
cd "$W/det3" && expect_ok "tile seed 8" tile ../in/double-torus.obj ../in/tex.png out --colors 2 --tile 32 --gutter 2 --seed 8
CMD="tiledtex tile ../in/double-torus.obj ../in/tex.png out --colors 2 --tile 32 --gutter 2 --seed 7 / --seed 8"
check "different seed: different .obj" "files differ" "identical" \
    "$(! cmp -s "$W/det1/out.obj" "$W/det3/out.obj"; echo $?)"
check "different seed: different .png" "files differ" "identical" \
    "$(! cmp -s "$W/det1/out.png" "$W/det3/out.png"; echo $?)"

# map + synth separately == tile (same --colors/--tile/--gutter/--seed)
cd "$W/det1" || exit 1
expect_ok "map seed 7" map ../in/double-torus.obj m.obj "${TARGS[@]}"
check "map: one-line summary on stdout" "1 line with quads, genus, valence" "$OUT" \
    "$([ "$(printf '%s\n' "$OUT" | wc -l)" -eq 1 ] && printf '%s' "$OUT" | grep -q 'quads.*genus.*valence'; echo $?)"
check "map without --atlas: no seam score, no .mtl" "no 'seam score', no m.mtl" "$OUT / $(ls)" \
    "$([ -z "$(summary_seam)" ] && [ ! -e m.mtl ]; echo $?)"
expect_ok "synth seed 7" synth ../in/tex.png a.png "${TARGS[@]}"
CMD="tiledtex map ../in/double-torus.obj m.obj ${TARGS[*]} vs tile ... ${TARGS[*]}"
check "map's vt lines = tile's vt lines" "identical vt lines" \
    "$(diff <(grep '^vt' m.obj 2>&1) <(grep '^vt' out.obj 2>/dev/null) 2>&1 | head -4)" \
    "$([ -s m.obj ] && diff -q <(grep '^vt' m.obj 2>/dev/null) <(grep '^vt' out.obj 2>/dev/null) >/dev/null; echo $?)"
check "map's f lines = tile's f lines" "identical f lines" \
    "$(diff <(grep '^f' m.obj 2>&1) <(grep '^f' out.obj 2>/dev/null) 2>&1 | head -4)" \
    "$([ -s m.obj ] && diff -q <(grep '^f' m.obj 2>/dev/null) <(grep '^f' out.obj 2>/dev/null) >/dev/null; echo $?)"
CMD="tiledtex synth ../in/tex.png a.png ${TARGS[*]} vs tile ... ${TARGS[*]}"
check "synth's atlas = tile's atlas" "cmp equal" "$(cmp a.png out.png 2>&1)" "$(cmp -s a.png out.png; echo $?)"

# map --atlas: seam score + .mtl
expect_ok "map --atlas" map ../in/double-torus.obj ma.obj "${TARGS[@]}" --atlas a.png
check "map --atlas: seam score printed" "'seam score X' on stdout" "$OUT" \
    "$([ -n "$(summary_seam)" ]; echo $?)"
check "map --atlas: writes ma.mtl naming a.png" "ma.mtl with map_Kd a.png; mtllib ma.mtl in ma.obj" \
    "$(cat ma.mtl 2>&1; grep mtllib ma.obj 2>&1)" \
    "$(grep -qE '^map_Kd +a\.png' ma.mtl 2>/dev/null && grep -qE '^mtllib +ma\.mtl' ma.obj 2>/dev/null; echo $?)"
s=$(summary_seam)
check "map --atlas: seam score <= 0.05 with matching atlas" "seam score <= 0.05" "$OUT" \
    "$(awk -v s="${s:-x}" 'BEGIN{exit !(s ~ /^-?[0-9.]+/ && s + 0 <= 0.05)}'; echo $?)"
check "map --atlas: same UVs as tile" "identical vt lines" "differ" \
    "$([ -s ma.obj ] && diff -q <(grep '^vt' ma.obj 2>/dev/null) <(grep '^vt' out.obj 2>/dev/null) >/dev/null; echo $?)"
# no --tile: the tile size is read off the atlas (640 = 16 x (32 + 2*4))
newdir
expect_ok "map --atlas without --tile" map ../in/torus.obj m.obj --colors 2 --atlas ../det1/a.png --gutter 2 --seed 7
check "map --atlas without --tile: tile size from atlas" "summary says 32 texels" "$OUT" \
    "$(printf '%s' "$OUT" | grep -qE '(^|[^0-9])32 texels'; echo $?)"
cd "$W" || exit 1
# wrong-size atlas with an explicit --tile fails cleanly
expect_error "map --atlas wrong size" map ../in/torus.obj m.obj --colors 2 --tile 64 --gutter 2 --atlas ../det1/a.png
err_mentions "map --atlas wrong size: message names the size" '[0-9]+ ?x ?[0-9]+|size'

# more options that must work
newdir
expect_ok "synth --colors 2 with two --edge" synth ../in/tex.png a.png --colors 2 --tile 32 --edge 0,0 --edge 100,120
check "synth two --edge: atlas 640x640" "640 640" "$(png_size a.png)" "$([ "$(png_size a.png)" = "640 640" ]; echo $?)"
expect_ok "synth --background" synth ../in/tex.png b.png --tile 32 --background 10,10,100,100 --gutter 0
check "synth --gutter 0: atlas 128x128" "128 128" "$(png_size b.png)" "$([ "$(png_size b.png)" = "128 128" ]; echo $?)"
expect_ok "synth --seed=5 (--opt=value form)" synth ../in/tex.png c.png --tile=32 --seed=5
expect_ok "map --subdivide 1" map ../in/torus.obj s.obj --subdivide 1
check "map --subdivide 1: 4x the quads" "2048 quads (512 x 4)" "$OUT" "$(printf '%s' "$OUT" | grep -qE '(^|[^0-9])2048 quads'; echo $?)"
[ -s s.obj ] && check_obj "map --subdivide 1" s.obj
cd "$W" || exit 1

# ----------------------------------------------------------------------
# synth --mips, render --size
# ----------------------------------------------------------------------
newdir
expect_ok "synth --mips" synth ../in/tex.png at.png --tile 32 --mips
check "synth --mips: at_mip1.png, at_mip2.png written" "at.png at_mip1.png at_mip2.png ..." "$(ls)" \
    "$([ -s at_mip1.png ] && [ -s at_mip2.png ] && is_png at_mip1.png; echo $?)"
check "synth --mips: only at*.png files, no temporaries" "at.png at_mipL.png ..." "$(ls -A | tr '\n' ' ')" \
    "$(! ls -A | grep -qvE '^at(_mip[0-9]+)?\.png$'; echo $?)"
check "synth --mips: at_mip1.png is half the atlas" "80 80 (atlas 160 160)" \
    "atlas $(png_size at.png), mip1 $(png_size at_mip1.png)" \
    "$([ "$(png_size at.png)" = "160 160" ] && [ "$(png_size at_mip1.png)" = "80 80" ]; echo $?)"
expect_ok "tile for render" tile ../in/torus.obj ../in/tex.png t --tile 32
expect_ok "render --size=123x77" render t.obj t.png r.png --size=123x77 --yaw 40 --pitch -10
check "render --size 123x77: PNG of that size" "123 77" "$(png_size r.png)" \
    "$(is_png r.png && [ "$(png_size r.png)" = "123 77" ]; echo $?)"
expect_ok "render default size" render t.obj t.png r2.png
check "render default size: 800x600" "800 600" "$(png_size r2.png)" "$([ "$(png_size r2.png)" = "800 600" ]; echo $?)"
expect_ok "render an untextured mesh" render ../in/torus.obj t.png r3.png --size 64x64
check "render untextured: 64x64" "64 64" "$(png_size r3.png)" "$([ "$(png_size r3.png)" = "64 64" ]; echo $?)"
cd "$W" || exit 1

# ======================================================================
# Hand-written OBJs
# ======================================================================
cd "$W/in" || exit 1
CUBE_V='v -1 -1 -1
v 1 -1 -1
v 1 1 -1
v -1 1 -1
v -1 -1 1
v 1 -1 1
v 1 1 1
v -1 1 1
'
CUBE_F='f 1 4 3 2
f 5 6 7 8
f 1 2 6 5
f 2 3 7 6
f 3 4 8 7
f 4 1 5 8
'
printf '%s%s' "$CUBE_V" "$CUBE_F" >cube.obj
# the same cube with relative (negative) indices, vertices interleaved with faces
{
    printf 'v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\n'
    printf 'f -4 -1 -2 -3\n'                   # = f 1 4 3 2
    printf 'v -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n'
    printf 'f -4 -3 -2 -1\nf -8 -7 -3 -4\nf -7 -6 -2 -3\nf -6 -5 -1 -2\nf -5 -8 -4 -1\n'
} >cube_neg.obj
# the same cube with v/vt/vn, v//vn and v/vt corners
{
    printf '%s' "$CUBE_V"
    printf 'vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n'
    printf 'f 1/1/1 4/2/1 3/3/1 2/4/1\nf 5/1/1 6/2/1 7/3/1 8/4/1\nf 1//1 2//1 6//1 5//1\n'
    printf 'f 2/1 3/2 7/3 6/4\nf 3/1/1 4/2/1 8/3/1 7/4/1\nf 4/4/1 1/3/1 5/2/1 8/1/1\n'
} >cube_forms.obj
# one face flipped (f 5 6 7 8 -> f 8 7 6 5): mis-oriented edges
printf '%s%s' "$CUBE_V" "$(printf '%s' "$CUBE_F" | sed 's/^f 5 6 7 8$/f 8 7 6 5/')" >cube_flipped.obj
printf '\n' >>cube_flipped.obj
# three triangles sharing the edge 1-2
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n' >nonmanifold.obj
printf '%sf 1 2 3 9\n' "$CUBE_V" >out_of_range.obj
printf '%sf -9 -5 -6 -7\n' "$CUBE_V" >bad_negative.obj
printf '%sf 0 1 2 3\n' "$CUBE_V" >zero_index.obj
printf 'v nan 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 4 3\n' >nan.obj
printf 'v inf 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 4 3\n' >inf.obj
printf '# no faces\nv 0 0 0\nv 1 0 0\nv 0 1 0\n' >noface.obj
: >empty.obj
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n' >two_corners.obj
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 1 2 3\n' >repeated_vertex.obj
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3x\n' >bad_corner.obj
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/5 3/1\n' >bad_vt.obj
head -c 2000 /dev/urandom >garbage.obj
awk 'BEGIN { srand(12345); for (i = 0; i < 2000; i++) printf "%c", int(rand() * 256) }' >garbage_fixed.obj
# OBJ-shaped random text: random vertices, then faces of 3-5 distinct random
# vertices (absolute or relative indices, some with /vt): a random soup of
# non-manifold and mis-oriented edges, which --permissive must cope with.
for k in 1 2 3 4 5 6; do
    awk -v seed=$k 'BEGIN {
        srand(seed); nv = 10 + 3 * seed
        for (i = 0; i < nv; i++) printf "v %f %f %f\n", rand() * 2 - 1, rand() * 2 - 1, (seed == 6 ? 0 : rand())
        printf "vt 0 0\nvt 1 1\n"
        for (i = 0; i < 20 + 10 * seed; i++) {
            n = 3 + int(rand() * 3); printf "f"; split("", used)
            for (j = 0; j < n; j++) {
                do x = 1 + int(rand() * nv); while (x in used)
                used[x] = 1
                printf " %d%s", (rand() < 0.3 ? x - nv - 1 : x), (rand() < 0.2 ? "/2" : "")
            }
            printf "\n"
        }
    }' >random$k.obj
done
# truncated mid-line: torus.obj cut in the middle of its 100th face line ("f 1"),
# and in the middle of a vertex line
off=$(awk '/^f /{n++; if (n == 100) {print b; exit}} {b += length($0) + 1}' torus.obj 2>/dev/null)
head -c $((${off:-100} + 3)) torus.obj >truncated_face.obj 2>/dev/null
off=$(awk '/^v /{n++; if (n == 50) {print b; exit}} {b += length($0) + 1}' torus.obj 2>/dev/null)
head -c $((${off:-100} + 4)) torus.obj >truncated_vertex.obj 2>/dev/null
cd "$W" || exit 1

# cube of quads: genus 0, valence 3..3, tile works
tile_case cube cube.obj 0 --tile 32
check "tile cube: valence 3..3" "'valence 3..3' in summary" "$OUT" "$(printf '%s' "$OUT" | grep -q 'valence 3\.\.3'; echo $?)"
check "tile cube: 6 quads" "'6 quads' in summary" "$OUT" "$(printf '%s' "$OUT" | grep -qE '(^|[^0-9])6 quads'; echo $?)"
CUBE_OUT=$W/d$NEWDIR_N/out.obj
tile_case cube-negative-indices cube_neg.obj 0 --tile 32
check "tile cube with negative indices: same v/vt/f as the plain cube" "identical v/vt/f lines" \
    "$(diff <(grep -E '^(v|vt|f) ' "$CUBE_OUT" 2>/dev/null) <(grep -E '^(v|vt|f) ' out.obj 2>/dev/null) 2>&1 | head -3)" \
    "$(cd "$W/d$NEWDIR_N" && diff -q <(grep -E '^(v|vt|f) ' "$CUBE_OUT" 2>/dev/null) <(grep -E '^(v|vt|f) ' out.obj 2>/dev/null) >/dev/null; echo $?)"
tile_case cube-v/vt/vn-forms cube_forms.obj 0 --tile 32
check "tile cube with v/vt/vn corners: same v/vt/f as the plain cube" "identical v/vt/f lines" \
    "$(diff <(grep -E '^(v|vt|f) ' "$CUBE_OUT" 2>/dev/null) <(grep -E '^(v|vt|f) ' out.obj 2>/dev/null) 2>&1 | head -3)" \
    "$(cd "$W/d$NEWDIR_N" && diff -q <(grep -E '^(v|vt|f) ' "$CUBE_OUT" 2>/dev/null) <(grep -E '^(v|vt|f) ' out.obj 2>/dev/null) >/dev/null; echo $?)"

newdir
expect_ok "map --subdivide 1 --smooth" map ../in/cube.obj sm.obj --subdivide 1 --smooth
check "map --subdivide 1 --smooth: cube -> 24 quads" "24 quads" "$OUT" "$(printf '%s' "$OUT" | grep -qE '(^|[^0-9])24 quads'; echo $?)"
check "--smooth moves the cube's corners inward" "no vertex at |x|=|y|=|z|=1" "$(grep -c '^v -\?1 -\?1 -\?1$' sm.obj 2>/dev/null) such vertices" \
    "$([ -s sm.obj ] && ! grep -qE '^v -?1 -?1 -?1$' sm.obj; echo $?)"
expect_ok "map --subdivide 1 (no --smooth)" map ../in/cube.obj sf.obj --subdivide 1
check "--subdivide without --smooth keeps the cube's corners" "8 vertices at |x|=|y|=|z|=1" "$(grep -cE '^v -?1 -?1 -?1$' sf.obj 2>/dev/null) such vertices" \
    "$([ "$(grep -cE '^v -?1 -?1 -?1$' sf.obj 2>/dev/null)" = 8 ]; echo $?)"
cd "$W" || exit 1

newdir
expect_ok "map non-manifold --permissive" map ../in/nonmanifold.obj m.obj --permissive
cd "$W" || exit 1

expect_error "tile flipped face" tile ../in/cube_flipped.obj ../in/tex.png out --tile 32
err_mentions "flipped face: message names the edge or face" 'edge|face'
newdir
expect_ok "tile flipped face --permissive" tile ../in/cube_flipped.obj ../in/tex.png out --tile 32 --permissive
[ -s out.obj ] && check_obj "tile flipped face --permissive" out.obj
cd "$W" || exit 1

# OBJ numbers vertices and faces from 1 (the tool says so itself), so an error
# about a mesh must never name vertex 0 or face 0.
no_zero_index() {
    check "$1: names vertices/faces the OBJ way (from 1)" "no 'vertex 0', 'vertices 0', 'face 0', 'faces 0', '(0,'" "$ERR" \
        "$(! printf '%s' "$ERR" | grep -qE '(vertex|vertices|face|faces) 0([^0-9.]|$)|\(0,'; echo $?)"
}

# permissive_case CMD IMAGE [ARGS...]: CMD refuses three triangles on one edge
# in one line that names the edge the OBJ way and says --permissive helps, and
# with --permissive cuts the edge open and writes an OBJ.
permissive_case() {
    local cmd=$1 image=$2
    shift 2
    expect_error "$cmd non-manifold edge" "$cmd" ../in/nonmanifold.obj "../in/$image" out "$@"
    err_mentions "$cmd non-manifold: names the edge or face and says --permissive would help" \
        '(edge|face).*--permissive'
    no_zero_index "$cmd non-manifold edge"
    newdir
    expect_ok "$cmd non-manifold --permissive" "$cmd" ../in/nonmanifold.obj "../in/$image" out "$@" --permissive
    check "$cmd non-manifold --permissive: writes the faces" "f lines in out.obj" "$(grep -c '^f ' out.obj 2>&1) f lines" \
        "$([ "$(grep -c '^f ' out.obj 2>/dev/null)" -gt 0 ]; echo $?)"
    # check_obj reads a quad OBJ, which only tile writes
    [ "$cmd" = tile ] && [ -s out.obj ] && check_obj "$cmd non-manifold --permissive" out.obj
    cd "$W" || exit 1
}
permissive_case tile tex.png --tile 32
expect_error "map NaN in vertex 1" map ../in/nan.obj m.obj
no_zero_index "map NaN in vertex 1"
expect_error "map non-manifold edge 1-2" map ../in/nonmanifold.obj m.obj
err_mentions "map non-manifold: message names the edge or face" 'edge|face'
no_zero_index "map non-manifold edge 1-2"
expect_error "map face 1 repeats vertex 1" map ../in/repeated_vertex.obj m.obj
no_zero_index "map face 1 repeats vertex 1"
expect_error "map flipped face 2" map ../in/cube_flipped.obj m.obj
check "map flipped face 2: names OBJ face 2 or vertices 8/7" "'face 2' / 'faces 2 and 5' or 'vertex 8 ... vertex 7'" "$ERR" \
    "$(printf '%s' "$ERR" | grep -qE 'faces? 2([^0-9]|$)|vertex 8.*vertex 7|vertex 7.*vertex 8|vertices (7 and 8|8 and 7)'; echo $?)"

expect_error "index out of range" tile ../in/out_of_range.obj ../in/tex.png out --tile 32
err_mentions "index out of range: message names line 9 or vertex 9" 'vertex 9|line 9|:9:'
expect_error "negative index out of range" tile ../in/bad_negative.obj ../in/tex.png out --tile 32
expect_error "index 0" tile ../in/zero_index.obj ../in/tex.png out --tile 32
expect_error "NaN coordinate" tile ../in/nan.obj ../in/tex.png out --tile 32
err_mentions "NaN coordinate: message says NaN" 'nan'
expect_error "infinite coordinate" map ../in/inf.obj m.obj
expect_error "OBJ without faces" tile ../in/noface.obj ../in/tex.png out --tile 32
expect_error "empty OBJ" tile ../in/empty.obj ../in/tex.png out --tile 32
expect_error "face with 2 corners" tile ../in/two_corners.obj ../in/tex.png out --tile 32
expect_error "face repeating a vertex" map ../in/repeated_vertex.obj m.obj
expect_error "unreadable face corner" map ../in/bad_corner.obj m.obj
expect_error "vt index out of range" map ../in/bad_vt.obj m.obj
expect_error "binary garbage OBJ" tile ../in/garbage.obj ../in/tex.png out --tile 32
expect_error "binary garbage OBJ (fixed)" map ../in/garbage_fixed.obj m.obj
# random OBJ-shaped input: either a clean error or a valid result, never a crash
for k in 1 2 3 4 5 6; do
    newdir
    run tile ../in/random$k.obj ../in/tex.png out --tile 32 --permissive
    if [ $RC -eq 0 ]; then
        pass
        check_obj "random OBJ $k" out.obj
        expect_ok "render random OBJ $k" render out.obj out.png r.png --size 64x48
        check "render random OBJ $k: 64x48" "64 48" "$(png_size r.png)" "$([ "$(png_size r.png)" = "64 48" ]; echo $?)"
    else
        check "random OBJ $k: clean failure" "exit 1 or 2, one 'tiledtex' stderr line, no files" \
            "exit $RC, stderr: $ERR, files: $(ls -A | tr '\n' ' ')" \
            "$([ $RC -lt 124 ] && [ "$(wc -l <"$W/err")" -eq 1 ] && head -c 8 "$W/err" | grep -qx tiledtex && [ -z "$(ls -A)" ]; echo $?)"
    fi
    cd "$W" || exit 1
done
expect_error "OBJ truncated mid face line" tile ../in/truncated_face.obj ../in/tex.png out --tile 32
expect_error "OBJ truncated mid vertex line" map ../in/truncated_vertex.obj m.obj

# ======================================================================
# Lapped textures
# ======================================================================
cd "$W/in" || exit 1
expect_ok "generate 64x64 texture for lapped" generate texture lap.png --size 64
# a black 64x64 mask (binary PGM): no pixel is inside the patch
{ printf 'P5\n64 64\n255\n'; head -c 4096 /dev/zero; } >black_mask.pgm
printf '# FACE X Y Z [SIGMA [WEIGHT]], faces counted from 1\n\n1 0 1 0\n300 1 0 0 0.5 2   # another\n' >constraints.txt
printf '1 0 1 0\n513 0 1 0\n' >constraints_range.txt
printf '1 0 0 0\n' >constraints_zero.txt
printf '1 0 1\n' >constraints_short.txt
printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n' >square.obj
printf '1 0 0 1\n' >constraints_normal.txt     # along the square's normal
# a quad whose fan has a zero-area triangle (corners 1, 2, 3 on one line)
printf 'v 0 0 0\nv 1 0 0\nv 2 0 0\nv 1 1 0\nf 1 2 3 4\n' >lapped_degenerate.obj
cd "$W" || exit 1

# lapped_coverage MESH OUT -> "triangles missing foreign": the MESH's faces as
# triangle fans; how many of them no face of OUT draws; how many faces of OUT
# are not one of them (triangles compared by their vertex sets).
lapped_coverage() {
    awk '
        function key(a, b, c,   t) {
            if (a > b) { t = a; a = b; b = t }
            if (b > c) { t = b; b = c; c = t }
            if (a > b) { t = a; a = b; b = t }
            return a " " b " " c
        }
        FNR == 1 { file++ }
        $1 == "f" {
            n = 0
            for (i = 2; i <= NF; i++) { split($i, p, "/"); v[++n] = p[1] + 0 }
            if (file == 1) {
                for (i = 2; i < n; i++) { k = key(v[1], v[i], v[i + 1]); if (!(k in want)) total++; want[k] = 1 }
            } else {
                k = key(v[1], v[2], v[3])
                if (n != 3 || !(k in want)) foreign++
                got[k] = 1
            }
        }
        END { for (k in want) if (!(k in got)) missing++; printf "%d %d %d\n", total, missing, foreign }
    ' "$1" "$2" 2>/dev/null
}
# lapped_groups OUT -> "groups bad": groups named paste_N with N increasing,
# each holding faces, and no face outside a group
lapped_groups() {
    awk '
        $1 == "g" {
            if (groups > 0 && faces == 0) bad++
            if ($2 !~ /^paste_[0-9]+$/ || substr($2, 7) + 0 <= last) bad++
            last = substr($2, 7) + 0; groups++; faces = 0
        }
        $1 == "f" { if (groups == 0) bad++; faces++ }
        END { if (groups > 0 && faces == 0) bad++; printf "%d %d\n", groups, bad }
    ' "$1" 2>/dev/null
}
summary_pastes() { printf '%s\n' "$OUT" | grep -oE '[0-9]+ pastes' | head -1 | awk '{print $1}'; }

# lapped_case NAME MESH ARGS... : in a fresh directory, lapped --pasting
# writes out.obj, out.mtl and out_patch.png; every triangle of MESH is in a
# paste, the groups are the pastes in order, coverage 100.0%.
lapped_case() {
    local name=$1 mesh=$2 r total missing foreign groups bad pastes
    shift 2
    newdir
    run lapped "../in/$mesh" ../in/lap.png out --pasting "$@"
    check "lapped $name: exit status" "0" "exit $RC, stderr: $ERR" "$([ $RC -eq 0 ]; echo $?)"
    check "lapped $name: exactly out.mtl, out.obj, out_patch.png" "out.mtl out.obj out_patch.png" \
        "$(ls -A | tr '\n' ' ')" "$([ "$(ls -A | tr '\n' ' ')" = "out.mtl out.obj out_patch.png " ]; echo $?)"
    check "lapped $name: patch is a PNG" "PNG signature" "$(od -An -tx1 -N8 out_patch.png 2>&1)" \
        "$(is_png out_patch.png; echo $?)"
    check "lapped $name: mtl names the patch as colour and alpha" "map_Kd and map_d out_patch.png, mtllib out.mtl" \
        "$(grep -h -E 'map_|mtllib' out.mtl out.obj 2>&1)" \
        "$(grep -qE '^map_Kd +out_patch\.png' out.mtl 2>/dev/null && grep -qE '^map_d +out_patch\.png' out.mtl 2>/dev/null &&
            grep -qE '^mtllib +out\.mtl' out.obj 2>/dev/null; echo $?)"
    r=$(lapped_coverage "$W/in/$mesh" out.obj)
    read -r total missing foreign <<<"$r"
    check "lapped $name: every triangle of the mesh is in a paste" "0 missing, 0 foreign of > 0" \
        "$total triangles, $missing missing, $foreign foreign" \
        "$([ "${total:-0}" -gt 0 ] && [ "${missing:-1}" -eq 0 ] && [ "${foreign:-1}" -eq 0 ]; echo $?)"
    read -r groups bad <<<"$(lapped_groups out.obj)"
    pastes=$(summary_pastes)
    check "lapped $name: groups paste_N in order, one per non-empty paste" \
        "> 1 groups, at most the $pastes pastes printed, in order" "$groups groups, $bad out of order or empty" \
        "$([ "${groups:-0}" -gt 1 ] && [ "${groups:-0}" -le "${pastes:-0}" ] && [ "${bad:-1}" -eq 0 ]; echo $?)"
    check "lapped $name: coverage 100.0%" "'coverage 100.0%' on stdout" "$OUT" \
        "$(printf '%s' "$OUT" | grep -q 'coverage 100\.0%'; echo $?)"
    cd "$W" || exit 1
}

lapped_case torus torus.obj --scale 1.5 --seed 3
LAPPED_TORUS=$W/d$NEWDIR_N
check "lapped torus: says it split the quads into triangles" "'1024 triangles (fans of 512 faces)'" "$OUT" \
    "$(printf '%s' "$OUT" | grep -q '1024 triangles (fans of 512 faces)'; echo $?)"
check "lapped torus: reports alignment" "'mean angle error X degrees, median scale error Y%'" "$OUT" \
    "$(printf '%s' "$OUT" | grep -qE 'mean angle error [0-9.]+ degrees, median scale error [0-9.]+%'; echo $?)"
check "lapped --pasting: says which programs draw the pasting OBJ and which do not" \
    "'out.obj holds the pastes: 'tiledtex render' and engines ... Blender and assimp do not ...'" "$OUT" \
    "$(printf '%s' "$OUT" | grep -qE "^out\.obj holds the pastes: 'tiledtex render' and engines .*; Blender and assimp do not .*leave out --pasting"; echo $?)"

# the default: the pastes baked into one texture, an ordinary textured mesh
# that every program opens; no pasting OBJ, no patch, no word of --pasting
newdir
expect_ok "lapped default (the bake)" lapped ../in/torus.obj ../in/lap.png out --scale 1.5 --seed 3
check "lapped default: exactly out.mtl, out.obj, out.png" "out.mtl out.obj out.png" "$(ls -A | tr '\n' ' ')" \
    "$([ "$(ls -A | tr '\n' ' ')" = "out.mtl out.obj out.png " ]; echo $?)"
bake_side=$(printf '%s\n' "$OUT" | sed -n 's/^bake size \([0-9]*\): the smallest power of two whose texels per unit .* reach .*/\1/p')
check "lapped default: the bake's side chosen and said: a power of two whose atlas reaches the pastes' texel density" \
    "'bake size N: the smallest power of two ...', N a power of two, an N x N texture" "$(png_size out.png) | $OUT" \
    "$(is_png out.png && [ -n "$bake_side" ] && [ "$(png_size out.png)" = "$bake_side $bake_side" ] &&
        [ $((bake_side & (bake_side - 1))) -eq 0 ]; echo $?)"
check "lapped default: the summary gives the atlas's fill and texel density spread" \
    "'bake atlas: N charts fill F% of it; texel density D texels per unit, 95th percentile over 5th S', S <= 1.2" \
    "$OUT" "$(printf '%s\n' "$OUT" | grep -E '^bake atlas: [0-9]+ charts? fill [0-9.]+% of it; texel density [0-9.e+]+ texels per unit, 95th percentile over 5th [0-9.]+$' |
        awk '{ exit !($NF + 0 >= 1 && $NF + 0 <= 1.2) }'; echo $?)"
check "lapped default: one material naming out.png, no paste groups" "map_Kd out.png, no 'g paste_'" \
    "$(grep -h -E '^(map_Kd|mtllib|usemtl|g) ' out.mtl out.obj 2>&1 | sort | uniq -c | head -5)" \
    "$(grep -qx 'map_Kd out.png' out.mtl && grep -qx 'mtllib out.mtl' out.obj && ! grep -q '^g paste_' out.obj; echo $?)"
check "lapped default: says it wrote the bake, not the pastes" \
    "'wrote out.obj, out.mtl, out.png (the pastes baked into NxN, over an atlas of N charts)', no 'holds the pastes'" \
    "$OUT" "$(printf '%s\n' "$OUT" | grep -qxE "wrote out\.obj, out\.mtl, out\.png \(the pastes baked into ${bake_side}x${bake_side}, over an atlas of [0-9]+ charts?\)" &&
        ! printf '%s' "$OUT" | grep -q 'holds the pastes'; echo $?)"
check_normals "lapped default: the baked OBJ" out.obj
expect_ok "render the default lapped OBJ with its texture" render out.obj out.png view.png --size 64x48
cd "$W" || exit 1

lapped_case sphere-triangles spheretri.obj --scale 0.9 --isotropic
lapped_case "grid (open)" grid.obj --scale 2 --up 0,0,1
lapped_case "pair (two components)" pair.obj --scale 1.5 --constraints ../in/constraints.txt

# the same seed twice: the same files; another seed: another result
newdir
expect_ok "lapped seed 3 again" lapped ../in/torus.obj ../in/lap.png out --pasting --scale 1.5 --seed 3
CMD="tiledtex lapped ../in/torus.obj ../in/lap.png out --pasting --scale 1.5 --seed 3 (twice)"
check "lapped same seed twice: identical .obj" "cmp equal" "$(cmp out.obj "$LAPPED_TORUS/out.obj" 2>&1)" \
    "$(cmp -s out.obj "$LAPPED_TORUS/out.obj"; echo $?)"
check "lapped same seed twice: identical patch" "cmp equal" "$(cmp out_patch.png "$LAPPED_TORUS/out_patch.png" 2>&1)" \
    "$(cmp -s out_patch.png "$LAPPED_TORUS/out_patch.png"; echo $?)"
expect_ok "lapped seed 4" lapped ../in/torus.obj ../in/lap.png other --pasting --scale 1.5 --seed 4
CMD="tiledtex lapped ../in/torus.obj ../in/lap.png out --pasting --scale 1.5 --seed 3 / --seed 4"
check "lapped different seed: different .obj" "files differ" "identical" "$(! cmp -s out.obj other.obj; echo $?)"

# the pasting OBJ renders (blended pastes)
expect_ok "render a pasting OBJ" render out.obj out_patch.png view.png --size 160x120
check "render pasting OBJ: 160x120 PNG" "160 120" "$(png_size view.png)" \
    "$(is_png view.png && [ "$(png_size view.png)" = "160 120" ]; echo $?)"
# each vt carries the paste's fade as its third number: in [0, 1], below 1
# where a paste had to stop short of its soft edge (this torus is thinner
# than its patch: pastes wrap and meet themselves), and render applies it
read -r nvt bad faded <<<"$(awk '$1=="vt"{n++; if (NF!=4 || $4<0 || $4>1) bad++; if ($4<1) f++} END{print n+0, bad+0, f+0}' out.obj)"
check "lapped: every vt has a fade in [0,1], some below 1" "vt u v w, 0 <= w <= 1, some w < 1" \
    "$nvt vt, $bad without or outside, $faded below 1" \
    "$([ "${nvt:-0}" -gt 0 ] && [ "${bad:-1}" = 0 ] && [ "${faded:-0}" -gt 0 ]; echo $?)"
awk '$1=="vt"{print "vt", $2, $3; next} {print}' out.obj > nofade.obj
expect_ok "render the pasting OBJ without its fades" render nofade.obj out_patch.png nofade.png --size 160x120
check "render: the fade in vt's third number changes the picture" "PNGs differ" "identical" \
    "$(! cmp -s view.png nofade.png; echo $?)"
awk '$1=="vt"{print "vt", $2, $3, 1; next} {print}' out.obj > ones.obj
expect_ok "render the pasting OBJ with fades of 1" render ones.obj out_patch.png ones.png --size 160x120
check "render: fades of 1 draw as no fade" "cmp equal" "$(cmp ones.png nofade.png 2>&1)" \
    "$(cmp -s ones.png nofade.png; echo $?)"
cd "$W" || exit 1

# --pasting --bake: over an atlas of charts (no vt in the OBJ) ...
newdir
expect_ok "lapped --pasting --bake 256" lapped ../in/torus.obj ../in/lap.png out --pasting --scale 1.5 --bake 256
seams_line=$(printf '%s\n' "$OUT" | grep '^baked seam score: ')
check "lapped --bake: the summary gives the baked seam score over every edge and where the top paste changes" \
    "'baked seam score: all edges S (1536 of 1536 edges); where the top paste changes S (N of N edges)'" \
    "$seams_line" \
    "$(printf '%s\n' "$seams_line" | grep -qE '^baked seam score: all edges -?[0-9]+\.[0-9]{3} \(1536 of 1536 edges\); where the top paste changes -?[0-9]+\.[0-9]{3} \(([0-9]+) of \1 edges\)$'; echo $?)"
check "lapped --bake without vt: over an atlas of charts, no warning" "'over an atlas of N charts', empty stderr" \
    "$OUT | $ERR" "$(printf '%s' "$OUT" | grep -qE 'over an atlas of [0-9]+ charts?\)' && [ -z "$ERR" ]; echo $?)"
check_normals "lapped --bake: the pasting OBJ" out.obj
check_normals "lapped --bake: the baked OBJ" out_baked.obj
check "lapped --bake: writes out_baked.obj/.mtl/.png too" "6 files" "$(ls -A | tr '\n' ' ')" \
    "$([ "$(ls -A | tr '\n' ' ')" = "out.mtl out.obj out_baked.mtl out_baked.obj out_baked.png out_patch.png " ]; echo $?)"
check "lapped --bake: 256x256 texture" "256 256" "$(png_size out_baked.png)" \
    "$(is_png out_baked.png && [ "$(png_size out_baked.png)" = "256 256" ]; echo $?)"
r=$(obj_report out_baked.obj)
read -r corners nvt nonquad badc baduv nf <<<"$r"
check "lapped --bake: baked OBJ has a vt in [0,1] at every corner of 1024 triangles" \
    "3072 corners, 0 < vt lines <= corners, 0 bad" "$corners corners, $nvt vt, $badc bad corners, $baduv bad vt" \
    "$([ "${corners:-0}" = 3072 ] && [ "${nvt:-0}" -gt 0 ] && [ "${nvt:-0}" -le 3072 ] && [ "${badc:-1}" = 0 ] &&
        [ "${baduv:-1}" = 0 ]; echo $?)"
for f in out.obj out_baked.obj; do
    check "lapped --bake: $f writes each distinct vt and vn once" "no vt line and no vn line twice" \
        "$(grep -E '^v[tn] ' $f | sort | uniq -d | head -2)" \
        "$([ -s $f ] && [ -z "$(grep -E '^v[tn] ' $f | sort | uniq -d)" ]; echo $?)"
done
check "lapped --bake: mtl names the baked texture" "map_Kd out_baked.png" "$(cat out_baked.mtl 2>&1)" \
    "$(grep -qE '^map_Kd +out_baked\.png' out_baked.mtl 2>/dev/null && grep -qE '^mtllib +out_baked\.mtl' out_baked.obj; echo $?)"
expect_ok "render the baked OBJ" render out_baked.obj out_baked.png view.png --size 64x48
# ... and over the OBJ's own texture coordinates when they can take a bake
# (the chart atlas just written can) ...
expect_ok "lapped --bake over the OBJ's own vt" lapped out_baked.obj ../in/lap.png own --scale 1.5 --bake 128
check "lapped --bake over own vt: says so, no warning" "'over the OBJ's texture coordinates', empty stderr" \
    "$OUT | $ERR" "$(printf '%s' "$OUT" | grep -q "over the OBJ's texture coordinates" && [ -z "$ERR" ]; echo $?)"
check "lapped --bake over own vt: same vt values as the OBJ" "identical sorted vt lines" "differ" \
    "$(diff -q <(grep '^vt' out_baked.obj | sort -u) <(grep '^vt' own.obj | sort -u) >/dev/null; echo $?)"
expect_ok "lapped --bake-uv atlas: a new atlas even over fit vt" lapped out_baked.obj ../in/lap.png new --scale 1.5 \
    --bake 128 --bake-uv atlas
check "lapped --bake-uv atlas: says so, no warning" "'over an atlas of N charts', empty stderr" "$OUT | $ERR" \
    "$(printf '%s' "$OUT" | grep -qE 'over an atlas of [0-9]+ charts?\)' && [ -z "$ERR" ]; echo $?)"
# ... but not over a tiled-texture OBJ's: its faces share tiles, so their vt
# overlap and a bake over them would scramble: auto warns once and makes an
# atlas, mesh refuses.
expect_ok "tile for lapped --bake" tile ../in/torus.obj ../in/lap.png t --tile 16
expect_ok "lapped --bake over overlapping vt" lapped t.obj ../in/lap.png tiled --scale 1.5 --bake 256
check "lapped --bake over overlapping vt: one warning naming two faces, then an atlas" \
    "one stderr line 'tiledtex: t.obj: its texture coordinates overlap (faces A and B); baking over a new atlas'" \
    "$OUT | $ERR" \
    "$([ "$(printf '%s\n' "$ERR" | wc -l)" = 1 ] &&
        printf '%s' "$ERR" | grep -qE '^tiledtex: t\.obj: its texture coordinates overlap \(faces [0-9]+ and [0-9]+\); baking over a new atlas$' &&
        printf '%s' "$OUT" | grep -qE 'over an atlas of [0-9]+ charts?\)'; echo $?)"
TILED_OBJ=$PWD/t.obj
NO_VT_OBJ=$W/in/torus.obj
cd "$W" || exit 1
expect_error "lapped --bake-uv mesh over overlapping vt" lapped "$TILED_OBJ" ../in/lap.png out --scale 1.5 --bake 256 \
    --bake-uv mesh
err_mentions "lapped --bake-uv mesh over overlapping vt: says why" 'bake-uv mesh: .*t\.obj: its texture coordinates overlap \(faces [0-9]+ and [0-9]+\)'
expect_error "lapped --bake-uv mesh without vt" lapped "$NO_VT_OBJ" ../in/lap.png out --scale 1.5 --bake 256 --bake-uv mesh
err_mentions "lapped --bake-uv mesh without vt: says so" 'bake-uv mesh: .*torus\.obj: its texture coordinates have none'
expect_error "lapped --bake-uv bogus" lapped "$NO_VT_OBJ" ../in/lap.png out --bake 256 --bake-uv bogus
err_mentions "lapped --bake-uv bogus: names the choices" 'auto, mesh or atlas'

# bad inputs: one line, non-zero exit, no files
expect_error "lapped missing mesh" lapped ../in/nope.obj ../in/lap.png out
err_mentions "lapped missing mesh: names the file" 'nope\.obj'
expect_error "lapped image not an image" lapped ../in/torus.obj ../in/torus.obj out
expect_error "lapped mask with no opaque pixel" lapped ../in/torus.obj ../in/lap.png out --mask ../in/black_mask.pgm
err_mentions "lapped empty mask: says so" 'opaque'
expect_error "lapped --scale 0" lapped ../in/torus.obj ../in/lap.png out --scale 0
expect_error "lapped --scale -1" lapped ../in/torus.obj ../in/lap.png out --scale -1
expect_error "lapped --scale nan" lapped ../in/torus.obj ../in/lap.png out --scale nan
expect_error "lapped --scale larger than the mesh" lapped ../in/torus.obj ../in/lap.png out --scale 1000
expect_error "lapped --constraints face out of range" lapped ../in/torus.obj ../in/lap.png out \
    --constraints ../in/constraints_range.txt
err_mentions "lapped constraint out of range: FILE:LINE" 'constraints_range\.txt:2:'
expect_error "lapped --constraints zero vector" lapped ../in/torus.obj ../in/lap.png out \
    --constraints ../in/constraints_zero.txt
err_mentions "lapped constraint zero vector: FILE:LINE" 'constraints_zero\.txt:1:'
expect_error "lapped --constraints malformed line" lapped ../in/torus.obj ../in/lap.png out \
    --constraints ../in/constraints_short.txt
err_mentions "lapped constraint malformed: FILE:LINE" 'constraints_short\.txt:1:'
expect_error "lapped --constraints along the face's normal" lapped ../in/square.obj ../in/lap.png out \
    --constraints ../in/constraints_normal.txt
err_mentions "lapped constraint along the normal: FILE:LINE, perpendicular" 'constraints_normal\.txt:1:.*perpendicular'
expect_error "lapped --constraints missing file" lapped ../in/torus.obj ../in/lap.png out --constraints ../in/nope.txt
expect_error "lapped --bake 0" lapped ../in/torus.obj ../in/lap.png out --bake 0
expect_error "lapped --bake 100000" lapped ../in/torus.obj ../in/lap.png out --bake 100000
expect_error "lapped --bake too small for the atlas" lapped ../in/torus.obj ../in/lap.png out --scale 1.5 --bake 16
err_mentions "lapped --bake too small: says the size" 'bake 16: .*the smallest size that works is'
expect_error "lapped --up 0,0,0" lapped ../in/torus.obj ../in/lap.png out --up 0,0,0
expect_error "lapped zero-area face" lapped ../in/lapped_degenerate.obj ../in/lap.png out
err_mentions "lapped zero-area face: FILE:LINE and face 1" 'lapped_degenerate\.obj:5: face 1 '
check "lapped zero-area face: no --permissive hint (the paste refuses such faces too)" "no '--permissive'" "$ERR" \
    "$(! printf '%s' "$ERR" | grep -q -- '--permissive'; echo $?)"
expect_error "lapped non-manifold edge" lapped ../in/nonmanifold.obj ../in/lap.png out
check "lapped non-manifold edge: suggests --permissive" "'--permissive cuts it open'" "$ERR" \
    "$(printf '%s' "$ERR" | grep -q -- '--permissive cuts it open'; echo $?)"
for arg in -1 abc 9 ''; do
    expect_error "lapped --subdivide '$arg'" lapped ../in/torus.obj ../in/lap.png out --subdivide "$arg"
    check "lapped --subdivide '$arg': says what it wants" "'--subdivide wants an integer from 0 to 8' or 'needs a value'" \
        "$ERR" "$(printf '%s' "$ERR" | grep -qE -- '--subdivide (wants an integer from 0 to 8, got|needs a value)'; echo $?)"
done
expect_error "lapped --subdivide without a value" lapped ../in/torus.obj ../in/lap.png out --subdivide
expect_error "lapped --subdivide 8: too many quads" lapped ../in/torus.obj ../in/lap.png out --subdivide 8
err_mentions "lapped --subdivide 8: says the limit" 'would make .* quads; the limit is'

# --permissive: an edge shared by three faces, as triangulated exports have
# (the torus with a fin on its edge 1-2), is cut open
{ cat "$W/in/torus.obj"; printf 'v 0 0 3\nf 1 2 513\n'; } >"$W/in/torus_fin.obj"
expect_error "lapped edge shared by three faces" lapped ../in/torus_fin.obj ../in/lap.png out --scale 1.5
check "lapped edge shared by three faces: one line naming the edge and suggesting --permissive" \
    "'torus_fin.obj:LINE: the edge between vertices 2 and 1 is shared by more than two faces ...; --permissive cuts it open'" \
    "$ERR" "$(printf '%s' "$ERR" | grep -qE 'torus_fin\.obj:[0-9]+: the edge between vertices [0-9]+ and [0-9]+ is shared by more than two faces.*--permissive cuts it open'; echo $?)"
lapped_case "edge shared by three faces --permissive" torus_fin.obj --scale 1.5 --permissive
check "lapped --permissive: says it cut the edge open" "'--permissive cut 1 non-manifold or mis-oriented edge open'" \
    "$ERR" "$(printf '%s' "$ERR" | grep -q 'torus_fin\.obj: --permissive cut 1 non-manifold or mis-oriented edge open'; echo $?)"
newdir
expect_ok "lapped three triangles on one edge --permissive" lapped ../in/nonmanifold.obj ../in/lap.png out --permissive
expect_ok "lapped flipped face --permissive" lapped ../in/cube_flipped.obj ../in/lap.png out --permissive --subdivide 1
cd "$W" || exit 1

# --subdivide L: each triangle quadrangulated L times, each quad split in two
# lapped_triangles OUT -> "distinct vertices": how many distinct triangles
# (by their vertex sets) the pastes draw, and the v lines
lapped_triangles() {
    awk '$1 == "v" { nv++ }
         $1 == "f" { for (i = 2; i <= 4; i++) { split($i, p, "/"); c[i] = p[1] + 0 }
                     if (c[2] > c[3]) { t = c[2]; c[2] = c[3]; c[3] = t }
                     if (c[3] > c[4]) { t = c[3]; c[3] = c[4]; c[4] = t }
                     if (c[2] > c[3]) { t = c[2]; c[2] = c[3]; c[3] = t }
                     k = c[2] " " c[3] " " c[4]; if (!(k in seen)) { seen[k] = 1; n++ } }
         END { printf "%d %d\n", n, nv }' "$1" 2>/dev/null
}
newdir
expect_ok "lapped --subdivide 1" lapped ../in/spheretri.obj ../in/lap.png out --scale 0.9 --subdivide 1
check "lapped --subdivide 1: 6 triangles per triangle" "'7680 triangles (1280 faces, --subdivide 1)'" "$OUT" \
    "$(printf '%s' "$OUT" | grep -q '7680 triangles (1280 faces, --subdivide 1)'; echo $?)"
check "lapped --subdivide 1: coverage 100.0%" "'coverage 100.0%'" "$OUT" "$(printf '%s' "$OUT" | grep -q 'coverage 100\.0%'; echo $?)"
read -r triangles verts <<<"$(lapped_triangles out.obj)"
# 642 vertices + 1920 edge points + 1280 face points
check "lapped --subdivide 1: the pastes draw the 7680 triangles over 3842 vertices" "7680 3842" \
    "$triangles $verts" "$([ "$triangles $verts" = "7680 3842" ]; echo $?)"
expect_ok "lapped --subdivide 2" lapped ../in/spheretri.obj ../in/lap.png two --scale 0.9 --subdivide 2
check "lapped --subdivide 2: 24 triangles per triangle" "'30720 triangles (1280 faces, --subdivide 2)'" "$OUT" \
    "$(printf '%s' "$OUT" | grep -q '30720 triangles (1280 faces, --subdivide 2)'; echo $?)"
expect_ok "lapped --subdivide 1 --smooth" lapped ../in/spheretri.obj ../in/lap.png smooth --scale 0.9 --subdivide 1 --smooth
check "lapped --smooth: other positions than the linear subdivision" "v lines differ" "identical" \
    "$(! cmp -s <(grep '^v ' out.obj) <(grep '^v ' smooth.obj); echo $?)"
expect_ok "lapped --subdivide 0: as without it" lapped ../in/spheretri.obj ../in/lap.png zero --scale 0.9 --subdivide 0
check "lapped --subdivide 0: 1280 triangles" "'1280 triangles,'" "$OUT" \
    "$(printf '%s' "$OUT" | grep -q '1280 triangles,'; echo $?)"
expect_ok "lapped --subdivide 1 --constraints (faces of the OBJ)" lapped ../in/pair.obj ../in/lap.png pair \
    --scale 1.5 --subdivide 1 --constraints ../in/constraints.txt
expect_error "lapped --subdivide 1 --constraints face out of range" lapped ../in/torus.obj ../in/lap.png out \
    --subdivide 1 --constraints ../in/constraints_range.txt
err_mentions "lapped --subdivide constraint out of range: counts the OBJ's faces" 'constraints_range\.txt:2:.*1 to 512'
newdir
expect_ok "an atlas OBJ for lapped --subdivide --bake" lapped ../in/torus.obj ../in/lap.png a --scale 1.5 --bake 256
mv a.obj t.obj
expect_ok "lapped --subdivide 1 --bake over the OBJ's own vt" lapped t.obj ../in/lap.png own --scale 1.5 --subdivide 1 \
    --bake 256 --bake-uv mesh --pasting
check "lapped --subdivide --bake over own vt: says so" "'over the OBJ's texture coordinates'" "$OUT" \
    "$(printf '%s' "$OUT" | grep -q "over the OBJ's texture coordinates"; echo $?)"
read -r corners nvt nonquad badc baduv nf <<<"$(obj_report own_baked.obj)"
check "lapped --subdivide --bake: a vt in [0,1] at every corner of 6144 triangles" \
    "18432 corners, 0 < vt lines <= corners, 0 bad" "$corners corners, $nvt vt, $badc bad corners, $baduv bad vt" \
    "$([ "${corners:-0}" = 18432 ] && [ "${nvt:-0}" -gt 0 ] && [ "${nvt:-0}" -le 18432 ] && [ "${badc:-1}" = 0 ] &&
        [ "${baduv:-1}" = 0 ]; echo $?)"
check "lapped --subdivide --bake: the OBJ's vt are still there (the corners keep theirs)" "every vt of t.obj" \
    "$(comm -23 <(grep '^vt' t.obj | sort -u) <(grep '^vt' own_baked.obj | sort -u) | head -3)" \
    "$([ -z "$(comm -23 <(grep '^vt' t.obj | sort -u) <(grep '^vt' own_baked.obj | sort -u))" ]; echo $?)"
cd "$W" || exit 1

# an absolute OUT_PREFIX: the OBJ names the MTL, the MTL the texture, by file
# name, so the folder can move; render the moved OBJ with the texture its MTL names
newdir
mkdir -p assets elsewhere pc
expect_ok "lapped into an absolute OUT_PREFIX" lapped ../in/torus.obj ../in/lap.png "$PWD/assets/out" --scale 1.5 \
    --bake 256 --pasting
check "lapped absolute OUT_PREFIX: mtllib lines name the MTL files by name" "mtllib out.mtl, mtllib out_baked.mtl" \
    "$(grep -h '^mtllib' assets/out.obj assets/out_baked.obj 2>&1)" \
    "$(grep -qx 'mtllib out.mtl' assets/out.obj && grep -qx 'mtllib out_baked.mtl' assets/out_baked.obj; echo $?)"
check "lapped absolute OUT_PREFIX: map_ lines name the textures by name" \
    "map_Kd/map_d out_patch.png, map_Kd out_baked.png, no '/'" "$(grep -h '^map_' assets/out.mtl assets/out_baked.mtl 2>&1)" \
    "$(grep -qx 'map_Kd out_patch.png' assets/out.mtl && grep -qx 'map_d out_patch.png' assets/out.mtl &&
        grep -qx 'map_Kd out_baked.png' assets/out_baked.mtl && ! grep -h -E '^(mtllib|map_)' assets/*.obj assets/*.mtl | grep -q /
        echo $?)"
mv assets elsewhere/moved
for obj in out out_baked; do
    mtl=$(awk '$1 == "mtllib" { print $2; exit }' "elsewhere/moved/$obj.obj" 2>/dev/null)
    texture=$(awk '$1 == "map_Kd" { print $2; exit }' "elsewhere/moved/$mtl" 2>/dev/null)
    case $texture in /*) ;; *) texture=elsewhere/moved/${texture:-missing} ;; esac
    expect_ok "render the moved $obj.obj with the texture its MTL names" render "elsewhere/moved/$obj.obj" \
        "$texture" "$obj.png" --size 64x48
done
# the other commands that write an MTL, with absolute paths
expect_ok "polycube into an absolute OUT_PREFIX" polycube ../in/spheretri.obj ../in/tex.png "$PWD/pc/out" --tile 16 \
    --colors 1 --resolution 6
check "polycube absolute OUT_PREFIX: map_Kd out.png, mtllib out.mtl twice" "no '/' in map_Kd and mtllib lines" \
    "$(grep -h -E '^(map_|mtllib)' pc/out.mtl pc/out.obj pc/out_polycube.obj 2>&1)" \
    "$(grep -qx 'map_Kd out.png' pc/out.mtl && grep -qx 'mtllib out.mtl' pc/out.obj &&
        grep -qx 'mtllib out.mtl' pc/out_polycube.obj; echo $?)"
expect_ok "tile for map --atlas with absolute paths" tile ../in/torus.obj ../in/tex.png "$PWD/pc/t" --tile 16
expect_ok "map --atlas with absolute paths" map ../in/torus.obj "$PWD/pc/m.obj" --tile 16 --atlas "$PWD/pc/t.png"
check "map --atlas absolute paths: map_Kd t.png, mtllib m.mtl" "map_Kd t.png, mtllib m.mtl" \
    "$(grep -h -E '^(map_|mtllib)' pc/m.mtl pc/m.obj 2>&1)" \
    "$(grep -qx 'map_Kd t.png' pc/m.mtl && grep -qx 'mtllib m.mtl' pc/m.obj; echo $?)"
cd "$W" || exit 1

# ----------------------------------------------------------------------
# Several texture patches (--patches): windows of the image, one material
# each, so that the pastes do not all show the same part of the photo
# ----------------------------------------------------------------------
cd "$W/in" || exit 1
expect_ok "generate 256x256 texture for lapped --patches" generate texture lap256.png --size 256 --seed 3
expect_ok "generate 128x128 texture for the stamping measure" generate texture lap128.png --size 128 --seed 3
cd "$W" || exit 1
# patch_summary -> "used of sum": from "patches: U of N used (...), a/b/c pastes"
patch_summary() {
    printf '%s\n' "$OUT" | awk '/^patches: / { n = split($NF == "pastes" ? $(NF - 1) : "", c, "/"); s = 0
        for (i = 1; i <= n; i++) s += c[i]; printf "%d %d %d\n", $2, $4, s; exit }'
}

newdir
expect_ok "lapped default on a 256x256 image" lapped ../in/torus.obj ../in/lap256.png out --pasting --scale 1.5
check "lapped default, 256x256 image: 4 patches of 128x128" "out.mtl out.obj out_patch_1.png ... out_patch_4.png" \
    "$(ls -A | tr '\n' ' ')" \
    "$([ "$(ls -A | tr '\n' ' ')" = "out.mtl out.obj out_patch_1.png out_patch_2.png out_patch_3.png out_patch_4.png " ] &&
        for k in 1 2 3 4; do [ "$(png_size out_patch_$k.png)" = "128 128" ] || exit 1; done; echo $?)"
check "lapped 4 patches: the MTL has materials lapped_1..4, each naming its patch" "4 x newmtl lapped_K, map_Kd out_patch_K.png" \
    "$(grep -E '^(newmtl|map_Kd)' out.mtl 2>&1)" \
    "$([ "$(grep -cE '^newmtl lapped_[1-4]$' out.mtl)" = 4 ] &&
        for k in 1 2 3 4; do grep -A6 -x "newmtl lapped_$k" out.mtl | grep -qx "map_Kd out_patch_$k.png" || exit 1; done; echo $?)"
check "lapped 4 patches: every group paste_N names a material lapped_K" "g paste_N then usemtl lapped_1..4, each used" \
    "$(grep -m4 -A1 '^g ' out.obj 2>&1)" \
    "$(awk '$1 == "g" { groups++; expect = 1; next }
            expect { if ($1 != "usemtl" || $2 !~ /^lapped_[1-4]$/) bad++; else used[$2] = 1; expect = 0 }
            END { n = 0; for (m in used) n++; exit !(groups > 1 && !bad && n == 4) }' out.obj; echo $?)"
read -r used total sum <<<"$(patch_summary)"
pastes=$(summary_pastes)
check "lapped 4 patches: the summary counts each patch's pastes, adding up to the pastes" \
    "'patches: 4 of 4 used (128x128 windows), a/b/c/d pastes', a+b+c+d = $pastes" "$OUT" \
    "$(printf '%s' "$OUT" | grep -qE '^patches: 4 of 4 used \(128x128 windows\), [0-9]+/[0-9]+/[0-9]+/[0-9]+ pastes$' &&
        [ "${used:-0}" = 4 ] && [ "${sum:-0}" = "${pastes:-x}" ]; echo $?)"
expect_ok "lapped 4 patches again" lapped ../in/torus.obj ../in/lap256.png again --pasting --scale 1.5
CMD="tiledtex lapped ../in/torus.obj ../in/lap256.png out / again (same seed)"
check "lapped 4 patches: same seed, same windows and pastes" "identical patches and OBJ bodies" "differ" \
    "$(for k in 1 2 3 4; do cmp -s out_patch_$k.png again_patch_$k.png || exit 1; done
        cmp -s <(grep -v mtllib out.obj) <(grep -v mtllib again.obj); echo $?)"
# render: each paste with its own material's patch, whichever TEXTURE is given
expect_ok "render a 4-patch pasting OBJ" render out.obj out_patch_1.png view.png --size 160x120
expect_ok "render a 4-patch pasting OBJ, another TEXTURE" render out.obj out_patch_2.png view2.png --size 160x120
expect_ok "render a 4-patch pasting OBJ with one texture (--no-materials)" render out.obj out_patch_1.png one.png \
    --size 160x120 --no-materials
CMD="tiledtex render out.obj out_patch_1.png / out_patch_2.png / --no-materials"
check "render 4 patches: the materials' textures are drawn, not TEXTURE" "view.png = view2.png" "differ" \
    "$(cmp -s view.png view2.png; echo $?)"
check "render 4 patches: differs from one texture on every paste" "view.png != one.png" "identical" \
    "$(! cmp -s view.png one.png; echo $?)"
cd "$W" || exit 1

# a small image keeps the whole image as the one patch; --patches 1 is that
newdir
expect_ok "lapped default on a 64x64 image" lapped ../in/torus.obj ../in/lap.png out --pasting --scale 1.5
check "lapped default, 64x64 image: one patch, the whole image" "out_patch.png 64x64, 'patches: 1 of 1 used (the whole image)'" \
    "$(ls -A | tr '\n' ' '); $OUT" \
    "$([ "$(png_size out_patch.png)" = "64 64" ] && [ ! -e out_patch_1.png ] &&
        printf '%s' "$OUT" | grep -qE '^patches: 1 of 1 used \(the whole image\), [0-9]+ pastes$'; echo $?)"
mkdir one && cd one || exit 1
expect_ok "lapped --patches 1 on a 64x64 image" lapped ../../in/torus.obj ../../in/lap.png out --pasting --scale 1.5 --patches 1
CMD="tiledtex lapped torus.obj lap.png out --scale 1.5 (default / --patches 1)"
check "lapped --patches 1 = the default on a small image" "identical out.obj, out.mtl, out_patch.png" "differ" \
    "$(cmp -s out.obj ../out.obj && cmp -s out.mtl ../out.mtl && cmp -s out_patch.png ../out_patch.png; echo $?)"
cd "$W" || exit 1
newdir
expect_ok "lapped --patches 1 on a 256x256 image" lapped ../in/torus.obj ../in/lap256.png out --pasting --scale 1.5 --patches 1
check "lapped --patches 1: the whole image, one material for the file" "out_patch.png 256x256, one usemtl lapped" \
    "$(png_size out_patch.png); $(grep -c '^usemtl' out.obj) usemtl" \
    "$([ "$(png_size out_patch.png)" = "256 256" ] && [ "$(grep -c '^usemtl' out.obj)" = 1 ] &&
        grep -qx 'usemtl lapped' out.obj && [ "$(grep -c '^newmtl' out.mtl)" = 1 ]; echo $?)"
expect_ok "lapped --patches 9" lapped ../in/torus.obj ../in/lap256.png nine --pasting --scale 1.5 --patches 9
check "lapped --patches 9: 9 windows of 85x85 (the largest that fit 3 x 3)" "nine_patch_1..9.png, 85x85" \
    "$(ls nine_patch_* | tr '\n' ' '); $(png_size nine_patch_9.png)" \
    "$([ "$(ls nine_patch_*.png | wc -l)" = 9 ] && [ "$(png_size nine_patch_9.png)" = "85 85" ]; echo $?)"
expect_ok "lapped --patch-size 64 (default count 4)" lapped ../in/torus.obj ../in/lap256.png sized --pasting --scale 1.5 \
    --patch-size 64 --isotropic --bake 256
check "lapped --patch-size 64 --isotropic --bake: 4 patches of 64x64, a baked texture" "sized_patch_4.png 64x64, sized_baked.png" \
    "$(ls sized* | tr '\n' ' ')" "$([ "$(png_size sized_patch_4.png)" = "64 64" ] && is_png sized_baked.png; echo $?)"
# one --mask for every patch: the image's size (scaled to the patch's) or a patch's
{ printf 'P5\n256 256\n255\n'; head -c 65536 /dev/zero | tr '\0' '\377'; } >mask256.pgm
{ printf 'P5\n128 128\n255\n'; head -c 16384 /dev/zero | tr '\0' '\377'; } >mask128.pgm
expect_ok "lapped 4 patches, --mask the image's size" lapped ../in/torus.obj ../in/lap256.png m1 --pasting --scale 1.5 --mask mask256.pgm
expect_ok "lapped 4 patches, --mask a patch's size" lapped ../in/torus.obj ../in/lap256.png m2 --pasting --scale 1.5 --mask mask128.pgm
CMD="tiledtex lapped ... --mask mask256.pgm / mask128.pgm (both all white)"
check "lapped --mask: the image-sized mask scaled to the patch is the patch-sized one" "identical patches" "differ" \
    "$(for k in 1 2 3 4; do cmp -s m1_patch_$k.png m2_patch_$k.png || exit 1; done; echo $?)"
cd "$W" || exit 1
# refused: with one line, the usage status for the command line, 1 for windows the image cannot hold
for arg in 0 -1 257 x; do
    expect_error "lapped --patches '$arg'" lapped ../in/torus.obj ../in/lap256.png out --patches "$arg"
    check "lapped --patches '$arg': usage status 2, says what it wants" "exit 2, '--patches wants an integer from 1 to 256'" \
        "exit $RC: $ERR" "$([ $RC -eq 2 ] && printf '%s' "$ERR" | grep -q -- '--patches wants an integer from 1 to 256'; echo $?)"
done
expect_error "lapped --patch-size 16" lapped ../in/torus.obj ../in/lap256.png out --patch-size 16
check "lapped --patch-size 16: usage status 2" "exit 2" "exit $RC" "$([ $RC -eq 2 ]; echo $?)"
expect_error "lapped --patches 5 on a 64x64 image" lapped ../in/torus.obj ../in/lap.png out --patches 5
err_mentions "lapped --patches 5 on 64x64: too small windows" 'patches 5: 5 windows fit in .*lap\.png \(64x64\) only at [0-9]+x[0-9]+ texels'
check "lapped --patches 5 on 64x64: status 1" "exit 1" "exit $RC" "$([ $RC -eq 1 ]; echo $?)"
expect_error "lapped --patches 2 --patch-size 40 on a 64x64 image" lapped ../in/torus.obj ../in/lap.png out --patches 2 \
    --patch-size 40
err_mentions "lapped --patches 2 --patch-size 40 on 64x64: says how many fit" 'only 1 window of 40x40 texels fits'
expect_error "lapped --patch-size larger than the image" lapped ../in/torus.obj ../in/lap.png out --patch-size 100
err_mentions "lapped --patch-size 100 on 64x64: says the image's size" 'patch-size 100: .*lap\.png is only 64x64'
expect_error "lapped --mask of neither size" lapped ../in/torus.obj ../in/lap256.png out --mask ../in/black_mask.pgm
err_mentions "lapped --mask of neither size: names both" 'black_mask\.pgm is 64x64: a mask must be the size of a patch \(128x128\) or of'

# render: each face's material is its latest usemtl, whatever g follows; a
# material texture that cannot be read is a note, and TEXTURE stands in
newdir
printf 'mtllib two.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n' >two.obj
printf 'usemtl dark\ng left\nf 1/1 2/2 3/3\nusemtl missing\ng right\nf 1/1 3/3 4/4\n' >>two.obj
{ printf 'P5\n4 4\n255\n'; head -c 16 /dev/zero; } >dark.pgm
{ printf 'P5\n4 4\n255\n'; head -c 16 /dev/zero | tr '\0' '\377'; } >light.pgm
printf 'newmtl dark\nmap_Kd -s 1 1 1 dark.pgm\nnewmtl missing\nmap_Kd nope.png\n' >two.mtl
expect_ok "render materials: usemtl before g, one texture missing" render two.obj light.pgm mat.png --size 32x32 --yaw 0 --pitch 0
err_mentions "render materials: a note names the missing texture and the stand-in" 'material missing of two\.obj: .*nope\.png.*drawn with light\.pgm'
expect_ok "render materials: --no-materials" render two.obj light.pgm plain.png --size 32x32 --yaw 0 --pitch 0 --no-materials
CMD="tiledtex render two.obj light.pgm (materials / --no-materials)"
check "render materials: the dark material's texture is drawn" "mat.png != plain.png" "identical" \
    "$(! cmp -s mat.png plain.png; echo $?)"
cd "$W" || exit 1

# A control that can fail: --patches 1 stamps one patch like wallpaper, and
# several patches stamp each part of the photo less. On a flat plane baked
# over its own texture coordinates (an undistorted picture of the pastes),
# count for 16 probe windows of 24x24 texels the other places where the
# same content recurs (normalised cross-correlation >= 0.9, local maxima).
cat >"$W/repeats.c" <<'EOF_C'
/* repeats IMAGE: the mean number of times the content of a probe window
   recurs elsewhere in IMAGE (see tests/e2e.sh). */
#define STB_IMAGE_IMPLEMENTATION
#include "stb_image.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#define WIN 24
int main(int argc, char **argv)
{
    int w, h, n, probe, x, y, i, j, total = 0, probes = 0;
    unsigned char *p = argc == 2 ? stbi_load(argv[1], &w, &h, &n, 3) : NULL;
    double *lum, *ncc;
    if (!p || w < 4 * WIN || h < 4 * WIN) return 1;
    lum = (double *)malloc(sizeof(double) * w * h);
    ncc = (double *)calloc((size_t)w * h, sizeof(double));
    if (!lum || !ncc) return 1;
    for (x = 0; x < w * h; x++) lum[x] = 0.299 * p[3 * x] + 0.587 * p[3 * x + 1] + 0.114 * p[3 * x + 2];
    for (probe = 0; probe < 16; probe++) {
        int px = (probe % 4) * (w - WIN) / 3, py = (probe / 4) * (h - WIN) / 3;
        double ma = 0, va = 0;
        for (j = 0; j < WIN; j++) for (i = 0; i < WIN; i++) ma += lum[(py + j) * w + px + i];
        ma /= WIN * WIN;
        for (j = 0; j < WIN; j++) for (i = 0; i < WIN; i++) va += pow(lum[(py + j) * w + px + i] - ma, 2);
        if (va < WIN * WIN * 4.0) continue;     /* flat: nothing to recognise */
        probes++;
        for (y = 0; y + WIN <= h; y++)
            for (x = 0; x + WIN <= w; x++) {
                double mb = 0, vb = 0, c = 0;
                for (j = 0; j < WIN; j++) for (i = 0; i < WIN; i++) mb += lum[(y + j) * w + x + i];
                mb /= WIN * WIN;
                for (j = 0; j < WIN; j++)
                    for (i = 0; i < WIN; i++) {
                        double b = lum[(y + j) * w + x + i] - mb;
                        vb += b * b;
                        c += (lum[(py + j) * w + px + i] - ma) * b;
                    }
                ncc[y * w + x] = vb > 0 ? c / sqrt(va * vb) : 0;
            }
        for (y = 1; y + WIN < h; y++)
            for (x = 1; x + WIN < w; x++) {
                double v = ncc[y * w + x];
                int peak = v >= 0.9 && (abs(x - px) >= WIN || abs(y - py) >= WIN);
                for (j = -1; j <= 1 && peak; j++)
                    for (i = -1; i <= 1 && peak; i++)
                        if ((i || j) && ncc[(y + j) * w + x + i] > v) peak = 0;
                total += peak;
            }
    }
    if (probes == 0) return 1;
    printf("%.2f\n", (double)total / probes);
    return 0;
}
EOF_C
newdir
# a 4 x 4 plane of 32 x 32 quads facing +z, texture coordinates = position / 4
awk 'BEGIN { n = 32; for (j = 0; j <= n; j++) for (i = 0; i <= n; i++) {
        printf "v %g %g 0\nvt %g %g\n", 4 * i / n, 4 * j / n, i / n, j / n }
    for (j = 0; j < n; j++) for (i = 0; i < n; i++) { a = j * (n + 1) + i + 1
        printf "f %d/%d %d/%d %d/%d %d/%d\n", a, a, a + 1, a + 1, a + n + 2, a + n + 2, a + n + 1, a + n + 1 } }' >plane.obj
CMD="$HELPER_CC $STB_INC repeats.c (test helper)"
# shellcheck disable=SC2086
if $HELPER_CC -O2 -w $STB_INC "$W/repeats.c" -o "$W/repeats" -lm 2>"$W/err"; then
    # Two seeds each: one run's count moves by a third with the paste order.
    for seed in 0 1; do
        expect_ok "lapped a plane, --patches 1, baked, seed $seed" lapped plane.obj ../in/lap128.png p1s$seed \
            --scale 1 --patches 1 --bake 256 --seed $seed --pasting
        expect_ok "lapped a plane, --patches 4, baked, seed $seed" lapped plane.obj ../in/lap128.png p4s$seed \
            --scale 1 --patches 4 --bake 256 --seed $seed --pasting
    done
    r1=$(awk -v a="$("$W/repeats" p1s0_baked.png 2>&1)" -v b="$("$W/repeats" p1s1_baked.png 2>&1)" \
        'BEGIN { printf "%.2f", (a + b) / 2 }')
    r4=$(awk -v a="$("$W/repeats" p4s0_baked.png 2>&1)" -v b="$("$W/repeats" p4s1_baked.png 2>&1)" \
        'BEGIN { printf "%.2f", (a + b) / 2 }')
    CMD="repeats p1s*_baked.png / p4s*_baked.png (mean of seeds 0 and 1)"
    check "stamping control: one patch recurs like wallpaper" "at least 3 recurrences per probe" "$r1" \
        "$(awk -v a="$r1" 'BEGIN { exit !(a + 0 >= 3) }'; echo $?)"
    check "stamping: 4 patches recur less than half as often as one" "repeats(p4) < repeats(p1) / 2" "$r4 against $r1" \
        "$(awk -v a="$r1" -v b="$r4" 'BEGIN { exit !(b + 0 < (a + 0) / 2) }'; echo $?)"
else
    fail "helper for the stamping measure" "$CMD" "compiles" "$(head -c 300 "$W/err")"
fi
cd "$W" || exit 1

# ======================================================================
# Hierarchical pattern mapping
# ======================================================================
# hpm_obj_report OBJ -> "faces nontri corners nvt badc unused nonfinite outside":
#   f lines, f lines without 3 corners, corners, vt lines, corners whose v or vt
#   index is missing or out of range, vt lines no corner uses, vt values that
#   are not finite numbers, finite ones outside [0,1].
hpm_obj_report() {
    awk '
        function isnum(s) { return s ~ /^[-+]?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][-+]?[0-9]+)?$/ }
        $1 == "v"  { nv++ }
        $1 == "vt" { nvt++
                     for (i = 2; i <= 3; i++)
                         if (!isnum($i)) nonfinite++
                         else if ($i + 0 < 0 || $i + 0 > 1) outside++ }
        $1 == "f"  { nf++
                     if (NF - 1 != 3) nontri++
                     for (i = 2; i <= NF; i++) { corners++; c[corners] = $i } }
        END {
            for (k = 1; k <= corners; k++) {
                n = split(c[k], p, "/")
                if (n < 2 || p[1] !~ /^[0-9]+$/ || p[2] !~ /^[0-9]+$/ ||
                    p[1] + 0 < 1 || p[1] + 0 > nv || p[2] + 0 < 1 || p[2] + 0 > nvt) badc++
                else uses[p[2] + 0]++
            }
            for (k = 1; k <= nvt; k++) if (uses[k] < 1) unused++
            printf "%d %d %d %d %d %d %d %d\n", nf, nontri, corners, nvt, badc, unused, nonfinite, outside
        }' "$1" 2>/dev/null
}
# fan_triangles OBJ -> the number of triangles its faces split into
fan_triangles() { awk '$1 == "f" { n += NF - 3 } END { print n + 0 }' "$1" 2>/dev/null; }

# hpm_case NAME MESH BOUNDED ARGS... : in a fresh directory, hpm writes
# exactly out.obj, out.mtl and out.png, a copy of the input image byte for
# byte, which the MTL names (the folder can move); the OBJ holds the mesh's
# triangle fans with a vt for each corner (equal ones shared), finite (and
# in [0,1] when BOUNDED is "bounded"); the summary has its lines.
hpm_case() {
    local name=$1 mesh=$2 bounded=$3 faces nontri corners nvt badc unused nonfinite outside want
    shift 3
    newdir
    run hpm "../in/$mesh" ../in/lap.png out "$@"
    check "hpm $name: exit status" "0" "exit $RC, stderr: $ERR" "$([ $RC -eq 0 ]; echo $?)"
    check "hpm $name: exactly out.mtl, out.obj, out.png" "out.mtl out.obj out.png" "$(ls -A | tr '\n' ' ')" \
        "$([ "$(ls -A | tr '\n' ' ')" = "out.mtl out.obj out.png " ]; echo $?)"
    check "hpm $name: mtl names out.png, the input image's copy" "map_Kd out.png, mtllib out.mtl, out.png = lap.png" \
        "$(grep -h -E 'map_|mtllib' out.mtl out.obj 2>&1)" \
        "$(grep -qE '^map_Kd +out\.png$' out.mtl 2>/dev/null && grep -qE '^mtllib +out\.mtl' out.obj 2>/dev/null &&
           cmp -s out.png ../in/lap.png; echo $?)"
    read -r faces nontri corners nvt badc unused nonfinite outside <<<"$(hpm_obj_report out.obj)"
    want=$(fan_triangles "$W/in/$mesh")
    check "hpm $name: the mesh's $want triangles" "$want triangle f lines" "$faces f lines, $nontri not triangles" \
        "$([ "${faces:-0}" = "$want" ] && [ "${nontri:-1}" = 0 ]; echo $?)"
    check "hpm $name: a vt for each face corner, equal ones shared" \
        "corners = $((3 * want)), 1 <= vt lines <= corners, 0 bad, 0 unused" \
        "$nvt vt, $corners corners, $badc bad corners, $unused vt unused" \
        "$([ "${corners:-0}" = $((3 * want)) ] && [ "${nvt:-0}" -ge 1 ] && [ "${nvt:-0}" -le "${corners:-0}" ] &&
            [ "${badc:-1}" = 0 ] && [ "${unused:-1}" = 0 ]; echo $?)"
    check "hpm $name: UVs finite" "0 non-finite vt values" "$nonfinite" "$([ "${nonfinite:-1}" = 0 ]; echo $?)"
    if [ "$bounded" = bounded ]; then
        check "hpm $name: UVs inside [0,1] (bounded image)" "0 vt values outside" "$outside" \
            "$([ "${outside:-1}" = 0 ]; echo $?)"
    fi
    check "hpm $name: summary" "'clusters per level: L0 N, ...', 'fits: N accepted', 'texel density'" "$OUT" \
        "$(printf '%s' "$OUT" | grep -qE '^clusters per level: L0 [0-9]+' &&
            printf '%s' "$OUT" | grep -qE '^fits: [0-9]+ accepted, [0-9]+ at the floor, [0-9]+ rejected' &&
            printf '%s' "$OUT" | grep -q 'texel density'; echo $?)"
    check "hpm $name: summary measures" "'seam score: cluster borders X (N of M border edges); all edges Y', \
'UV distortion: stretch p5 X, median Y, p95 Z; texel density p5 A, p95 B of its median; density error ...; 0 flipped UV triangles'" "$OUT" \
        "$(printf '%s' "$OUT" | grep -qE '^seam score: cluster borders -?[0-9.]+ \([0-9]+ of [0-9]+ border edges\); all edges -?[0-9.]+ ' &&
            printf '%s' "$OUT" | grep -qE '^UV distortion: stretch p5 [0-9.]+, median [0-9.]+, p95 [0-9.]+; texel density p5 [0-9.]+, p95 [0-9.]+ of its median; density error median [0-9.]+%, p95 [0-9.]+%; 0 flipped UV triangles$'; echo $?)"
    cd "$W" || exit 1
}

hpm_case torus torus.obj bounded --rotations 3 --seed 2
HPM_TORUS=$W/d$NEWDIR_N
HPM_TORUS_OUT=$OUT
check "hpm torus: says it split the quads into triangles" "'1024 triangles (fans of 512 faces)'" "$OUT" \
    "$(printf '%s' "$OUT" | grep -q '1024 triangles (fans of 512 faces)'; echo $?)"
hpm_case sphere-triangles spheretri.obj bounded --rotations 3
hpm_case "grid (open)" grid.obj bounded --rotations 3 --threshold inf
hpm_case "pair (two components)" pair.obj bounded --rotations 1 --band 4
hpm_case "torus --toroidal" torus.obj toroidal --rotations 3 --toroidal --scale 0.5
check "hpm --toroidal: coordinates leave [0,1]" "some vt outside [0,1] (the image repeats)" \
    "$(hpm_obj_report "$W/d$NEWDIR_N/out.obj")" \
    "$(read -r _ _ _ _ _ _ _ outside <<<"$(hpm_obj_report "$W/d$NEWDIR_N/out.obj")"; [ "${outside:-0}" -gt 0 ]; echo $?)"
hpm_case "torus --max-turn 180" torus.obj bounded --rotations 5 --max-turn 180
hpm_case "torus --no-fit" torus.obj bounded --rotations 3 --seed 2 --no-fit
HPM_RANDOM=$W/d$NEWDIR_N
check "hpm --no-fit: says the clusters were placed at random" "'placed at random'" "$OUT" \
    "$(printf '%s' "$OUT" | grep -q 'placed at random'; echo $?)"
CMD="tiledtex hpm ../in/torus.obj ../in/lap.png out --rotations 3 --seed 2 [--no-fit]"
check "hpm --no-fit: other coordinates than the fitted ones" "files differ" "identical" \
    "$(! cmp -s "$HPM_TORUS/out.obj" "$HPM_RANDOM/out.obj"; echo $?)"

# The mesh options: --subdivide makes six triangles of each before the
# clusters are made, and the OBJ has them; --permissive cuts a bad edge open.
newdir
expect_ok "hpm --subdivide 1" hpm ../in/spheretri.obj ../in/lap.png out --rotations 3 --subdivide 1
check "hpm --subdivide 1: the summary counts 6 triangles for each" "'7680 triangles (1280 faces, --subdivide 1)'" \
    "$OUT" "$(printf '%s' "$OUT" | grep -q 'spheretri.obj: 7680 triangles (1280 faces, --subdivide 1)'; echo $?)"
check "hpm --subdivide 1: the OBJ has them" "7680 f lines" "$(grep -c '^f ' out.obj 2>&1) f lines" \
    "$([ "$(grep -c '^f ' out.obj 2>/dev/null)" = 7680 ]; echo $?)"
cd "$W" || exit 1
# --subdivide auto, the default: the 1280-triangle sphere at a 256-texel
# image's default scale has triangles of about 860 texels^2, more than half
# the library's smallest patch (576): subdivided once, and said; a 64-texel
# image (54 texels^2) leaves it; --subdivide 0 keeps it; auto is hpm's own.
newdir
expect_ok "hpm on a coarse mesh (--subdivide auto)" hpm ../in/spheretri.obj ../in/lap256.png out --rotations 3
err_mentions "hpm on a coarse mesh: says it subdivided, why and how to keep the mesh" \
    'spheretri\.obj: its triangles cover [0-9]+ texels\^2 each \(the median\) at the texture.s scale, more than half the smallest patch \(576\): subdivided once \(--subdivide 1\), 1280 triangles into 7680, .*--subdivide 0 keeps them'
check "hpm on a coarse mesh: the summary and the OBJ have the 7680 triangles" \
    "'7680 triangles (1280 faces, --subdivide 1)', 7680 f lines" "$(grep -c '^f ' out.obj 2>&1) f lines" \
    "$(printf '%s' "$OUT" | grep -q 'spheretri.obj: 7680 triangles (1280 faces, --subdivide 1)' &&
       [ "$(grep -c '^f ' out.obj 2>/dev/null)" = 7680 ]; echo $?)"
expect_ok "hpm --subdivide auto (given)" hpm ../in/spheretri.obj ../in/lap256.png given --rotations 3 --subdivide auto
check "hpm --subdivide auto: the same vertices, coordinates and faces as the default" "equal v, vt and f lines" \
    "$(diff <(grep -E '^(v|vt|f) ' out.obj) <(grep -E '^(v|vt|f) ' given.obj) 2>&1 | head -3)" \
    "$(diff -q <(grep -E '^(v|vt|f) ' out.obj) <(grep -E '^(v|vt|f) ' given.obj) >/dev/null 2>&1; echo $?)"
expect_ok "hpm --subdivide 0 on the coarse mesh" hpm ../in/spheretri.obj ../in/lap256.png kept --rotations 3 --subdivide 0
check "hpm --subdivide 0: the mesh's 1280 triangles, no note" "1280 f lines, nothing on stderr about subdividing" \
    "$(grep -c '^f ' kept.obj 2>&1) f lines; $ERR" \
    "$([ "$(grep -c '^f ' kept.obj 2>/dev/null)" = 1280 ] && ! printf '%s' "$ERR" | grep -q subdivid; echo $?)"
expect_ok "hpm on a 64-texel image (triangles small enough)" hpm ../in/spheretri.obj ../in/lap.png small --rotations 3
check "hpm on a 64-texel image: not subdivided, no note" "1280 f lines, nothing on stderr about subdividing" \
    "$(grep -c '^f ' small.obj 2>&1) f lines; $ERR" \
    "$([ "$(grep -c '^f ' small.obj 2>/dev/null)" = 1280 ] && ! printf '%s' "$ERR" | grep -q subdivid; echo $?)"
expect_ok "hpm --scale 8 (a coarser texture: triangles small enough)" hpm ../in/spheretri.obj ../in/lap256.png far \
    --rotations 3 --scale 8
check "hpm --scale 8: not subdivided" "1280 f lines" "$(grep -c '^f ' far.obj 2>&1) f lines" \
    "$([ "$(grep -c '^f ' far.obj 2>/dev/null)" = 1280 ]; echo $?)"
expect_error "lapped --subdivide auto (hpm's only)" lapped ../in/spheretri.obj ../in/lap.png out --subdivide auto
check "lapped --subdivide auto: exit status 2 (usage)" "exit 2" "exit $RC" "$([ $RC -eq 2 ]; echo $?)"
err_mentions "lapped --subdivide auto: names the option and what it wants" "subdivide wants an integer from 0 to 8, got 'auto'"
# A seamless image gets one note suggesting --toroidal; a photo that does
# not tile (the generated stones) gets none, nor does a command that gives
# --toroidal. The seamless one is noise mirrored across both axes, so its
# last column and row repeat its first: it wraps with no difference at all.
# (Noise alone wraps like a random pair of its columns, which ranks among
# the largest 5 % one time in twenty per axis.)
newdir
LC_ALL=C awk 'BEGIN {
    printf "P6\n64 64\n255\n"; s = 12345
    for (y = 0; y < 32; y++) for (x = 0; x < 32; x++) for (c = 0; c < 3; c++) {
        s = (s * 16807) % 2147483647; v[y, x, c] = 1 + int(s / 2147483647 * 255)
    }
    for (y = 0; y < 64; y++) for (x = 0; x < 64; x++) for (c = 0; c < 3; c++)
        printf "%c", v[y < 32 ? y : 63 - y, x < 32 ? x : 63 - x, c]
}' >noise.ppm
expect_ok "hpm with an image that tiles" hpm ../in/spheretri.obj noise.ppm seamless --rotations 3
check "hpm with an image that tiles: one note naming it and --toroidal" "1 line '... tiles ...: --toroidal'" "$ERR" \
    "$(printf '%s' "$ERR" | grep -c "noise.ppm tiles (its opposite edges continue each other): --toroidal" | grep -qx 1; echo $?)"
expect_ok "hpm --toroidal with an image that tiles" hpm ../in/spheretri.obj noise.ppm wrapped --rotations 3 --toroidal
check "hpm --toroidal: no note about tiling" "no 'tiles (' in stderr" "$ERR" \
    "$(! printf '%s' "$ERR" | grep -q "tiles (its opposite"; echo $?)"
expect_ok "hpm with a photo that does not tile" hpm ../in/spheretri.obj ../in/lap256.png bounded --rotations 3
check "hpm with a photo that does not tile: no note about tiling" "no 'tiles (' in stderr" "$ERR" \
    "$(! printf '%s' "$ERR" | grep -q "tiles (its opposite"; echo $?)"
cd "$W" || exit 1
permissive_case hpm lap.png --rotations 3

# --up: each cluster turned so that the image's up follows the direction field;
# the summary says how level it lies on the walls (the torus's axis is z; on this
# coarse torus and a bounded 64x64 image about 60 % of the wall faces lie within
# 10 degrees, against about 1 in 9 for random turns)
newdir
expect_ok "hpm --up z" hpm ../in/torus.obj ../in/lap.png out --rotations 3 --seed 2 --up z
LEVEL=$(printf '%s\n' "$OUT" | sed -nE "s/^level: the image's up ([0-9.]+)% of ([0-9]+) wall faces within 10 degrees of --up, mean [0-9.]+, p90 [0-9.]+ degrees; its rows \(courses\) [0-9.]+%, mean [0-9.]+, p90 [0-9.]+$/\1 \2/p")
check "hpm --up z: summary 'level: the image's up P% of N wall faces ...', P >= 40, N > 0" "P >= 40, N > 0" \
    "${LEVEL:-no level line}: $OUT" "$(read -r p n <<<"$LEVEL"; awk -v p="${p:-0}" -v n="${n:-0}" 'BEGIN { exit !(p >= 40 && n > 0) }'; echo $?)"
check "hpm --up z: other coordinates than without" "files differ" "identical" \
    "$(! cmp -s out.obj "$HPM_TORUS/out.obj"; echo $?)"
check "hpm without --up: no level line" "no 'level:' in the summary of the run without --up" "$HPM_TORUS_OUT" \
    "$(! printf '%s\n' "$HPM_TORUS_OUT" | grep -q '^level:'; echo $?)"
expect_ok "hpm --constraints" hpm ../in/torus.obj ../in/lap.png cons --rotations 3 --constraints ../in/constraints.txt
check "hpm --constraints: says how level, against y" "'level: ...'" "$OUT" \
    "$(printf '%s' "$OUT" | grep -q '^level: the image'"'"'s up'; echo $?)"
expect_error "hpm --constraints face out of range" hpm ../in/torus.obj ../in/lap.png out --rotations 3 \
    --constraints ../in/constraints_range.txt
err_mentions "hpm constraint out of range: FILE:LINE" 'constraints_range\.txt:2:'

# tile --up: each quad's tile turned along the field, upright, with a left or
# right side plain where it meets a quad that sees the edge as its bottom or
# top, in an atlas of four sets twice as wide and twice as tall. The torus's axis
# is y: with --up y its grid runs along the field and every quad is upright; the
# double torus's vertices of valence 3, 5 and 6 turn the field past quads'
# diagonals: there sides are plain, and most quads keep upright tiles.
newdir
expect_ok "tile (no --up) for --up" tile ../in/torus.obj ../in/lap256.png flat --colors 2 --tile 32
TILE_FLAT_OUT=$OUT
expect_ok "tile --up y" tile ../in/torus.obj ../in/lap256.png out --colors 2 --tile 32 --up y
check "tile --up y: every quad of the torus upright" "'up: 512 quads' tiles turned ..., 512 upright, 0 with one side plain and 0 plain'" \
    "$OUT" "$(printf '%s\n' "$OUT" | grep -q "^up: 512 quads' tiles turned along the field, 512 upright, 0 with one side plain and 0 plain"; echo $?)"
check "tile --up y: the atlas twice as wide and twice as tall" "$(($(png_size flat.png | cut -d' ' -f1) * 2)) $(($(png_size flat.png | cut -d' ' -f2) * 2))" \
    "$(png_size out.png)" \
    "$([ "$(png_size out.png)" = "$(($(png_size flat.png | cut -d' ' -f1) * 2)) $(($(png_size flat.png | cut -d' ' -f2) * 2))" ]; echo $?)"
check "tile --up y: other coordinates than without" "files differ" "identical" \
    "$(! cmp -s out.obj flat.obj; echo $?)"
check "tile without --up: no up line" "no 'up:' in the summary" "$TILE_FLAT_OUT" \
    "$(! printf '%s\n' "$TILE_FLAT_OUT" | grep -q '^up:'; echo $?)"
SEAM_UP=$(printf '%s\n' "$OUT" | sed -nE 's/.*seam score (-?[0-9.]+) .*/\1/p')
check "tile --up y: seams still match (score below 0.1)" "below 0.1" "${SEAM_UP:-none}: $OUT" \
    "$(awk -v s="${SEAM_UP:-9}" 'BEGIN { exit !(s < 0.1) }'; echo $?)"
expect_ok "tile --up z on the double torus" tile ../in/double-torus.obj ../in/lap256.png dt --colors 2 --tile 32 --up z
UPRIGHT=$(printf '%s\n' "$OUT" | sed -nE "s/^up: [0-9]+ quads' tiles turned along the field, ([0-9]+) upright, ([0-9]+) with one side plain and ([0-9]+) plain.*/\1 \2 \3/p")
check "tile --up z on the double torus: quads upright, some with a side plain, fewer plain" \
    "upright and one-side-plain above 0, their sum above the plain" "${UPRIGHT:-no up line}" \
    "$(read -r u o p <<<"$UPRIGHT"; [ "${u:-0}" -gt 0 ] && [ "${o:-0}" -gt 0 ] && [ $((${u:-0} + ${o:-0})) -gt "${p:-0}" ]; echo $?)"
expect_ok "tile --up z --format glb" tile ../in/torus.obj ../in/lap256.png g.glb --colors 2 --tile 32 --up z
expect_ok "tile --up z --mips" tile ../in/torus.obj ../in/lap256.png m --tile 32 --up z --mips
check "tile --up z --mips: mip levels twice as wide" "$(($(png_size m.png | cut -d' ' -f1) / 2)) ..." \
    "$(png_size m_mip1.png)" "$([ "$(png_size m_mip1.png | cut -d' ' -f1)" = "$(($(png_size m.png | cut -d' ' -f1) / 2))" ]; echo $?)"
expect_ok "tile --constraints" tile ../in/torus.obj ../in/lap256.png cons --tile 32 --constraints ../in/constraints.txt
check "tile --constraints: an up line" "'up: ...'" "$OUT" "$(printf '%s\n' "$OUT" | grep -q '^up: '; echo $?)"
expect_ok "tile --constraints on triangles (faces of the OBJ, before quadrangulation)" tile ../in/spheretri.obj \
    ../in/lap256.png tri --tile 32 --constraints ../in/constraints.txt
check "tile --constraints on triangles: 3840 quads turned" "'up: 3840 quads' ...'" "$OUT" \
    "$(printf '%s\n' "$OUT" | grep -q "^up: 3840 quads' tiles turned"; echo $?)"
expect_error "tile --constraints face out of range" tile ../in/torus.obj ../in/lap256.png out --tile 32 \
    --constraints ../in/constraints_range.txt
err_mentions "tile constraint out of range: FILE:LINE" 'constraints_range\.txt:2:'
# tile --remesh: the icosphere's triangles would make kites whose tiles turn
# every way; remeshed along the field its walls get rows of level quads.
newdir
expect_ok "tile --up y on the icosphere's triangles, no remesh" tile ../in/spheretri.obj ../in/lap256.png kites \
    --tile 32 --up y
LEVEL_KITES=$(printf '%s\n' "$OUT" | sed -nE 's/^level: the image.s up ([0-9.]+)% .*/\1/p')
expect_ok "tile --up y --remesh auto" tile ../in/spheretri.obj ../in/lap256.png rm --tile 32 --up y --remesh auto
LEVEL_REMESH=$(printf '%s\n' "$OUT" | sed -nE 's/^level: the image.s up ([0-9.]+)% .*/\1/p')
ROWS_REMESH=$(printf '%s\n' "$OUT" | sed -nE 's/^level: .*; its rows \(courses\) ([0-9.]+)%, mean [0-9.]+, p90 [0-9.]+$/\1/p')
check "tile --remesh: the rows (courses) level too (90 % within 10 degrees)" "rows >= 90" \
    "rows ${ROWS_REMESH:-none}" "$(awk -v r="${ROWS_REMESH:-0}" 'BEGIN { exit !(r >= 90) }'; echo $?)"
check "tile --remesh: walls level (90 % within 10 degrees), the kites far from it" \
    "remesh >= 90, kites < 60" "remesh ${LEVEL_REMESH:-none}, kites ${LEVEL_KITES:-none}" \
    "$(awk -v r="${LEVEL_REMESH:-0}" -v k="${LEVEL_KITES:-100}" 'BEGIN { exit !(r >= 90 && k < 60) }'; echo $?)"
err_mentions "tile --remesh: the note says what the remesh made" \
    'remeshed along the field into [0-9]+ quads of side about [0-9.]+ \(from a lattice of [0-9]+ quads?, [0-9]+ triangles?'
check "tile --remesh: a closed genus-0 surface of quads" "genus 0, 1 component, 0 boundary loops" "$OUT" \
    "$(printf '%s\n' "$OUT" | grep -q '^\.\./in/spheretri\.obj: [0-9]* quads, [0-9]* vertices, genus 0, 1 component, 0 boundary loops'; echo $?)"
check "tile --remesh: the OBJ holds quads only" "every f line 4 corners" "$(awk '/^f /{print NF-1}' rm.obj | sort -u | tr '\n' ' ')" \
    "$([ "$(awk '/^f /{print NF-1}' rm.obj | sort -u)" = "4" ]; echo $?)"
ON_SPHERE=$(awk '/^v /{ r = sqrt($2*$2 + $3*$3 + $4*$4); if (r < lo || NR == 1 || lo == "") lo = r; if (r > hi) hi = r }
    END { printf "%.4f %.4f", lo, hi }' rm.obj)
check "tile --remesh: vertices on or just inside the icosphere (radius 1 at its vertices)" "0.97 .. 1.0001" \
    "$ON_SPHERE" "$(read -r lo hi <<<"$ON_SPHERE"; awk -v a="$lo" -v b="$hi" 'BEGIN { exit !(a >= 0.97 && b <= 1.0001) }'; echo $?)"
expect_ok "tile --remesh 0.1: smaller quads" tile ../in/spheretri.obj ../in/lap256.png rm2 --tile 32 --up y --remesh 0.1
check "tile --remesh 0.1: larger quads than auto's (0.043), so fewer" "fewer quads than auto's" \
    "$(grep -c '^f ' rm2.obj) vs $(grep -c '^f ' rm.obj)" "$([ "$(grep -c '^f ' rm2.obj)" -lt "$(grep -c '^f ' rm.obj)" ]; echo $?)"
expect_ok "tile --remesh without --up (the library's +y)" tile ../in/spheretri.obj ../in/lap256.png rm3 --tile 32 \
    --remesh auto
expect_ok "tile --remesh --format glb" tile ../in/spheretri.obj ../in/lap256.png rm4.glb --tile 32 --up y --remesh auto
expect_error "tile --remesh 0" tile ../in/spheretri.obj ../in/lap256.png bad --tile 32 --remesh 0
err_mentions "tile --remesh 0: what it wants" "remesh wants the quads' side in mesh units \\(above 0\\) or 'auto'"
expect_error "tile --remesh with no value" tile ../in/spheretri.obj ../in/lap256.png bad --tile 32 --remesh
expect_error "tile --remesh larger than the mesh" tile ../in/spheretri.obj ../in/lap256.png bad --tile 32 --remesh 5
err_mentions "tile --remesh 5: too large" 'remesh 5: edge_length 5 is more than an eighth'
expect_error "tile --remesh --constraints" tile ../in/spheretri.obj ../in/lap256.png bad --tile 32 --remesh auto \
    --constraints ../in/constraints.txt
err_mentions "tile --remesh --constraints: refused" "remesh follows --up: not with --constraints"
# A photo laid in courses (bricks 15 rows apart, each course's head joints at
# their own offset, grain from an LCG): with --up, tile and polycube resample
# it so that a tile holds a whole number of courses and cut every tile on
# them, and say so; --no-courses, plain tiles and a photo without courses
# leave it as it is.
newdir
awk 'BEGIN { w = 192; h = 192; p = 15; seed = 7; printf "P5\n%d %d\n255\n", w, h
    for (y = 0; y < h; y++) {
        c = int((y + 0.5 - 5) / p + 0.5); m = (y + 0.5 - 5) / p - c; if (m < 0) m = -m
        off = ((c * 7919 + 13) % 97) / 97
        for (x = 0; x < w; x++) {
            a = x / 33 + off; b = int(a); seed = (seed * 1103515245 + 12345) % 2147483648
            v = (m * p < 1.5 || (a - b) * 33 < 2.5) ? 215 : 80 + (b * 31 + c * 17) % 60
            printf "%c", v + int(seed / 2147483648 * 30) } } }' >bricks.pgm
expect_ok "tile --up y on bricks" tile ../in/torus.obj bricks.pgm courses --colors 2 --tile 32 --up y
err_mentions "tile --up on bricks: the courses found, the photo resampled" \
    'bricks\.pgm has courses every 1[45]\.[0-9] texels: resampled by 1\.0[0-9]* so that a 32-texel tile holds 2'
expect_ok "tile --up y --no-courses on bricks" tile ../in/torus.obj bricks.pgm asis --colors 2 --tile 32 --up y \
    --no-courses
check "tile --no-courses: no word of courses" "no 'courses' on stderr" "$ERR" \
    "$(! printf '%s' "$ERR" | grep -q courses; echo $?)"
check "tile --up on bricks: --no-courses makes another atlas" "files differ" "identical" \
    "$(! cmp -s courses.png asis.png; echo $?)"
expect_ok "tile (no --up) on bricks" tile ../in/torus.obj bricks.pgm plain --colors 2 --tile 32
check "tile without --up: the photo as it is" "no 'courses every' on stderr" "$ERR" \
    "$(! printf '%s' "$ERR" | grep -q 'courses every'; echo $?)"
err_mentions "tile without --up on bricks: one note that --up keeps the courses level" \
    'bricks\.pgm has courses \(bricks, blocks laid in rows\): without --up each tile follows its quad.*--up gives'
for pipeline in lapped hpm polycube; do
    case $pipeline in
        polycube) extra=(--resolution 6 --tile 32) ;;
        *) extra=() ;;
    esac
    expect_ok "$pipeline without --up on bricks" $pipeline ../in/spheretri.obj bricks.pgm noup "${extra[@]}"
    check "$pipeline without --up on bricks: one note on the courses and --up" "one 'has courses (bricks' line" \
        "$ERR" "$([ "$(printf '%s\n' "$ERR" | grep -c 'has courses (bricks')" -eq 1 ]; echo $?)"
    expect_ok "$pipeline --up y on bricks" $pipeline ../in/spheretri.obj bricks.pgm up "${extra[@]}" --up y
    check "$pipeline --up y on bricks: no note on --up" "no 'has courses (bricks' line" "$ERR" \
        "$(! printf '%s' "$ERR" | grep -q 'has courses (bricks'; echo $?)"
done
expect_ok "hpm without --up on stones" hpm ../in/spheretri.obj ../in/lap256.png noup_stones
check "hpm on a photo without courses: no note on --up" "no 'has courses (bricks' line" "$ERR" \
    "$(! printf '%s' "$ERR" | grep -q 'has courses (bricks'; echo $?)"
expect_ok "tile --up y on stones" tile ../in/torus.obj ../in/lap256.png stones --colors 2 --tile 32 --up y
check "tile --up on a photo without courses: none found" "no 'courses' on stderr" "$ERR" \
    "$(! printf '%s' "$ERR" | grep -q courses; echo $?)"
expect_ok "polycube on bricks" polycube ../in/spheretri.obj bricks.pgm pc --resolution 6 --tile 32
err_mentions "polycube on bricks: the walls' courses kept" 'bricks\.pgm has courses every'
expect_ok "polycube --no-courses on bricks" polycube ../in/spheretri.obj bricks.pgm pcn --resolution 6 --tile 32 \
    --no-courses
check "polycube --no-courses: no word of courses" "no 'courses' on stderr" "$ERR" \
    "$(! printf '%s' "$ERR" | grep -q courses; echo $?)"
# Courses 40 texels apart, and squares that would show 16 texels of the
# photo: each square shows a course's texels instead of the photo shrunk.
awk 'BEGIN { w = 256; h = 256; p = 40; printf "P5\n%d %d\n255\n", w, h
    for (y = 0; y < h; y++) {
        c = int(y / p); m = y - c * p
        for (x = 0; x < w; x++) {
            a = int((x + 37 * c) / 64); v = (m < 4 || (x + 37 * c) % 64 < 4) ? 220 : 70 + (a * 29 + c * 13) % 70
            printf "%c", v } } }' >bricks40.pgm
expect_ok "polycube on 40-texel courses, squares of 16 texels" polycube ../in/spheretri.obj bricks40.pgm big \
    --tile 32 --texture-size 100
err_mentions "polycube, squares smaller than a course: shows a course's texels, and says so" \
    'would show [0-9.e+-]+ texels of bricks40\.pgm, fewer than one of its courses \(40\.0\); shows 40, a course'
err_mentions "polycube, squares smaller than a course: the photo is not shrunk" \
    'courses every 40\.0 texels(: resampled by 1(\.00[0-9]*)? so that a|, 1 to a) 40-texel tile'
expect_error "tile --up 0,0,0" tile ../in/torus.obj ../in/lap256.png out --tile 32 --up 0,0,0
expect_error "tile --up without a value" tile ../in/torus.obj ../in/lap256.png out --tile 32 --up
expect_error "tile --up with an atlas too wide for four sets" tile ../in/torus.obj ../in/lap256.png out --colors 4 \
    --tile 72 --gutter 0 --up z
err_mentions "tile --up atlas too wide: says why" 'plain and upright'
expect_error "hpm --constraints missing file" hpm ../in/torus.obj ../in/lap.png out --constraints ../in/nope.txt
# A bounded image keeps a texel's margin round every coordinate: 2 x 2 has
# none to give (the error once blamed the mesh's "scale 0"); tiling, it maps.
{ printf 'P5\n2 2\n255\n'; printf '\000\377\377\000'; } >"$W/in/tiny2.pgm"
expect_error "hpm on a 2 x 2 image" hpm ../in/torus.obj ../in/tiny2.pgm out
err_mentions "hpm on a 2 x 2 image: names the image, its size and the 3 texels it needs" \
    'tiny2\.pgm: hpm: the image is 2 x 2 texels: a bounded image needs at least 3 on each side'
newdir
expect_ok "hpm on a 2 x 2 image --toroidal" hpm ../in/torus.obj ../in/tiny2.pgm tiny --toroidal
cd "$W" || exit 1
expect_error "hpm --up 0,0,0" hpm ../in/torus.obj ../in/lap.png out --up 0,0,0

# the same seed twice: the same file; another seed: another result
newdir
expect_ok "hpm seed 2 again" hpm ../in/torus.obj ../in/lap.png out --rotations 3 --seed 2
CMD="tiledtex hpm ../in/torus.obj ../in/lap.png out --rotations 3 --seed 2 (twice)"
check "hpm same seed twice: identical .obj" "cmp equal" "$(cmp out.obj "$HPM_TORUS/out.obj" 2>&1)" \
    "$(cmp -s out.obj "$HPM_TORUS/out.obj"; echo $?)"
expect_ok "hpm seed 3" hpm ../in/torus.obj ../in/lap.png other --rotations 3 --seed 3
check_normals "hpm" other.obj
CMD="tiledtex hpm ../in/torus.obj ../in/lap.png out --rotations 3 --seed 2 / --seed 3"
check "hpm different seed: different .obj" "files differ" "identical" "$(! cmp -s out.obj other.obj; echo $?)"
# the result renders with the image itself as its texture
expect_ok "render an hpm OBJ" render out.obj ../in/lap.png view.png --size 160x120
check "render hpm OBJ: 160x120 PNG" "160 120" "$(png_size view.png)" \
    "$(is_png view.png && [ "$(png_size view.png)" = "160 120" ]; echo $?)"
# outputs elsewhere: the MTL still finds the image, also from a directory reached with ".."
mkdir -p sub images run
cp ../in/lap.png images/stones.png
expect_ok "hpm into a subdirectory" hpm ../in/torus.obj images/stones.png sub/out --rotations 3
check "hpm into a subdirectory: map_Kd finds the image from sub/" "sub/<map_Kd> is images/stones.png" \
    "$(grep map_Kd sub/out.mtl 2>&1)" \
    "$(cmp -s "sub/$(awk '$1 == "map_Kd" { print $2 }' sub/out.mtl 2>/dev/null)" images/stones.png; echo $?)"
cd run || exit 1
expect_ok "hpm into ../sub from another directory" hpm ../../in/torus.obj ../images/stones.png ../sub/up --rotations 3
check "hpm into ../sub: map_Kd names the copy beside it" "map_Kd up.png" "$(grep map_Kd ../sub/up.mtl 2>&1)" \
    "$(grep -qE '^map_Kd +up\.png$' ../sub/up.mtl 2>/dev/null && cmp -s ../sub/up.png ../images/stones.png; echo $?)"
# --reference-image: no copy, the MTL names IMAGE relative to itself, from a directory reached with ".."
expect_ok "hpm --reference-image into ../sub" hpm ../../in/torus.obj ../images/stones.png ../sub/ref --rotations 3 \
    --reference-image
check "hpm --reference-image: map_Kd ../images/stones.png, no copy" "map_Kd ../images/stones.png" \
    "$(grep map_Kd ../sub/ref.mtl 2>&1)" \
    "$(grep -qE '^map_Kd +\.\./images/stones\.png$' ../sub/ref.mtl 2>/dev/null && [ ! -e ../sub/ref.png ]; echo $?)"
cd .. || exit 1
# absolute paths too: relative to the MTL, so sub/ and images/ can move together
expect_ok "hpm --reference-image with an absolute IMAGE and OUT_PREFIX" hpm ../in/torus.obj "$PWD/images/stones.png" \
    "$PWD/sub/abs" --rotations 3 --reference-image
check "hpm absolute paths: map_Kd ../images/stones.png, mtllib abs.mtl" "map_Kd ../images/stones.png, mtllib abs.mtl" \
    "$(grep -h -E '^(map_Kd|mtllib)' sub/abs.mtl sub/abs.obj 2>&1)" \
    "$(grep -qx 'map_Kd ../images/stones.png' sub/abs.mtl 2>/dev/null && grep -qx 'mtllib abs.mtl' sub/abs.obj; echo $?)"
# IMAGE that is the copy's own name already (OUT_PREFIX.png beside the OBJ) is named, not copied over
cp images/stones.png sub/same.png
expect_ok "hpm with IMAGE at OUT_PREFIX.png" hpm ../in/torus.obj sub/same.png sub/same --rotations 3
check "hpm IMAGE at OUT_PREFIX.png: named as it is" "map_Kd same.png, the file unchanged" "$(grep map_Kd sub/same.mtl 2>&1)" \
    "$(grep -qx 'map_Kd same.png' sub/same.mtl && cmp -s sub/same.png images/stones.png; echo $?)"
# a JPEG is copied as a JPEG, byte for byte
if command -v convert >/dev/null 2>&1 && convert images/stones.png images/stones.jpg 2>/dev/null; then
    expect_ok "hpm with a JPEG IMAGE" hpm ../in/torus.obj images/stones.jpg sub/jp --rotations 3
    check "hpm JPEG IMAGE: copied as sub/jp.jpg" "map_Kd jp.jpg, the same bytes" "$(grep map_Kd sub/jp.mtl 2>&1)" \
        "$(grep -qx 'map_Kd jp.jpg' sub/jp.mtl && cmp -s sub/jp.jpg images/stones.jpg; echo $?)"
fi
# the folder moved: the MTL still finds its texture
mv sub moved
check "hpm output folder moved: map_Kd still names a file beside the MTL" "moved/up.png" "$(ls moved)" \
    "$([ -s "moved/$(awk '$1 == "map_Kd" { print $2 }' moved/up.mtl)" ]; echo $?)"
cd "$W" || exit 1

# bad inputs: one line, non-zero exit, no files
expect_error "hpm missing mesh" hpm ../in/nope.obj ../in/lap.png out
err_mentions "hpm missing mesh: names the file" 'nope\.obj'
expect_error "hpm missing image" hpm ../in/torus.obj ../in/nope.png out
err_mentions "hpm missing image: names the file" 'nope\.png'
expect_error "hpm image not an image" hpm ../in/torus.obj ../in/torus.obj out
expect_error "hpm --rotations 0" hpm ../in/torus.obj ../in/lap.png out --rotations 0
expect_error "hpm --rotations 65" hpm ../in/torus.obj ../in/lap.png out --rotations 65
expect_error "hpm --threshold -1" hpm ../in/torus.obj ../in/lap.png out --threshold -1
expect_error "hpm --threshold 0" hpm ../in/torus.obj ../in/lap.png out --threshold 0
expect_error "hpm --threshold abc" hpm ../in/torus.obj ../in/lap.png out --threshold abc
expect_error "hpm --threshold nan" hpm ../in/torus.obj ../in/lap.png out --threshold nan
expect_error "hpm --scale -1" hpm ../in/torus.obj ../in/lap.png out --scale -1
expect_error "hpm --scale 0" hpm ../in/torus.obj ../in/lap.png out --scale 0
expect_error "hpm --band 0" hpm ../in/torus.obj ../in/lap.png out --band 0
expect_error "hpm --max-turn 0" hpm ../in/torus.obj ../in/lap.png out --max-turn 0
expect_error "hpm --max-turn 181" hpm ../in/torus.obj ../in/lap.png out --max-turn 181
expect_error "hpm --seed abc" hpm ../in/torus.obj ../in/lap.png out --seed abc
expect_error "hpm zero-area face" hpm ../in/lapped_degenerate.obj ../in/lap.png out
err_mentions "hpm zero-area face: FILE:LINE and face 1" 'lapped_degenerate\.obj:5: face 1 '
expect_error "hpm OBJ truncated mid face line" hpm ../in/truncated_face.obj ../in/lap.png out

# ======================================================================
# Polycube + Wang tiles
# ======================================================================
# polycube_obj_report OBJ TILE GUTTER ATLAS_WIDTH ATLAS_HEIGHT ->
#   "faces nontri corners nvt badc unused outside straddling":
#   f lines, f lines without 3 corners, corners, vt lines, corners whose v or
#   vt index is missing or out of range, vt lines no corner uses, vt values that are not numbers in [0,1], and triangles whose three vt
#   do not fall in one tile of the atlas (cells of TILE + 2 GUTTER texels from its top left, the
#   corners within the TILE x TILE square inside the gutter).
polycube_obj_report() {
    awk -v s="$2" -v g="$3" -v aw="$4" -v ah="$5" '
        function isnum(x) { return x ~ /^[-+]?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][-+]?[0-9]+)?$/ }
        BEGIN { cell = s + 2 * g }
        $1 == "v"  { nv++ }
        $1 == "vt" { nvt++; u[nvt] = $2; v[nvt] = $3
                     for (i = 2; i <= 3; i++)
                         if (!isnum($i) || $i + 0 < 0 || $i + 0 > 1) outside++ }
        $1 == "f"  { nf++
                     if (NF - 1 != 3) nontri++
                     for (i = 2; i <= NF; i++) { corners++; c[corners] = $i; cf[corners] = nf } }
        END {
            for (k = 1; k <= corners; k++) {
                m = split(c[k], p, "/")
                if (m < 2 || p[1] !~ /^[0-9]+$/ || p[2] !~ /^[0-9]+$/ ||
                    p[1] + 0 < 1 || p[1] + 0 > nv || p[2] + 0 < 1 || p[2] + 0 > nvt) { badc++; continue }
                t = p[2] + 0
                uses[t]++
                x = u[t] * aw; y = (1 - v[t]) * ah
                key = int(x / cell) "," int(y / cell)
                # Inside the tile proper: the gutter is for filtering only.
                if (x - int(x / cell) * cell < g - 0.01 || x - int(x / cell) * cell > g + s + 0.01 ||
                    y - int(y / cell) * cell < g - 0.01 || y - int(y / cell) * cell > g + s + 0.01)
                    if (!(cf[k] in straddles)) { straddles[cf[k]] = 1; straddling++ }
                if (!(cf[k] in tile)) tile[cf[k]] = key
                else if (tile[cf[k]] != key && !(cf[k] in straddles)) { straddles[cf[k]] = 1; straddling++ }
            }
            for (k = 1; k <= nvt; k++) if (uses[k] < 1) unused++
            printf "%d %d %d %d %d %d %d %d\n", nf, nontri, corners, nvt, badc, unused, outside, straddling
        }' "$1" 2>/dev/null
}

# polycube_case NAME MESH COLORS ARGS... : in a fresh directory, polycube with
# 16-texel tiles writes exactly out.obj, out.mtl, out.png, out_polycube.obj;
# the OBJ holds at least the mesh's triangle fans, each corner's vt inside its
# triangle's tile; the polycube's surface is quads with tile UVs; the summary has its lines.
polycube_case() {
    local name=$1 mesh=$2 colors=$3 faces nontri corners nvt badc unused outside straddling want shown aw ah
    shift 3
    newdir
    run polycube "../in/$mesh" ../in/tex.png out --tile 16 --colors "$colors" "$@"
    check "polycube $name: exit status" "0" "exit $RC, stderr: $ERR" "$([ $RC -eq 0 ]; echo $?)"
    check "polycube $name: exactly out.mtl, out.obj, out.png, out_polycube.obj" \
        "out.mtl out.obj out.png out_polycube.obj" "$(ls -A | tr '\n' ' ')" \
        "$([ "$(ls -A | tr '\n' ' ')" = "out.mtl out.obj out.png out_polycube.obj " ]; echo $?)"
    check "polycube $name: mtl names the atlas, both OBJs the mtl" "map_Kd out.png, mtllib out.mtl twice" \
        "$(grep -h -E 'map_|mtllib' out.mtl out.obj out_polycube.obj 2>&1)" \
        "$(grep -qE '^map_Kd +out\.png$' out.mtl 2>/dev/null && grep -qE '^mtllib +out\.mtl$' out.obj 2>/dev/null &&
            grep -qE '^mtllib +out\.mtl$' out_polycube.obj 2>/dev/null; echo $?)"
    # The compact atlas: the smallest power-of-two square or 2:1 rectangle
    # of 24-texel cells holding the tiles the summary says S shows.
    shown=$(printf '%s' "$OUT" | sed -nE 's/^tiles: ([0-9]+) of the .*/\1/p')
    read -r aw ah <<<"$(png_size out.png)"
    check "polycube $name: a power-of-two atlas just holding the $shown tiles shown" \
        "WxW or 2WxW, W a power of two, the half size too small" "${aw}x$ah, $shown tiles" \
        "$(is_png out.png && [ -n "$shown" ] && [ $((aw & (aw - 1))) = 0 ] && [ $((ah & (ah - 1))) = 0 ] &&
            { [ "$aw" = "$ah" ] || [ "$aw" = $((2 * ah)) ]; } &&
            [ $(((aw / 24) * (ah / 24))) -ge "$shown" ] &&
            if [ "$aw" = "$ah" ]; then [ $(((aw / 24) * (aw / 48))) -lt "$shown" ];
            else [ $(((ah / 24) * (ah / 24))) -lt "$shown" ]; fi; echo $?)"
    read -r faces nontri corners nvt badc unused outside straddling \
        <<<"$(polycube_obj_report out.obj 16 4 $(png_size out.png))"
    want=$(fan_triangles "$W/in/$mesh")
    check "polycube $name: triangles, at least the mesh's $want" ">= $want triangle f lines" \
        "$faces f lines, $nontri not triangles" \
        "$([ "${faces:-0}" -ge "$want" ] && [ "${nontri:-1}" = 0 ]; echo $?)"
    check "polycube $name: a vt for each face corner, equal ones shared" \
        "corners = 3 x faces, 1 <= vt lines <= corners, 0 bad, 0 unused" \
        "$nvt vt, $corners corners, $badc bad corners, $unused vt unused" \
        "$([ "${corners:-0}" = $((3 * ${faces:-0})) ] && [ "${nvt:-0}" -ge 1 ] && [ "${nvt:-0}" -le "${corners:-0}" ] &&
            [ "${badc:-1}" = 0 ] && [ "${unused:-1}" = 0 ]; echo $?)"
    check "polycube $name: UVs in [0,1]" "0 bad vt values" "$outside" "$([ "${outside:-1}" = 0 ]; echo $?)"
    check "polycube $name: each triangle's three vt in one tile" "0 triangles across tiles" "$straddling" \
        "$([ "${straddling:-1}" = 0 ]; echo $?)"
    [ -f out_polycube.obj ] && check_obj "polycube $name: out_polycube.obj" out_polycube.obj
    check "polycube $name: summary" "'polycube: N cubes', 'mapping: N triangles, N split, N fallback, N failed edges', \
'stretch: p5 X, median Y, p95 Z; texel density p5 A, p95 B of its median', 'seam score: tile borders X (...); all edges Y', 'time: build'" "$OUT" \
        "$(printf '%s' "$OUT" | grep -qE '; polycube: [0-9]+ cubes of [0-9.e+-]+ units \(resolution [0-9]+\), [0-9]+ quads, [0-9]+ components?, genus [0-9]+' &&
            printf '%s' "$OUT" | grep -qE '^mapping: [0-9]+ triangles, [0-9]+ split, [0-9]+ fallback, [0-9]+ failed edges, [0-9]+ flipped' &&
            printf '%s' "$OUT" | grep -qE '^stretch: p5 [0-9.]+, median [0-9.]+, p95 [0-9.]+; texel density p5 [0-9.]+, p95 [0-9.]+ of its median; ' &&
            printf '%s' "$OUT" | grep -qE '^seam score: tile borders -?[0-9.]+ \([0-9]+ of [0-9]+ border edges( sampled)?\); all edges -?[0-9.]+ ' &&
            printf '%s' "$OUT" | grep -qE '^time: build [0-9.]+ s, synthesis [0-9.]+ s, mapping [0-9.]+ s$'; echo $?)"
    # A number (or n/a, on these small smooth tiles); its size is judged on
    # real photos, where 16-texel tiles are not used.
    check "polycube $name: the seam score near the squares' corners" \
        "'near the squares' corners (within 5 % of an edge's ends) X (N of N square edges)' or 'n/a: ...'" "$OUT" \
        "$(printf '%s' "$OUT" | grep -qE "^seam score: .*; near the squares' corners \(within 5 % of an edge's ends\) (-?[0-9.]+ \([0-9]+ of [0-9]+ square edges( sampled)?\)|n/a: )"; echo $?)"
    cd "$W" || exit 1
}

polycube_case "sphere-triangles" spheretri.obj 2 --resolution 8
POLYCUBE_SPHERE=$W/d$NEWDIR_N
check "polycube sphere: genus 0 as the mesh" "'genus 0 (as the mesh)'" "$OUT" \
    "$(printf '%s' "$OUT" | grep -q 'genus 0 (as the mesh)'; echo $?)"
check "polycube sphere: no note about cuts (none beyond 0.1 %)" "no 'no seamless place' on stderr" "$ERR" \
    "$(printf '%s' "$ERR" | grep -q 'no seamless place'; [ $? -ne 0 ]; echo $?)"
check "polycube sphere: of the paper's 256 tiles in four sets, those shown" "'tiles: N of the 4 x 256 shown (n=2, 16 texels, gutter 4; upright, plain on a top's side beside a wall), in a WxH atlas (all would take 768x768)'" "$OUT" \
    "$(printf '%s' "$OUT" | grep -qE "^tiles: [0-9]+ of the 4 x 256 shown \(n=2, 16 texels, gutter 4; upright, plain on a top's side beside a wall\), in a [0-9]+x[0-9]+ atlas \(all would take 768x768\)"; echo $?)"
SQUARES=$(printf '%s\n' "$OUT" | sed -nE 's/^squares: ([0-9]+) walls upright; ([0-9]+) tops and bottoms: ([0-9]+) upright, ([0-9]+) with one side plain \(beside a wall\), ([0-9]+) plain$/\1 \2 \3 \4 \5/p')
QUADS=$(printf '%s\n' "$OUT" | sed -nE 's/.* ([0-9]+) quads, 1 component.*/\1/p')
check "polycube sphere: the squares' tiles, walls and tops, add up to the quads" \
    "'squares: W walls upright; T tops and bottoms: U upright, O with one side plain (beside a wall), P plain', W + T = $QUADS, U + O + P = T, U > 0, O > 0" \
    "${SQUARES:-no squares line}" \
    "$(read -r w t u o p <<<"$SQUARES"; [ -n "$p" ] && [ $((w + t)) -eq "${QUADS:-0}" ] && [ $((u + o + p)) -eq "$t" ] &&
        [ "$u" -gt 0 ] && [ "$o" -gt 0 ]; echo $?)"
expect_error "polycube --max-atlas below the tiles shown" polycube ../in/spheretri.obj ../in/tex.png out --tile 16 \
    --resolution 8 --max-atlas 64
check "polycube --max-atlas 64: says the size the tiles need and what helps" \
    "'need a WxH atlas, above max_size 64 ...; here: a larger --max-atlas, ...'" "$ERR" \
    "$(printf '%s' "$ERR" | grep -qE 'need a [0-9]+ x [0-9]+ atlas, above max_size 64.*; here: a larger --max-atlas, --colors 1 or a smaller --tile$'; echo $?)"
# --max-atlas 300: the largest power-of-two square within it, 256, holds 10 x 10 cells of 24 texels; the squares
# (167 tiles shown without the limit) are given as few tiles as that, and the atlas stays within 300.
newdir
run polycube ../in/spheretri.obj ../in/tex.png out --tile 16 --resolution 8 --no-upright --max-atlas 300
check "polycube --max-atlas 300: at most 100 tiles, in an atlas within 300 texels a side" \
    "exit 0, 'tiles: N of', N <= 100, PNG sides <= 300" "exit $RC, $(printf '%s' "$OUT" | grep '^tiles:'), $(png_size out.png)" \
    "$([ $RC -eq 0 ] && n=$(printf '%s' "$OUT" | sed -nE 's/^tiles: ([0-9]+) of the .*/\1/p') && [ -n "$n" ] &&
        [ "$n" -le 100 ] && read -r aw ah <<<"$(png_size out.png)" && [ "$aw" -le 300 ] && [ "$ah" -le 300 ]; echo $?)"
cd "$W" || exit 1
polycube_case "sphere --no-upright" spheretri.obj 2 --resolution 8 --no-upright
check "polycube --no-upright: of one set of 256 tiles, those shown" "'tiles: N of the 256 shown (n=2, 16 texels, gutter 4), in a WxH atlas (all would take 384x384);'" "$OUT" \
    "$(printf '%s' "$OUT" | grep -qE '^tiles: [0-9]+ of the 256 shown \(n=2, 16 texels, gutter 4\), in a [0-9]+x[0-9]+ atlas \(all would take 384x384\);'; echo $?)"
polycube_case "torus (quads as fans)" torus.obj 1 --seed 3
check "polycube torus: says it split the quads into triangles" "'1024 triangles (fans of 512 faces)'" "$OUT" \
    "$(printf '%s' "$OUT" | grep -q '1024 triangles (fans of 512 faces)'; echo $?)"
polycube_case "sphere --cube-size" spheretri.obj 1 --cube-size 0.5
check "polycube --cube-size 0.5: cubes of 0.5 units" "'cubes of 0.5 units'" "$OUT" \
    "$(printf '%s' "$OUT" | grep -q 'cubes of 0.5 units'; echo $?)"
# Two vertices 4e-9 apart: their refined triangles include ones of no area,
# and the mapped triangles with them; the quality report is still computed
# (it was switched off: "not measured").
newdir
printf '%s\n' 'v -0.0617647059 -0.247058824 -0.24509804' 'v 0.0622548983 -0.250980407 -0.250980407' \
    'v 0.205392152 -0.250980407 -0.14705883' 'v 0.062254902 0.249019593 -0.250980407' \
    'v 0.0622548983 0.249019593 -0.250980407' 'v 0.187254906 0.249019593 -0.250980407' \
    'v -0.0627451017 0.749019623 -0.250980407' 'v 0.0622548983 0.749019623 -0.250980407' \
    'v 0.187254906 0.749019623 -0.250980407' 'f 1 2 5' 'f 1 5 4' 'f 2 3 6' 'f 2 6 5' 'f 4 5 8' 'f 4 8 7' \
    'f 5 6 9' 'f 5 9 8' >sliver_strip.obj
expect_ok "polycube on a strip with a sliver" polycube sliver_strip.obj ../in/tex.png out --tile 16 --cube-size 1
check "polycube sliver strip: the stretch and seams are measured" "'stretch: p5 ...' and 'seam score: ...', no 'not measured'" \
    "$OUT" "$(printf '%s' "$OUT" | grep -q '^stretch: p5 ' && printf '%s' "$OUT" | grep -q '^seam score: ' &&
        ! printf '%s' "$OUT" | grep -q 'not measured'; echo $?)"
newdir
expect_ok "polycube torus at resolution 2" polycube ../in/torus.obj ../in/tex.png out --tile 16 --colors 1 --resolution 2
check "polycube torus at resolution 2: warns that the genus differs" \
    "one stderr line 'the polycube has genus 0, the mesh 1 ... raise --resolution'" "$ERR" \
    "$(printf '%s' "$ERR" | grep -c 'the polycube has genus 0, the mesh 1.*raise --resolution' | grep -qx 1; echo $?)"
check "polycube torus at resolution 2: the summary says so" "'genus 0 (the mesh's 1: they differ)'" "$OUT" \
    "$(printf '%s' "$OUT" | grep -q "genus 0 (the mesh's 1: they differ)"; echo $?)"
check "polycube torus at resolution 2: one stderr line says how many triangles show a cut, and what may help" \
    "'N of M triangles (P %) have no seamless place ... try another --resolution'" "$ERR" \
    "$(printf '%s' "$ERR" | grep -cE '[0-9]+ of the [0-9]+ triangles mapped \([0-9.e+-]+ %\) have no seamless place.*--resolution' |
        grep -qx 1; echo $?)"
cd "$W" || exit 1
polycube_case "sphere --up -z --no-correct" spheretri.obj 1 --resolution 6 --up -z --no-correct
polycube_case "sphere --up 1,2,0" spheretri.obj 1 --resolution 6 --up 1,2,0

# an inside-out mesh (every face's corners reversed): mapped reversed, said on stderr, and written outward
awk '$1 == "f" { print "f", $2, $4, $3; next } { print }' "$W/in/spheretri.obj" >"$W/in/spheretri_inward.obj"
# the signed volume of an OBJ's triangles (v and f lines; f corners as v or v/vt): > 0 when they wind outward
obj_volume() {
    awk '$1 == "v" { n++; x[n] = $2; y[n] = $3; z[n] = $4 }
         $1 == "f" { split($2, a, "/"); split($3, b, "/"); split($4, c, "/"); i = a[1]; j = b[1]; k = c[1];
                     v += x[i] * (y[j] * z[k] - z[j] * y[k]) - y[i] * (x[j] * z[k] - z[j] * x[k]) + z[i] * (x[j] * y[k] - y[j] * x[k]) }
         END { printf "%.6f\n", v / 6 }' "$1"
}
polycube_case "inside-out sphere" spheretri_inward.obj 1 --resolution 6
cd "$W/d$NEWDIR_N" || exit 1
check "polycube inside-out sphere: one stderr line says it mapped the faces reversed" "'wind inward ... reversed'" \
    "$ERR" "$(printf '%s' "$ERR" | grep -c 'faces wind inward.*mapped them reversed' | grep -qx 1; echo $?)"
check "polycube inside-out sphere: the output winds outward (volume > 0; the input's < 0)" \
    "out.obj $(obj_volume out.obj 2>/dev/null) > 0, input $(obj_volume ../in/spheretri_inward.obj) < 0" \
    "$(obj_volume out.obj 2>&1)" \
    "$(awk -v o="$(obj_volume out.obj 2>/dev/null)" -v i="$(obj_volume ../in/spheretri_inward.obj)" \
        'BEGIN { exit !(o > 0 && i < 0) }'; echo $?)"
cd "$W" || exit 1

# the same seed twice: the same files; another seed: another result
newdir
expect_ok "polycube sphere again" polycube ../in/spheretri.obj ../in/tex.png out --tile 16 --colors 2 --resolution 8
check_normals "polycube" out.obj
check_normals "polycube: the polycube's own OBJ" out_polycube.obj
read -r corners nvn bad creased <<<"$(normals_report out.obj)"
check "polycube: the sphere's normals carried smooth onto the split triangles (every vertex one normal)" \
    "0 creased vertices" "$creased creased vertices of $corners corners" \
    "$([ "${creased:-1}" = 0 ] && [ "${corners:-0}" -gt 0 ]; echo $?)"
for f in out.obj out.mtl out.png out_polycube.obj; do
    CMD="tiledtex polycube ../in/spheretri.obj ../in/tex.png out --tile 16 --colors 2 --resolution 8 (twice)"
    check "polycube same seed twice: identical $f" "cmp equal" "$(cmp "$f" "$POLYCUBE_SPHERE/$f" 2>&1)" \
        "$(cmp -s "$f" "$POLYCUBE_SPHERE/$f"; echo $?)"
done
expect_ok "polycube seed 5" polycube ../in/spheretri.obj ../in/tex.png other --tile 16 --colors 2 --resolution 8 --seed 5
CMD="tiledtex polycube ... --seed 0 / --seed 5"
check "polycube different seed: different atlas and UVs" "files differ" "identical" \
    "$(! cmp -s out.png other.png && ! cmp -s out.obj other.obj; echo $?)"
# the result renders with its atlas
expect_ok "render a polycube OBJ" render out.obj out.png view.png --size 160x120
check "render polycube OBJ: 160x120 PNG" "160 120" "$(png_size view.png)" \
    "$(is_png view.png && [ "$(png_size view.png)" = "160 120" ]; echo $?)"
cd "$W" || exit 1

# bad command lines: exit 2, one line, no files
# expect_usage_error WHAT ARGS... : expect_error, and the status is TOOL_EXIT_USAGE (2)
expect_usage_error() {
    local what=$1
    expect_error "$@"
    check "$what: exit status 2 (usage)" "exit 2" "exit $RC" "$([ $RC -eq 2 ]; echo $?)"
}
expect_usage_error "polycube --resolution 0" polycube ../in/spheretri.obj ../in/tex.png out --resolution 0
expect_usage_error "polycube --resolution -4" polycube ../in/spheretri.obj ../in/tex.png out --resolution -4
expect_usage_error "polycube --resolution 99999" polycube ../in/spheretri.obj ../in/tex.png out --resolution 99999
expect_usage_error "polycube --resolution abc" polycube ../in/spheretri.obj ../in/tex.png out --resolution abc
expect_usage_error "polycube --resolution without a value" polycube ../in/spheretri.obj ../in/tex.png out --resolution
expect_usage_error "polycube --cube-size 0" polycube ../in/spheretri.obj ../in/tex.png out --cube-size 0
expect_usage_error "polycube --cube-size -1" polycube ../in/spheretri.obj ../in/tex.png out --cube-size -1
expect_usage_error "polycube --cube-size nan" polycube ../in/spheretri.obj ../in/tex.png out --cube-size nan
expect_usage_error "polycube --resolution with --cube-size" polycube ../in/spheretri.obj ../in/tex.png out \
    --resolution 8 --cube-size 0.5
err_mentions "polycube --resolution with --cube-size: names both" 'resolution.*cube-size'
expect_usage_error "polycube --colors 0" polycube ../in/spheretri.obj ../in/tex.png out --colors 0
expect_usage_error "polycube --tile 2" polycube ../in/spheretri.obj ../in/tex.png out --tile 2
expect_usage_error "polycube --up w" polycube ../in/spheretri.obj ../in/tex.png out --up w
expect_usage_error "polycube --up 0,0,0" polycube ../in/spheretri.obj ../in/tex.png out --up 0,0,0
expect_usage_error "polycube --up 1,2" polycube ../in/spheretri.obj ../in/tex.png out --up 1,2
expect_usage_error "polycube --seed abc" polycube ../in/spheretri.obj ../in/tex.png out --seed abc
expect_usage_error "polycube unknown option" polycube ../in/spheretri.obj ../in/tex.png out --bogus
expect_usage_error "polycube two arguments" polycube ../in/spheretri.obj ../in/tex.png
expect_usage_error "polycube four arguments" polycube ../in/spheretri.obj ../in/tex.png out more
# bad inputs: one line, non-zero exit, no files
expect_error "polycube missing mesh" polycube ../in/nope.obj ../in/tex.png out
err_mentions "polycube missing mesh: names the file" 'nope\.obj'
expect_error "polycube missing image" polycube ../in/spheretri.obj ../in/nope.png out
err_mentions "polycube missing image: names the file" 'nope\.png'
expect_error "polycube image not an image" polycube ../in/spheretri.obj ../in/spheretri.obj out
expect_error "polycube zero-area face" polycube ../in/lapped_degenerate.obj ../in/tex.png out
err_mentions "polycube zero-area face: FILE:LINE and face 1" 'lapped_degenerate\.obj:5: face 1 '
expect_error "polycube non-manifold edge" polycube ../in/nonmanifold.obj ../in/tex.png out
no_zero_index "polycube non-manifold edge"

# ======================================================================
# Bad files, images and options
# ======================================================================
expect_error "missing mesh file" tile ../in/nope.obj ../in/tex.png out
err_mentions "missing mesh: message names the file" 'nope\.obj'
expect_error "missing image file" tile ../in/torus.obj ../in/nope.png out
err_mentions "missing image: message names the file" 'nope\.png'
expect_error "missing image file (synth)" synth ../in/nope.png a.png
expect_error "non-image file as IMAGE" tile ../in/torus.obj ../in/torus.obj out
expect_error "garbage as IMAGE (synth)" synth ../in/garbage.obj a.png
expect_error "non-image TEXTURE (render)" render ../in/torus.obj ../in/torus.obj r.png
expect_error "missing mesh (render)" render ../in/nope.obj ../in/tex.png r.png
expect_error "NaN mesh (render)" render ../in/nan.obj ../in/tex.png r.png
expect_error "garbage mesh (render)" render ../in/garbage.obj ../in/tex.png r.png
expect_error "image smaller than the tiles" synth ../in/small.png a.png --tile 128
err_mentions "image smaller than the tiles: message mentions the size" '64 ?x ?64'
newdir
expect_ok "tile with a small image and no --tile picks a smaller tile" tile ../in/torus.obj ../in/small.png out
check "tile small image: atlas 128x128 (24-texel tiles: 2/5 of 64)" "128 128" "$(png_size out.png)" \
    "$([ "$(png_size out.png)" = "128 128" ]; echo $?)"
cd "$W" || exit 1
expect_error "--tile 100000 (synth)" synth ../in/tex.png a.png --tile 100000
expect_error "--tile 100000 (tile)" tile ../in/torus.obj ../in/tex.png out --tile 100000
expect_error "--tile 100000 (map)" map ../in/torus.obj m.obj --tile 100000
expect_error "--colors 0 (synth)" synth ../in/tex.png a.png --colors 0
expect_error "--colors 99 (synth)" synth ../in/tex.png a.png --colors 99
expect_error "--colors 0 (map)" map ../in/torus.obj m.obj --colors 0
expect_error "--colors 99 (tile)" tile ../in/torus.obj ../in/tex.png out --colors 99
expect_error "--gutter -1" synth ../in/tex.png a.png --gutter -1
expect_error "--subdivide 99" map ../in/torus.obj m.obj --subdivide 99
expect_error "--size 0x0 (render)" render ../in/torus.obj ../in/tex.png r.png --size 0x0
expect_error "--size 100000x100000 (render)" render ../in/torus.obj ../in/tex.png r.png --size 100000x100000
expect_error "--size 12 (render)" render ../in/torus.obj ../in/tex.png r.png --size 12
expect_error "--pitch 90 (render)" render ../in/torus.obj ../in/tex.png r.png --pitch 90
expect_error "--yaw nan (render)" render ../in/torus.obj ../in/tex.png r.png --yaw nan
expect_error "--size 0 (generate texture)" generate texture t.png --size 0
expect_error "--size 100000 (generate texture)" generate texture t.png --size 100000
expect_error "--seed abc (synth)" synth ../in/tex.png a.png --seed abc
expect_error "--seed abc (map)" map ../in/torus.obj m.obj --seed abc
expect_error "--seed abc (tile)" tile ../in/torus.obj ../in/tex.png out --seed abc
expect_error "--seed abc (generate)" generate texture t.png --seed abc
expect_error "--seed without a value" synth ../in/tex.png a.png --seed
for sub in synth map tile lapped hpm render generate; do
    case $sub in
        synth) args="../in/tex.png a.png" ;;
        map) args="../in/torus.obj m.obj" ;;
        tile) args="../in/torus.obj ../in/tex.png out" ;;
        lapped | hpm) args="../in/torus.obj ../in/tex.png out" ;;
        render) args="../in/torus.obj ../in/tex.png r.png" ;;
        generate) args="mesh g.obj --shape torus" ;;
    esac
    # shellcheck disable=SC2086
    expect_error "unknown option ($sub)" $sub $args --frobnicate
    err_mentions "unknown option ($sub): message names it" 'frobnicate'
    check "unknown option ($sub): nothing near it to suggest" "no 'did you mean'" "$ERR" \
        "$(printf '%s' "$ERR" | grep -q 'did you mean'; [ $? -ne 0 ]; echo $?)"
done
# A typo of an option the command takes is answered with that option (the
# nearest within two edits, a swap of two letters being one, or the only
# option a long enough start begins); one of an option another command
# takes is not, nor is a start that two options share.
typo_suggests() {
    local what=$1 expected=$2
    shift 2
    expect_error "typo $what" "$@"
    check "typo $what: suggestion" "did you mean '$expected'" "$ERR" \
        "$(printf '%s' "$ERR" | grep -qF "did you mean '$expected'?"; echo $?)"
}
typo_suggests "--colours (synth)" --colors synth ../in/tex.png a.png --colours 2
typo_suggests "--colours=2 (tile)" --colors tile ../in/torus.obj ../in/tex.png out --colours=2
typo_suggests "--resoluton (polycube)" --resolution polycube ../in/spheretri.obj ../in/tex.png out --resoluton 4
typo_suggests "--cube_size (polycube)" --cube-size polycube ../in/spheretri.obj ../in/tex.png out --cube_size 1
typo_suggests "--isotorpic (lapped)" --isotropic lapped ../in/torus.obj ../in/tex.png out --isotorpic
typo_suggests "--scal (hpm)" --scale hpm ../in/torus.obj ../in/tex.png out --scal 2
typo_suggests "--wirefame (render)" --wireframe render ../in/torus.obj ../in/tex.png r.png --wirefame
typo_suggests "--normall (tile)" --normal tile ../in/torus.obj ../in/tex.png out --normall n.png
typo_suggests "--quite (global)" --quiet tile ../in/torus.obj ../in/tex.png out --quite
typo_suggests "--resol (a start, polycube)" --resolution polycube ../in/spheretri.obj ../in/tex.png out --resol 4
expect_error "typo of another command's option" polycube ../in/spheretri.obj ../in/tex.png out --smoth
check "typo of another command's option: no suggestion" "no 'did you mean'" "$ERR" \
    "$(printf '%s' "$ERR" | grep -q 'did you mean'; [ $? -ne 0 ]; echo $?)"
# A file given by an option that cannot be read is named with its option.
expect_error "--normal file missing" tile ../in/torus.obj ../in/tex.png out --normal nothere.png
err_mentions "--normal file missing: message names the option" "[-]-normal: cannot open 'nothere.png'"
expect_error "--mask file missing" lapped ../in/torus.obj ../in/tex.png out --mask nothere.png
err_mentions "--mask file missing: message names the option" "[-]-mask: cannot open 'nothere.png'"
expect_error "--constraints file missing" lapped ../in/torus.obj ../in/tex.png out --constraints nothere.txt
err_mentions "--constraints file missing: message names the option" "[-]-constraints: cannot open 'nothere.txt'"
expect_error "unknown command" frobnicate
expect_error "missing positional args (synth)" synth ../in/tex.png
expect_error "missing positional args (map)" map ../in/torus.obj
expect_error "missing positional args (tile)" tile ../in/torus.obj ../in/tex.png
expect_error "missing positional args (tile, none)" tile
expect_error "missing positional args (lapped)" lapped ../in/torus.obj ../in/tex.png
expect_error "missing positional args (hpm)" hpm ../in/torus.obj ../in/tex.png
expect_error "too many positional args (hpm)" hpm ../in/torus.obj ../in/tex.png out extra
expect_error "missing positional args (render)" render ../in/torus.obj ../in/tex.png
expect_error "missing positional args (generate)" generate
expect_error "missing positional args (generate mesh)" generate mesh
expect_error "generate mesh without --shape" generate mesh g.obj
expect_error "generate mesh unknown shape" generate mesh g.obj --shape blob
expect_error "too many positional args (synth)" synth ../in/tex.png a.png extra.png
expect_error "--edge outside the image" synth ../in/tex.png a.png --edge 1000,1000
expect_error "--edge negative" synth ../in/tex.png a.png --tile 32 --edge -1,0
expect_error "--edge once with --colors 2" synth ../in/tex.png a.png --colors 2 --tile 32 --edge 0,0
expect_error "--edge once with --colors 2 (tile)" tile ../in/torus.obj ../in/tex.png out --colors 2 --tile 32 --edge 0,0
expect_error "--edge not X,Y" synth ../in/tex.png a.png --edge 5
expect_error "--background outside the image" synth ../in/tex.png a.png --tile 32 --background 200,200,100,100
expect_error "map --atlas missing" map ../in/torus.obj m.obj --atlas ../in/nope.png
expect_error "map --atlas not an image" map ../in/torus.obj m.obj --atlas ../in/torus.obj
expect_error "output directory missing" tile ../in/torus.obj ../in/tex.png nodir/out --tile 32

# more geometry errors (and their --permissive twins)
printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 1 0\nv 2 2 0\nv 1 2 0\nf 1 2 3 4\nf 3 5 6 7\n' >"$W/in/bowtie.obj"
printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\nf 1 2 3 4\n' >"$W/in/duplicate_face.obj"
printf 'v 0 0 0\nv 0 0 0\nv 1 1 1\nv 2 2 2\nf 1 2 3 4\n' >"$W/in/zero_area.obj"
expect_error "two quads touching at one vertex" map ../in/bowtie.obj m.obj
no_zero_index "two quads touching at one vertex"
newdir
expect_ok "two quads touching at one vertex --permissive" map ../in/bowtie.obj m.obj --permissive
cd "$W" || exit 1
expect_error "the same face twice" map ../in/duplicate_face.obj m.obj
no_zero_index "the same face twice"
expect_error "zero-area face" tile ../in/zero_area.obj ../in/tex.png out --tile 32
no_zero_index "zero-area face"
# the messages above suggest --permissive: it must then work
newdir
expect_ok "face repeating a vertex --permissive" map ../in/repeated_vertex.obj m1.obj --permissive
expect_ok "the same face twice --permissive" map ../in/duplicate_face.obj m2.obj --permissive
expect_ok "zero-area face --permissive" tile ../in/zero_area.obj ../in/tex.png out --tile 32 --permissive
cd "$W" || exit 1

# bare `tiledtex`: either help (exit 0) or an error with its one stderr line
newdir
run
check "tiledtex with no arguments" "exit 0 with help, or non-zero with one 'tiledtex...' line on stderr" \
    "exit $RC, $(wc -l <"$W/err") stderr line(s), stdout ${#OUT} bytes" \
    "$({ [ $RC -eq 0 ] && [ -n "$OUT" ]; } || { [ $RC -ne 0 ] && [ "$(wc -l <"$W/err")" -eq 1 ] && head -c 8 "$W/err" | grep -qx tiledtex; }; echo $?)"
cd "$W" || exit 1

# an output folder that does not exist: said at once, before the work
for pipeline in tile hpm lapped polycube; do
    expect_error "$pipeline into a missing folder" $pipeline ../in/torus.obj ../in/tex.png no_such_folder/out
    err_mentions "$pipeline into a missing folder: names the folder" "no folder 'no_such_folder/'"
done

# all-or-nothing output: one output path is a directory -> nothing else written
for blocked in obj mtl png; do
    newdir
    mkdir out.$blocked
    run tile ../in/torus.obj ../in/tex.png out --tile 32
    check "tile with out.$blocked a directory: fails" "non-zero exit, one stderr line" "exit $RC, stderr: $ERR" \
        "$([ $RC -ne 0 ] && [ $RC -lt 124 ] && [ "$(wc -l <"$W/err")" -eq 1 ]; echo $?)"
    check "tile with out.$blocked a directory: no other output" "only out.$blocked" "$(ls -A)" \
        "$([ "$(ls -A)" = "out.$blocked" ]; echo $?)"
    cd "$W" || exit 1
done
newdir
echo old >out.obj
mkdir out.png
run tile ../in/torus.obj ../in/tex.png out --tile 32
check "failed tile keeps an existing out.obj" "out.obj still 'old', no other files" "$(ls -A | tr '\n' ' ') / $(head -c 40 out.obj 2>/dev/null)" \
    "$([ $RC -ne 0 ] && [ "$(cat out.obj 2>/dev/null)" = old ] && [ "$(ls -A | tr '\n' ' ')" = "out.obj out.png " ]; echo $?)"
cd "$W" || exit 1
newdir
mkdir a_mip2.png
run synth ../in/tex.png a.png --tile 32 --mips
check "synth --mips with a_mip2.png a directory: nothing written" "non-zero exit, only a_mip2.png" \
    "exit $RC, files: $(ls -A | tr '\n' ' ')" "$([ $RC -ne 0 ] && [ "$(ls -A)" = a_mip2.png ]; echo $?)"
cd "$W" || exit 1

# ======================================================================
# OBJ reader: byte-order marks, line endings, unknown keywords
# ======================================================================
# Two quads; the BOM / CR / CRLF twins must give byte-identical outputs.
OBJ_LINES='v 0 0 0|v 1 0 0|v 2 0 0|v 0 1 0|v 1 1 0|v 2 1 0.5|f 1 2 5 4|f 2 3 6 5|'
printf '%s' "$OBJ_LINES" | tr '|' '\n' >"$W/in/two.obj"
{ printf '\357\273\277'; cat "$W/in/two.obj"; } >"$W/in/two_bom.obj"
tr '\n' '\r' <"$W/in/two.obj" >"$W/in/two_cr.obj"
sed 's/$/\r/' "$W/in/two.obj" >"$W/in/two_crlf.obj"
newdir
expect_ok "map two quads (LF)" map ../in/two.obj lf.obj --seed 1
for kind in bom cr crlf; do
    expect_ok "map two quads ($kind)" map ../in/two_$kind.obj $kind.obj --seed 1
    check "OBJ with $kind: same output as with LF" "cmp equal, nothing on stderr" "$(cmp lf.obj $kind.obj 2>&1) / $ERR" \
        "$(cmp -s lf.obj $kind.obj && [ -z "$ERR" ]; echo $?)"
done
# a BOM must not drop the first vertex (the faces would silently shift)
check "OBJ with a BOM: 6 vertices, first one kept" "6 v lines, the first 'v 0 0 0'" "$(grep -c '^v ' bom.obj) v lines" \
    "$([ "$(grep -c '^v ' bom.obj)" = 6 ] && [ "$(grep -m1 '^v ' bom.obj)" = 'v 0 0 0' ]; echo $?)"
# CR-only lines count as lines: an error names the right line
printf 'v 0 0 0\rv 1 0 0\rv 1 1 0\rf 1 2 9\r' >"$W/in/cr_bad.obj"
cd "$W" || exit 1
expect_error "CR-only OBJ with a bad face" map ../in/cr_bad.obj m.obj
err_mentions "CR-only OBJ with a bad face: names line 4" 'cr_bad\.obj:4: '
# unknown keywords: one warning naming the first, its line and the count
printf 'v 0 0 0\nv 1 0 0\nfoo 1 2\nv 1 1 0\nbar\nv 0 1 0\nV 3 3 3\nf 1 2 3 4\n' >"$W/in/unknown.obj"
newdir
expect_ok "OBJ with unknown keywords" map ../in/unknown.obj m.obj
check "unknown keywords: exactly one warning line" "1 stderr line" "$ERR" \
    "$([ "$(wc -l <"$W/err")" -eq 1 ]; echo $?)"
err_mentions "unknown keywords: names the first, its line and the count" "unknown\.obj:3: .*3 lines.*'foo'"
# known but unused statements stay silent
printf 'mtllib x.mtl\no thing\ng part\nusemtl m\ns 1\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nvt 0 0\nl 1 2\np 1\n# note\nf 1//1 2//1 3//1 4//1\n' \
    >"$W/in/known.obj"
expect_ok "OBJ with known unused statements" map ../in/known.obj k.obj
check "known unused statements: no warning" "empty stderr" "$ERR" "$([ -z "$ERR" ]; echo $?)"
cd "$W" || exit 1

# ======================================================================
# Other mesh formats: STL and OFF read, the rest named; --weld
# ======================================================================
cd "$W/in" || exit 1
# Formats the tool does not read: each named, with a conversion command.
printf 'ply\nformat ascii 1.0\nelement vertex 0\nend_header\n' >model.ply
printf 'glTF\002\000\000\000\024\000\000\000' >model.glb
printf '{"asset": {"version": "2.0"}, "meshes": []}\n' >model.gltf
printf 'Kaydara FBX Binary  \000\032\000' >model.fbx
printf '<?xml version="1.0"?>\n<COLLADA version="1.4.1"></COLLADA>\n' >model.dae
printf 'MM\012\000\000\000\002\000\012\000' >model.3ds
cp model.ply MODEL.PLY
cp model.ply ply_named.obj
cp model.glb glb_named.obj
# A tetrahedron, outward, as ASCII STL (its facets' normals are not used)...
stl_facet() { printf ' facet normal 0 0 0\n  outer loop\n   vertex %s\n   vertex %s\n   vertex %s\n  endloop\n endfacet\n' "$@"; }
{
    printf 'solid tetra\n'
    stl_facet '0 0 0' '0 1 0' '1 0 0'
    stl_facet '0 0 0' '1 0 0' '0 0 1'
    stl_facet '0 0 0' '0 0 1' '0 1 0'
    stl_facet '1 0 0' '0 1 0' '0 0 1'
    printf 'endsolid tetra\n'
} >tetra.stl
cp tetra.stl stl_named.obj
# ... as binary STL (80-byte header that starts "solid", like some exporters
# write, a count, 50 bytes per triangle: normal, 3 corners, 2 spare bytes) ...
O='\000\000\000\000'
I='\000\000\200\077'
stl_triangle() { printf "$O$O$O$1$2$3$4$5$6$7$8$9\000\000"; }
{
    printf 'solid binary header%61s' ''
    printf '\004\000\000\000'
    stl_triangle "$O" "$O" "$O" "$O" "$I" "$O" "$I" "$O" "$O"
    stl_triangle "$O" "$O" "$O" "$I" "$O" "$O" "$O" "$O" "$I"
    stl_triangle "$O" "$O" "$O" "$O" "$O" "$I" "$O" "$I" "$O"
    stl_triangle "$I" "$O" "$O" "$O" "$I" "$O" "$O" "$O" "$I"
} >tetra_binary.stl
# ... and the cube as OFF: a comment, colours after some vertices and faces.
printf 'OFF\n# a cube\n8 6 12\n-1 -1 -1\n1 -1 -1 0.5 0.5 0.5\n1 1 -1\n-1 1 -1\n-1 -1 1\n1 -1 1\n1 1 1\n-1 1 1\n4 0 3 2 1 255 0 0\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n' >cube.off
printf 'OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 4\n' >bad_index.off
# two triangles of a square, each with its own vertices
printf 'OFF\n6 2 0\n0 0 0\n1 0 0\n0 1 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 3 4 5\n' >per_face.off
printf 'solid bad\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n  endloop\n endfacet\nendsolid bad\n' >two_corners.stl
# The torus exported per face: every corner its own vertex ("v" lines
# before each face); the noisy twin moves each copy by up to 2e-6, within
# --weld's 1e-6 of the diagonal (about 3.6).
awk '$1 == "v" { v[++n] = $0 }
     $1 == "f" { s = "f"; for (i = 2; i <= NF; i++) { split($i, c, "/"); print v[c[1]]; s = s " " ++m }; print s }' \
    torus.obj >torus_per_face.obj
awk '$1 == "v" { k++; printf "v %.9g %.9g %.9g\n", $2 + (k % 3) * 1e-6, $3 - (k % 2) * 1e-6, $4; next } { print }' \
    torus_per_face.obj >torus_per_face_noisy.obj
cd "$W" || exit 1

for format in ply:PLY glb:'binary glTF \(GLB\)' gltf:glTF fbx:FBX dae:COLLADA 3ds:3DS; do
    ext=${format%%:*}
    name=${format#*:}
    expect_error "mesh .$ext refused" map ../in/model.$ext m.obj
    err_mentions "mesh .$ext: names the format and how to convert it" \
        "model\\.$ext: an? $name mesh; tiledtex reads Wavefront OBJ, STL and OFF: convert it \\(e\\.g\\. assimp export ../in/model\\.$ext ../in/model\\.obj, from Debian's assimp-utils\\)"
done
expect_error "mesh .PLY (upper case) refused" tile ../in/MODEL.PLY ../in/tex.png out
err_mentions "mesh .PLY: names the format" 'MODEL\.PLY: a PLY mesh'
expect_error "PLY named .obj refused" lapped ../in/ply_named.obj ../in/tex.png out
err_mentions "PLY named .obj: recognised by its first bytes" 'ply_named\.obj: a PLY mesh \(by its first bytes.*assimp export ../in/ply_named\.obj ../in/ply_named_converted\.obj'
expect_error "GLB named .obj refused (render)" render ../in/glb_named.obj ../in/tex.png r.png
err_mentions "GLB named .obj: recognised by its first bytes" 'glb_named\.obj: a binary glTF \(GLB\) mesh \(by its first bytes'

newdir
expect_ok "map ASCII STL" map ../in/tetra.stl a.obj
check "ASCII STL: 4 triangles welded to 4 vertices, one closed component" "'12 quads, 14 vertices, genus 0, 1 component, 0 boundary loops'" \
    "$OUT" "$(printf '%s' "$OUT" | grep -q '12 quads, 14 vertices, genus 0, 1 component, 0 boundary loops'; echo $?)"
expect_ok "map binary STL (header starting 'solid')" map ../in/tetra_binary.stl b.obj
check "binary STL: the same mesh as the ASCII one" "identical v and f lines" "differ" \
    "$(cmp -s <(grep -E '^(v|f) ' a.obj) <(grep -E '^(v|f) ' b.obj); echo $?)"
expect_ok "map STL named .obj" map ../in/stl_named.obj c.obj
check "STL named .obj: read as STL" "identical v and f lines to the .stl" "differ" \
    "$(cmp -s <(grep -E '^(v|f) ' a.obj) <(grep -E '^(v|f) ' c.obj); echo $?)"
run render ../in/tetra_binary.stl ../in/tex.png r.png --size 32x32
check "render binary STL: 4 triangles" "'4 triangles'" "exit $RC, $OUT" \
    "$([ $RC -eq 0 ] && printf '%s' "$OUT" | grep -q '4 triangles'; echo $?)"
expect_ok "map OFF cube" map ../in/cube.off d.obj
check "OFF cube: 6 quads, 8 vertices, closed" "'6 quads, 8 vertices, genus 0, 1 component, 0 boundary loops'" "$OUT" \
    "$(printf '%s' "$OUT" | grep -q '6 quads, 8 vertices, genus 0, 1 component, 0 boundary loops'; echo $?)"
check "OFF cube: the cube's corners" "8 v lines, all at |x|=|y|=|z|=1" "$(grep -cE '^v -?1 -?1 -?1$' d.obj)" \
    "$([ "$(grep -cE '^v -?1 -?1 -?1$' d.obj)" = 8 ]; echo $?)"
expect_ok "map per-face OFF" map ../in/per_face.off pf.obj
check "per-face OFF: two components" "'2 components'" "$OUT" "$(printf '%s' "$OUT" | grep -q '2 components'; echo $?)"
err_mentions "per-face OFF: a note suggests --weld" 'per_face\.off looks unwelded .*try --weld'
expect_ok "map per-face OFF --weld" map ../in/per_face.off pfw.obj --weld
check "per-face OFF --weld: one component, one boundary loop" "'1 component, 1 boundary loop'" "$OUT" \
    "$(printf '%s' "$OUT" | grep -q '1 component, 1 boundary loop'; echo $?)"
cd "$W" || exit 1
expect_error "OFF face index out of range" map ../in/bad_index.off m.obj
err_mentions "OFF index out of range: names line and corner" 'bad_index\.off:7: face 1: corner 3 is not a vertex index from 0 to 3'
printf '4 1 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n' >"$W/in/no_header.off"
expect_error "OFF without its header" map ../in/no_header.off m.obj
err_mentions "OFF without its header: says what it must start with" "no_header\.off:1: an OFF file starts with 'OFF'"
expect_error "STL facet with 2 vertices" map ../in/two_corners.stl m.obj
err_mentions "STL facet with 2 vertices: names the line" 'two_corners\.stl:7: a facet with 2 vertices'
# A binary STL whose triangle count disagrees with its size (a count of 5
# over 4 triangles; 4 triangles cut short; less than the header): said so.
{ head -c 80 "$W/in/tetra_binary.stl"; printf '\005\000\000\000'; tail -c +85 "$W/in/tetra_binary.stl"; } >"$W/in/count5.stl"
head -c 180 "$W/in/tetra_binary.stl" >"$W/in/cut.stl"
head -c 82 "$W/in/tetra_binary.stl" >"$W/in/header_only.stl"
expect_error "binary STL counting 5 of 4 triangles" map ../in/count5.stl m.obj
err_mentions "binary STL counting 5 of 4 triangles: the count and the size" 'count5\.stl: a binary STL whose header counts 5 triangles \(334 bytes .*\) is 284 bytes long: the file is truncated'
expect_error "binary STL cut short" map ../in/cut.stl m.obj
err_mentions "binary STL cut short: truncated" 'cut\.stl: a binary STL whose header counts 4 triangles .* is 180 bytes long: the file is truncated'
expect_error "binary STL shorter than its header" map ../in/header_only.stl m.obj
err_mentions "binary STL shorter than its header" 'header_only\.stl: a binary STL of 82 bytes, shorter than its 84-byte header'

newdir
expect_ok "tile torus (for --weld)" tile ../in/torus.obj ../in/tex.png orig --tile 16
ORIG_SUMMARY=$(printf '%s\n' "$OUT" | head -1 | sed 's/^[^:]*: //')
expect_ok "tile per-face torus without --weld" tile ../in/torus_per_face.obj ../in/tex.png pf --tile 16
check "per-face torus without --weld: 512 components" "'512 components'" "$OUT" \
    "$(printf '%s' "$OUT" | grep -q '512 components'; echo $?)"
err_mentions "per-face torus without --weld: a note suggests --weld" 'torus_per_face\.obj looks unwelded \(each face has its own vertices\): try --weld'
expect_ok "tile per-face torus --weld" tile ../in/torus_per_face.obj ../in/tex.png w --tile 16 --weld
check "--weld: the same summary as the torus it came from" "$ORIG_SUMMARY" "$OUT" \
    "$([ "$(printf '%s\n' "$OUT" | head -1 | sed 's/^[^:]*: //')" = "$ORIG_SUMMARY" ]; echo $?)"
check "--weld: no note about welding" "empty stderr" "$ERR" "$([ -z "$ERR" ]; echo $?)"
check "--weld: the same atlas as the torus it came from" "cmp equal" "$(cmp orig.png w.png 2>&1)" \
    "$(cmp -s orig.png w.png; echo $?)"
expect_ok "tile per-face torus, positions off by 1e-6, --weld (before the command)" \
    --weld tile ../in/torus_per_face_noisy.obj ../in/tex.png n --tile 16
check "--weld within the tolerance: the same summary" "$ORIG_SUMMARY" "$OUT" \
    "$([ "$(printf '%s\n' "$OUT" | head -1 | sed 's/^[^:]*: //')" = "$ORIG_SUMMARY" ]; echo $?)"
expect_ok "lapped per-face torus --weld" lapped ../in/torus_per_face.obj ../in/lap.png lw --weld
LW_OUT=$(printf '%s\n' "$OUT" | sed 's/torus_per_face\.obj/torus.obj/')
expect_ok "lapped torus (for --weld)" lapped ../in/torus.obj ../in/lap.png lo
check "lapped --weld: the same summary numbers as the torus it came from" "$(oneline "$OUT")" "$LW_OUT" \
    "$([ "$(printf '%s\n' "$OUT" | sed 's/ lo[._]/ X/g; s/[0-9.]* s\b//g')" = "$(printf '%s\n' "$LW_OUT" | sed 's/ lw[._]/ X/g; s/[0-9.]* s\b//g')" ]; echo $?)"
expect_ok "map torus --weld" map ../in/torus.obj mw.obj --weld
expect_ok "map torus" map ../in/torus.obj mo.obj
check "--weld on a welded mesh changes nothing" "cmp equal" "$(cmp mo.obj mw.obj 2>&1)" "$(cmp -s mo.obj mw.obj; echo $?)"
run --help
check "--help documents --weld and the mesh formats" "'--weld' and 'STL' in the usage" "$OUT" \
    "$(printf '%s' "$OUT" | grep -q -- '--weld' && printf '%s' "$OUT" | grep -q 'STL'; echo $?)"
cd "$W" || exit 1

# ======================================================================
# Outputs never replace inputs; the rollback removes only its own files
# ======================================================================
# expect_refused WHAT ARGS... : run in the current directory, whose files are
# the inputs: non-zero exit, one stderr line saying it will not overwrite,
# and afterwards the same files with the same contents.
expect_refused() {
    local what=$1 before after
    shift
    before=$(ls -A | tr '\n' ' '; cat -- * 2>/dev/null | cksum)
    run "$@"
    after=$(ls -A | tr '\n' ' '; cat -- * 2>/dev/null | cksum)
    check "$what: refused" "non-zero exit, one stderr line 'will not overwrite'" "exit $RC, stderr: $ERR" \
        "$([ $RC -ne 0 ] && [ $RC -lt 124 ] && [ "$(wc -l <"$W/err")" -eq 1 ] && grep -q 'will not overwrite' "$W/err"; echo $?)"
    check "$what: nothing written or changed" "files and contents as before" "before: $before, after: $after" \
        "$([ "$before" = "$after" ]; echo $?)"
}
newdir
cp ../in/torus.obj m.obj
cp ../in/lap.png img.png
expect_refused "tile MESH IMAGE with OUT_PREFIX naming the mesh" tile m.obj img.png m --tile 16
expect_refused "tile ./m.obj ... m (same file, other spelling)" tile ./m.obj img.png m --tile 16
expect_refused "tile with OUT_PREFIX naming the image" tile m.obj img.png img --tile 16
ln m.obj link.obj
expect_refused "map onto a hard link of the input" map m.obj link.obj
expect_refused "map onto the input" map m.obj m.obj
cp img.png x_patch.png
expect_refused "lapped --pasting IMAGE that is OUT_PREFIX_patch.png" lapped m.obj x_patch.png x --scale 1.5 --pasting
cp img.png y_baked.png
expect_refused "lapped --pasting --bake output that is the IMAGE" lapped m.obj y_baked.png y --scale 1.5 --bake 64 \
    --pasting
cp img.png z.png
expect_refused "lapped baked texture that is the IMAGE" lapped m.obj z.png z --scale 1.5 --bake 64
expect_refused "hpm with OUT_PREFIX naming the mesh" hpm m.obj img.png m --rotations 3
cp m.obj z.mtl
expect_refused "hpm with OUT_PREFIX.mtl an input (the mesh)" hpm z.mtl img.png z --rotations 3
expect_refused "polycube with OUT_PREFIX naming the mesh" polycube m.obj img.png m --tile 16
expect_refused "polycube with OUT_PREFIX naming the image" polycube m.obj img.png img --tile 16
cp m.obj w_polycube.obj
expect_refused "polycube with OUT_PREFIX_polycube.obj the mesh" polycube w_polycube.obj img.png w --tile 16
expect_refused "synth onto its image" synth img.png img.png --tile 16
expect_refused "synth onto its image (other spelling)" synth img.png ../$(basename "$PWD")/img.png --tile 16
expect_refused "render onto its texture" render m.obj img.png img.png --size 32x32
expect_refused "render onto its mesh" render m.obj img.png m.obj --size 32x32
CMD="tiledtex map - m.obj < m.obj"
"$TOOL" map - m.obj <m.obj >"$W/out" 2>"$W/err"
RC=$?
check "map from standard input onto the same file: refused" "non-zero exit, m.obj unchanged" "exit $RC, $(cat "$W/err")" \
    "$([ $RC -ne 0 ] && cmp -s m.obj ../in/torus.obj; echo $?)"
cd "$W" || exit 1

# Corrupt images the fuzzer found, each refused before the decoder sees it
# with a line saying why. A fuzz_image seed holds the file after a 2-byte
# mode prefix. refused_seed SEED FILE WHAT WHY: the seed as FILE, refused by
# synth, the message containing WHY.
refused_seed() {
    tail -c +3 "$ROOT/tests/fuzz/corpus_image/$1" >"$W/in/$2"
    expect_error "$3" synth "../in/$2" out.png --tile 16
    err_mentions "$3: says why" "$4"
}
# A Huffman table of 257 codes (some stb_image versions write past their
# table on it); the same table of 520 codes in a DHT segment between the
# scans of a progressive JPEG, behind bytes that start no segment (the
# decoder skips them).
refused_seed jpeg_huffman_257_codes huffman257.jpg "a JPEG with a 257-code Huffman table" "Huffman table"
refused_seed jpeg_dht_after_first_scan dht_late.jpg "a JPEG with a 520-code Huffman table after junk bytes" \
    "Huffman table"
# A progressive JPEG whose second scan uses an AC table no DHT segment
# defined (the decoder read whatever was left in that table's memory and
# failed its own assertion).
refused_seed jpeg_scan_uses_undefined_ac_table undefined_table.jpg "a JPEG scan that uses an undefined Huffman table" \
    "Huffman table never defined"
# A 60-byte PNG whose IDAT chunk declares a gigabyte (stb_image grew its
# buffer to 2 GB before reading the chunk).
refused_seed png_idat_longer_than_file idat_overrun.png "a PNG whose IDAT chunk runs past the end of the file" \
    "chunk longer than the rest of the file"
# A valid progressive JPEG and one with restart markers are read.
newdir
for jpeg in jpeg_progressive_64x48 jpeg_restart_markers_64x48; do
    tail -c +3 "$ROOT/tests/fuzz/corpus_image/$jpeg" >"$W/in/$jpeg.jpg"
    expect_ok "a valid JPEG is read: $jpeg" synth ../in/$jpeg.jpg "$jpeg.png" --tile 16 --colors 1
done
cd "$W" || exit 1

# Ctrl-C (SIGINT) or SIGTERM during a long library call cancels it through
# the progress callback: one line saying so, exit status 130, nothing
# written. The run (27,000 pastes on the sphere, several seconds even
# without sanitizers) is well inside its paste loop after 3 s (--bake 2048:
# the atlas for the default side, 8192 here, is packed before the paste
# loop, and the packing takes no progress callback).
for sig in INT TERM; do
    newdir
    CMD="tiledtex lapped sphere.obj lap.png out --scale 0.05 --bake 2048, then SIG$sig after 3 s"
    "$TOOL" lapped ../in/spheretri.obj ../in/lap.png out --scale 0.05 --bake 2048 >"$W/out" 2>"$W/err" </dev/null &
    pid=$!
    sleep 3
    kill -s "$sig" "$pid"
    wait "$pid"
    RC=$?
    ERR=$(cat "$W/err")
    check "SIG$sig during lapped: cancelled cleanly" "exit 130, one line saying it was cancelled, no file" \
        "exit $RC, stderr: $ERR, files: $(ls -A | tr '\n' ' ')" \
        "$([ $RC -eq 130 ] && [ "$(wc -l <"$W/err")" -eq 1 ] && grep -qi 'cancel' "$W/err" && [ -z "$(ls -A)" ]; echo $?)"
    cd "$W" || exit 1
done

# a directory named like a temporary is never opened nor removed
newdir
mkdir out.obj.tiledtex-tmp
expect_ok "tile beside a directory named out.obj.tiledtex-tmp" tile ../in/torus.obj ../in/tex.png out --tile 16
check "the directory named like a temporary is left alone" "out.obj.tiledtex-tmp still a directory, out.obj written" \
    "$(ls -A | tr '\n' ' ')" "$([ -d out.obj.tiledtex-tmp ] && [ -s out.obj ]; echo $?)"
cd "$W" || exit 1
newdir
mkdir out.obj.tiledtex-tmp out.png
run tile ../in/torus.obj ../in/tex.png out --tile 16
check "failed tile: rollback keeps a directory named like a temporary" "fails; only out.obj.tiledtex-tmp and out.png" \
    "exit $RC, files: $(ls -A | tr '\n' ' ')" \
    "$([ $RC -ne 0 ] && [ "$(ls -A | tr '\n' ' ')" = "out.obj.tiledtex-tmp out.png " ] && [ -d out.obj.tiledtex-tmp ]; echo $?)"
cd "$W" || exit 1

# What killed runs left beside the outputs (PATH.tiledtex-tmp-PID, a
# previous file moved aside as PATH.tiledtex-old-PID) goes at the next run,
# when its process is gone; a live process's, other names and directories
# stay.
newdir
sh -c 'exit 0' &
dead=$!
wait "$dead"
printf 'half' >"out.obj.tiledtex-tmp-$dead"
printf 'half' >"out.png.tiledtex-tmp-$dead-2"
printf 'old' >"out.mtl.tiledtex-old-$dead"
printf 'mine' >"out.obj.tiledtex-tmp-$$"
printf 'other' >"other.obj.tiledtex-tmp-$dead"
mkdir "out.png.tiledtex-tmp-$((dead + 1))x"
expect_ok "tile beside a killed run's leftovers" tile ../in/torus.obj ../in/tex.png out --tile 16
check "a killed run's temporaries and moved-aside files are removed, nothing else" \
    "out.obj.tiledtex-tmp-$$, other.obj.tiledtex-tmp-$dead and the directory kept" "$(ls -A | tr '\n' ' ')" \
    "$([ ! -e "out.obj.tiledtex-tmp-$dead" ] && [ ! -e "out.png.tiledtex-tmp-$dead-2" ] &&
        [ ! -e "out.mtl.tiledtex-old-$dead" ] && [ -f "out.obj.tiledtex-tmp-$$" ] &&
        [ -f "other.obj.tiledtex-tmp-$dead" ] && [ -d "out.png.tiledtex-tmp-$((dead + 1))x" ] && [ -s out.obj ]; echo $?)"
cd "$W" || exit 1

# The commit's renames, watched and failed through a preloaded rename(): the
# model file (OBJ, GLB) takes its name last, and a rename that fails puts the
# previous run's files back exactly as they were.
cat >"$W/rename_shim.c" <<'EOF_C'
#define _GNU_SOURCE
#include <dlfcn.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
/* RENAME_LOG: append each rename's new name; RENAME_FAIL: fail (EIO) the
   first rename onto the path with that ending (the undo's own renames then
   go through). */
static int failed_once;
int rename(const char *from, const char *to)
{
    int (*real)(const char *, const char *) = (int (*)(const char *, const char *))dlsym(RTLD_NEXT, "rename");
    const char *log = getenv("RENAME_LOG"), *failing = getenv("RENAME_FAIL");
    size_t n = strlen(to);
    if (log) {
        FILE *f = fopen(log, "a");
        if (f) { fprintf(f, "%s\n", to); fclose(f); }
    }
    if (failing && !failed_once && n >= strlen(failing) && strcmp(to + n - strlen(failing), failing) == 0) {
        failed_once = 1;
        errno = EIO;
        return -1;
    }
    return real(from, to);
}
EOF_C
CMD="$HELPER_CC -shared rename_shim.c (test helper)"
if $HELPER_CC -shared -fPIC -O1 "$W/rename_shim.c" -o "$W/rename_shim.so" -ldl 2>"$W/err"; then
    pass
    newdir
    expect_ok "tile, the previous run" tile ../in/torus.obj ../in/tex.png out --tile 16 --seed 1
    before=$(cksum out.obj out.mtl out.png)
    CMD="RENAME_LOG=renames tiledtex tile ... out --seed 2"
    RENAME_LOG=$PWD/renames LD_PRELOAD=$W/rename_shim.so ASAN_OPTIONS=verify_asan_link_order=0:detect_leaks=0 \
        "$TOOL" tile ../in/torus.obj ../in/tex.png out --tile 16 --seed 2 >"$W/out" 2>"$W/err"
    RC=$?
    check "the OBJ takes its name last" "exit 0; out.mtl and out.png renamed, then out.obj" \
        "exit $RC, renames: $(grep -v tiledtex-old renames | tr '\n' ' ')" \
        "$([ $RC -eq 0 ] && [ "$(grep -v tiledtex-old renames | sed 's|.*/||' | tail -n 1)" = out.obj ] &&
            [ "$(grep -c . renames)" -ge 3 ]; echo $?)"
    expect_ok "tile, the previous run again" tile ../in/torus.obj ../in/tex.png out --tile 16 --seed 1
    for failing in out.png out.obj; do
        CMD="RENAME_FAIL=$failing tiledtex tile ... out --seed 2"
        RENAME_FAIL=$failing LD_PRELOAD=$W/rename_shim.so ASAN_OPTIONS=verify_asan_link_order=0:detect_leaks=0 \
            "$TOOL" tile ../in/torus.obj ../in/tex.png out --tile 16 --seed 2 >"$W/out" 2>"$W/err"
        RC=$?
        check "a rename onto $failing fails: the previous run's files as they were" \
            "non-zero exit, one error line, out.obj/.mtl/.png unchanged, nothing else" \
            "exit $RC, $(cat "$W/err"), files: $(ls -A | tr '\n' ' ')" \
            "$([ $RC -ne 0 ] && [ "$(grep -c . "$W/err")" = 1 ] && [ "$(cksum out.obj out.mtl out.png)" = "$before" ] &&
                [ "$(ls -A | tr '\n' ' ')" = "out.mtl out.obj out.png renames " ]; echo $?)"
    done
    cd "$W" || exit 1
else
    fail "rename shim builds" "$CMD" "a shared object" "$(cat "$W/err")"
fi

# The OBJ is written to its temporary while it is made (streamed, not held
# whole in memory): a write that fails there (here a file size limit, EFBIG)
# is one error line naming the OBJ, and leaves no file, temporary or other.
newdir
CMD="ulimit -f 64; tiledtex tile ../in/torus.obj ../in/tex.png out --tile 16 --subdivide 3"
(trap '' XFSZ; ulimit -f 64; exec "$TOOL" tile ../in/torus.obj ../in/tex.png out --tile 16 --subdivide 3) \
    >"$W/out" 2>"$W/err" </dev/null
RC=$?
check "a streamed OBJ that cannot be written: one error, nothing left" \
    "non-zero exit, one line \"cannot write 'out.obj': ...\", empty directory" \
    "exit $RC, $(cat "$W/err"), files: $(ls -A | tr '\n' ' ')" \
    "$([ $RC -ne 0 ] && [ $RC -lt 124 ] && [ "$(grep -c . "$W/err")" = 1 ] &&
        grep -q "cannot write 'out.obj': " "$W/err" && [ -z "$(ls -A)" ]; echo $?)"
expect_ok "the same without the limit" tile ../in/torus.obj ../in/tex.png out --tile 16 --subdivide 3
check "... writes an OBJ over the limit" "out.obj above 64 KB" "$(wc -c <out.obj) bytes" \
    "$([ "$(wc -c <out.obj)" -gt 65536 ]; echo $?)"
cd "$W" || exit 1

# ======================================================================
# Image size budget (--max-pixels): refused from the header, before decoding
# ======================================================================
# A valid 8000x8000 all-black PNG of well under 1 MB: 64 M pixels to decode.
cat >"$W/bigpng.c" <<'EOF_C'
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include "stb_image_write.h"
#include <stdlib.h>
int main(int argc, char **argv)
{
    int width = argc > 2 ? atoi(argv[2]) : 8000, height = width;
    unsigned char *pixels = (unsigned char *)calloc((size_t)width * height, 1);
    return !(pixels && stbi_write_png(argv[1], width, height, 1, pixels, width));
}
EOF_C
CMD="$HELPER_CC $STB_INC bigpng.c (test helper)"
# shellcheck disable=SC2086
if $HELPER_CC -O2 -w $STB_INC "$W/bigpng.c" -o "$W/bigpng" -lm 2>"$W/err" && "$W/bigpng" "$W/in/big.png"; then
    pass
    check "helper PNG: 8000x8000, under 1 MB" "8000 8000, < 1000000 bytes" "$(png_size "$W/in/big.png"), $(wc -c <"$W/in/big.png") bytes" \
        "$([ "$(png_size "$W/in/big.png")" = "8000 8000" ] && [ "$(wc -c <"$W/in/big.png")" -lt 1000000 ]; echo $?)"
    for sub in synth tile lapped hpm render; do
        case $sub in
            synth) args="../in/big.png a.png" ;;
            tile) args="../in/torus.obj ../in/big.png out" ;;
            lapped | hpm) args="../in/torus.obj ../in/big.png out" ;;
            render) args="../in/torus.obj ../in/big.png r.png --max-pixels 16777216" ;;
        esac
        # shellcheck disable=SC2086
        expect_error "8000x8000 PNG ($sub)" $sub $args
        err_mentions "8000x8000 PNG ($sub): names the size and --max-pixels" '8000x8000.*--max-pixels'
    done
    expect_error "8000x8000 PNG as map --atlas" map ../in/torus.obj m.obj --atlas ../in/big.png
    err_mentions "8000x8000 PNG as map --atlas: names --max-pixels" 'with --max-pixels'
    # render opens what the tool writes (a lapped bake may be 8192x8192)
    # without the option: its default budget is 8192x8192, not 4096x4096.
    if "$W/bigpng" "$W/in/big4100.png" 4100 && "$W/bigpng" "$W/in/big8200.png" 8200; then
        expect_error "4100x4100 PNG (tile, default budget 4096x4096)" tile ../in/torus.obj ../in/big4100.png out
        newdir
        expect_ok "4100x4100 PNG (render, default budget 8192x8192)" render ../in/torus.obj ../in/big4100.png r.png --size 64x48
        cd "$W" || exit 1
        expect_error "8200x8200 PNG (render, over 8192x8192)" render ../in/torus.obj ../in/big8200.png r.png
        err_mentions "8200x8200 PNG (render): names the size and --max-pixels" '8200x8200.*67108864.*--max-pixels'
    else
        fail "helper for the 4100 and 8200 PNGs" "$CMD" "writes big4100.png and big8200.png" ""
    fi
else
    fail "helper for the big PNG" "$CMD" "compiles and writes big.png" "$(head -c 300 "$W/err")"
fi
# the budget itself: tex.png is 256x256 = 65536 pixels
expect_error "--max-pixels 65535 refuses a 256x256 image" synth ../in/tex.png a.png --tile 32 --max-pixels 65535
err_mentions "--max-pixels 65535: names the size and the option" '256x256.*65535.*--max-pixels'
newdir
expect_ok "--max-pixels 65536 (before the command) takes a 256x256 image" --max-pixels 65536 synth ../in/tex.png a.png --tile 32
expect_ok "--max-pixels=65536 (after the command)" synth ../in/tex.png b.png --tile 32 --max-pixels=65536
cd "$W" || exit 1
expect_error "--max-pixels 0" --max-pixels 0 synth ../in/tex.png a.png
expect_error "--max-pixels abc" synth ../in/tex.png a.png --max-pixels abc
expect_error "--max-pixels without a value" synth ../in/tex.png a.png --max-pixels
run --help
check "--help documents --max-pixels" "'--max-pixels' in the usage" "$OUT" \
    "$(printf '%s' "$OUT" | grep -q -- '--max-pixels'; echo $?)"

# ======================================================================
# Threads (-j N, --jobs N): the same outputs at every N
# ======================================================================
# tile and synth at -j 1 (serial) and -j 2 (the thread pool runs the tiles of
# the synthesis and the ranges of edges of the seam report): byte-identical
# files, and the same summary line.
for jobs in 1 2; do
    mkdir -p "$W/jobs$jobs" && cd "$W/jobs$jobs" || exit 1
    expect_ok "tile -j $jobs" -j $jobs tile ../in/double-torus.obj ../in/tex.png out --colors 2 --tile 16 --seed 3
    echo "$OUT" >tile_summary.txt
    expect_ok "synth --jobs $jobs" synth ../in/tex.png atlas.png --colors 2 --tile 32 --mips --jobs=$jobs
done
cd "$W" || exit 1
for f in out.obj out.mtl out.png atlas.png atlas_mip1.png tile_summary.txt; do
    CMD="tiledtex tile/synth ... -j 1 and -j 2: $f"
    check "-j 2 writes the same $f as -j 1" "identical files" "$(cmp "jobs1/$f" "jobs2/$f" 2>&1)" \
        "$(cmp -s "jobs1/$f" "jobs2/$f"; echo $?)"
done
expect_error "-j 0" -j 0 synth ../in/tex.png a.png --tile 32
err_mentions "-j 0: names the option and the range" "^tiledtex: -j wants an integer from 1 to"
expect_error "-j -1 (after the command)" synth ../in/tex.png a.png --tile 32 -j -1
expect_error "--jobs abc" --jobs abc synth ../in/tex.png a.png --tile 32
err_mentions "--jobs abc: names the option and the value" "^tiledtex: --jobs wants an integer.*'abc'"
expect_error "-j2x" -j2x synth ../in/tex.png a.png --tile 32
expect_error "-j without a value" synth ../in/tex.png a.png --tile 32 -j
newdir
expect_ok "-j4 (make's form) and -j=1" -j4 synth ../in/tex.png a.png --tile 32
expect_ok "-j=1" synth ../in/tex.png b.png --tile 32 -j=1
cd "$W" || exit 1
run --help
check "--help documents -j / --jobs" "'-j, --jobs N' in the usage" "$OUT" \
    "$(printf '%s' "$OUT" | grep -q -- '-j, --jobs N'; echo $?)"

# ======================================================================
# Numbers in written OBJ files: tool_format_float reads back exactly
# ======================================================================
cat >"$W/fmt_check.c" <<'EOF_C'
/* Round trip of tool_format_float on random floats, and its speed against printf;
   tool_format_int against printf. */
#define _POSIX_C_SOURCE 200112L
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <math.h>
#include <stdint.h>
#include "tool.h"

static uint64_t state = 0x9E3779B97F4A7C15u;
static uint32_t next_random(void)
{
    state ^= state << 13; state ^= state >> 7; state ^= state << 17;
    return (uint32_t)(state >> 16);
}
static float random_float(long i)
{
    uint32_t bits;
    float f;
    if (i % 4 == 0) {                     /* mesh-like values */
        f = ((float)next_random() / 4294967296.0f - 0.5f) * 20.0f;
        return f;
    }
    do {                                  /* any finite bit pattern */
        bits = next_random();
        memcpy(&f, &bits, sizeof f);
    } while (!isfinite(f));
    return f;
}
static double seconds(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

int main(int argc, char **argv)
{
    long n = argc > 1 ? atol(argv[1]) : 1000000, i, bad = 0, differs = 0;
    static const float special[] = {0.0f, -0.0f, 1.0f, -1.0f, 0.1f, 0.5f, 1e-4f, 9.99999975e-05f, 1e9f,
                                    999999999.0f, 123456789.0f, 1e-45f, -1e-45f, 1.17549435e-38f, 3.40282347e38f,
                                    -3.40282347e38f, 16777216.0f, 2097151.625f, 0.0001f, 100000000.0f};
    char mine[TOOL_NUMBER_TEXT_SIZE], theirs[64];
    double t0, t_mine, t_printf;
    size_t sink = 0;
    for (i = 0; i < n + (long)(sizeof special / sizeof special[0]); i++) {
        float f = i < n ? random_float(i) : special[i - n], back, back_double;
        tool_format_float(f, mine);
        back = strtof(mine, NULL);
        back_double = (float)strtod(mine, NULL);       /* how the tool's reader reads it */
        if (memcmp(&back, &f, sizeof f) != 0 || memcmp(&back_double, &f, sizeof f) != 0) {
            if (bad++ < 5) printf("no round trip: %.9g -> '%s'\n", f, mine);
        }
        snprintf(theirs, sizeof theirs, "%.9g", f);
        if (strcmp(mine, theirs) != 0 && differs++ < 5) printf("differs from printf: '%s' vs '%s'\n", mine, theirs);
    }
    printf("%ld floats: %ld without an exact round trip, %ld differing from printf %%.9g\n", i, bad, differs);
    {   /* integers: every one from -100000 to 100000, each power of ten and its neighbours, the extremes */
        static const long extremes[] = {LONG_MAX, LONG_MIN, LONG_MIN + 1, LONG_MAX - 1};
        long bad_ints = 0, p10 = 1, k;
        for (k = -100000; k <= 100000; k++) {
            tool_format_int(k, mine);
            snprintf(theirs, sizeof theirs, "%ld", k);
            if (strcmp(mine, theirs) != 0 && bad_ints++ < 5) printf("int %ld written '%s'\n", k, mine);
        }
        for (; p10 <= LONG_MAX / 10; p10 *= 10) {
            long around[6] = {p10 - 1, p10, p10 + 1, -p10 + 1, -p10, -p10 - 1}, j;
            for (j = 0; j < 6; j++) {
                tool_format_int(around[j], mine);
                snprintf(theirs, sizeof theirs, "%ld", around[j]);
                if (strcmp(mine, theirs) != 0 && bad_ints++ < 5) printf("int %ld written '%s'\n", around[j], mine);
            }
        }
        for (k = 0; k < 4; k++) {
            tool_format_int(extremes[k], mine);
            snprintf(theirs, sizeof theirs, "%ld", extremes[k]);
            if (strcmp(mine, theirs) != 0 && bad_ints++ < 5) printf("int %ld written '%s'\n", extremes[k], mine);
        }
        printf("integers: %ld written otherwise than printf %%ld\n", bad_ints);
        bad += bad_ints;
    }
    if (argc > 2) {                               /* speed: the same 1M values both ways */
        long m = 1000000, r, rounds = atol(argv[2]);
        float *values = (float *)malloc((size_t)m * sizeof(float));
        for (i = 0; i < m; i++) values[i] = ((float)next_random() / 4294967296.0f - 0.5f) * 20.0f;
        t0 = seconds();
        for (r = 0; r < rounds; r++)
            for (i = 0; i < m; i++) sink += (size_t)tool_format_float(values[i], mine);
        t_mine = (seconds() - t0) / ((double)m * rounds);
        t0 = seconds();
        for (r = 0; r < rounds; r++)
            for (i = 0; i < m; i++) sink += (size_t)snprintf(theirs, sizeof theirs, "%.9g", values[i]);
        t_printf = (seconds() - t0) / ((double)m * rounds);
        printf("tool_format_float %.1f ns, snprintf %%.9g %.1f ns per float: %.1fx (%zu)\n", t_mine * 1e9,
               t_printf * 1e9, t_printf / t_mine, sink % 10);
        free(values);
    }
    return bad != 0;
}
EOF_C
CMD="$HELPER_CC fmt_check.c examples/format_number.c (test helper)"
if $HELPER_CC -std=c99 -O2 -I"$ROOT" -I"$ROOT/examples" "$W/fmt_check.c" "$ROOT/examples/format_number.c" \
    -o "$W/fmt_check" -lm 2>"$W/err"; then
    FMT=$("$W/fmt_check" 1000000 2>&1)
    check "tool_format_float: 1M random floats read back exactly" "0 without an exact round trip" "$FMT" \
        "$(printf '%s' "$FMT" | grep -q ' 0 without an exact round trip'; echo $?)"
    check "tool_format_int: written as printf %ld writes them" "integers: 0 written otherwise" "$FMT" \
        "$(printf '%s' "$FMT" | grep -q '^integers: 0 written otherwise'; echo $?)"
else
    fail "helper for the float formatter" "$CMD" "compiles" "$(head -c 300 "$W/err")"
fi
# a written mesh reads back as the same numbers: map's OBJ through map again
newdir
expect_ok "map the double torus" map ../in/double-torus.obj a.obj --seed 2
expect_ok "map its output again" map a.obj b.obj --seed 2
check "positions survive writing and reading" "identical v lines" "differ" \
    "$(cmp -s <(grep '^v ' a.obj) <(grep '^v ' b.obj); echo $?)"
cd "$W" || exit 1

# ======================================================================
# PNG files: png_write.c's files decode to their pixels, with valid CRCs and
# Adler-32, the same bytes at -j 1 and -j 2
# ======================================================================
cat >"$W/png_check.c" <<'EOF_C'
/* Images of every channel count and several shapes (one texel, one row, one
   column, flat, noise over several compressed pieces, a repeating
   pattern) through png_write_to_memory at -j 1 and -j 2: each file must be
   the same at both, decode (stb_image) to the same bytes, have a correct
   CRC on every chunk and a zlib stream whose Adler-32 matches its data.
   Prints one line per problem and "checked N images". */
#define STB_IMAGE_IMPLEMENTATION
#include "stb_image.h"
#define TILEDTEX_IMPLEMENTATION
#include "tool.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static unsigned long be32(const unsigned char *p)
{
    return (unsigned long)p[0] << 24 | (unsigned long)p[1] << 16 | (unsigned long)p[2] << 8 | p[3];
}

static unsigned long crc32_naive(const unsigned char *p, size_t n)
{
    unsigned long c = 0xfffffffful;
    size_t i;
    int k;
    for (i = 0; i < n; i++) {
        c ^= p[i];
        for (k = 0; k < 8; k++) c = c & 1 ? 0xedb88320ul ^ (c >> 1) : c >> 1;
    }
    return c ^ 0xfffffffful;
}

/* Chunks' CRCs, the IDAT data inflated, its Adler-32; 0 when all good. */
static int check_file(const unsigned char *png, size_t size, const char *what)
{
    unsigned char *idat = malloc(size), *raw;
    size_t at = 8, nidat = 0, i;
    unsigned long s1 = 1, s2 = 0;
    int raw_length, bad = 0;
    while (at + 12 <= size) {
        unsigned long n = be32(png + at);
        if (at + 12 + n > size) { printf("%s: chunk past the end\n", what); return 1; }
        if (crc32_naive(png + at + 4, 4 + n) != be32(png + at + 8 + n)) { printf("%s: bad CRC\n", what); bad = 1; }
        if (memcmp(png + at + 4, "IDAT", 4) == 0) { memcpy(idat + nidat, png + at + 8, n); nidat += n; }
        at += 12 + n;
    }
    if (at != size || memcmp(png + size - 8, "IEND", 4) != 0) { printf("%s: does not end with IEND\n", what); bad = 1; }
    raw = (unsigned char *)stbi_zlib_decode_malloc((const char *)idat, (int)nidat, &raw_length);
    if (!raw) { printf("%s: the zlib stream does not inflate\n", what); free(idat); return 1; }
    for (i = 0; i < (size_t)raw_length; i++) { s1 = (s1 + raw[i]) % 65521; s2 = (s2 + s1) % 65521; }
    if ((s2 << 16 | s1) != be32(idat + nidat - 4)) { printf("%s: wrong Adler-32\n", what); bad = 1; }
    free(raw);
    free(idat);
    return bad;
}

int main(void)
{
    static const int shapes[][2] = {{1, 1}, {300, 1}, {1, 300}, {700, 500}, {1024, 700}, {333, 257}};
    int s, c, kind, checked = 0, bad = 0;
    unsigned long state = 12345;
    for (s = 0; s < 6; s++)
        for (c = 1; c <= 4; c++)
            for (kind = 0; kind < 3; kind++) {
                int w = shapes[s][0], h = shapes[s][1], x, y, k, ww, hh, cc;
                size_t n = (size_t)w * h * c, sizes[2];
                unsigned char *pixels = malloc(n), *png[2], *back;
                char what[96];
                for (y = 0; y < h; y++)
                    for (x = 0; x < w; x++)
                        for (k = 0; k < c; k++) {
                            size_t i = ((size_t)y * w + x) * c + k;
                            state = state * 6364136223846793005ul + 1442695040888963407ul;
                            pixels[i] = kind == 0 ? (unsigned char)(77 + k)                     /* flat */
                                        : kind == 1 ? (unsigned char)(state >> 33)               /* noise */
                                                    : (unsigned char)((x * 7 + y * 3 + k * 50) % 23 * 11);
                        }
                snprintf(what, sizeof what, "%dx%d, %d channels, %s", w, h, c,
                         kind == 0 ? "flat" : kind == 1 ? "noise" : "pattern");
                for (k = 0; k < 2; k++) {
                    tool_set_jobs(k + 1);
                    if (png_write_to_memory(pixels, w, h, c, &png[k], &sizes[k]) != 0) {
                        printf("%s: not encoded\n", what);
                        return 1;
                    }
                }
                if (sizes[0] != sizes[1] || memcmp(png[0], png[1], sizes[0]) != 0) {
                    printf("%s: -j 2 wrote other bytes than -j 1\n", what);
                    bad++;
                }
                bad += check_file(png[0], sizes[0], what);
                back = stbi_load_from_memory(png[0], (int)sizes[0], &ww, &hh, &cc, 0);
                if (!back || ww != w || hh != h || cc != c || memcmp(back, pixels, n) != 0) {
                    printf("%s: does not decode to its pixels\n", what);
                    bad++;
                }
                stbi_image_free(back);
                free(png[0]);
                free(png[1]);
                free(pixels);
                checked++;
            }
    printf("checked %d images\n", checked);
    return bad != 0;
}
EOF_C
CMD="$HELPER_CC png_check.c examples/png_write.c executor.c (test helper)"
# shellcheck disable=SC2086
if $HELPER_CC -std=c99 -O1 -w -pthread -I"$ROOT" -I"$ROOT/examples" $STB_INC "$W/png_check.c" \
    "$ROOT/examples/png_write.c" "$ROOT/examples/executor.c" -o "$W/png_check" -lm 2>"$W/err"; then
    PNGCHECK=$("$W/png_check" 2>&1)
    check "PNG files: decode to their pixels, CRCs and Adler-32 right, same at -j 1 and -j 2" \
        "checked 72 images, no problem" "$PNGCHECK" \
        "$([ "$PNGCHECK" = "checked 72 images" ]; echo $?)"
else
    fail "helper for the PNG writer" "$CMD" "compiles" "$(head -c 300 "$W/err")"
fi

# ======================================================================
# Colour: linear light inside, sRGB in the files (converted once each way);
# the seam report
# ======================================================================
cat >"$W/pixstat.c" <<'EOF_C'
/* pixstat FILE: "min max" of every r, g, b byte of an image;
   pixstat FILE X Y: "r g b" of one pixel. */
#define STB_IMAGE_IMPLEMENTATION
#include "stb_image.h"
#include <stdio.h>
#include <stdlib.h>
int main(int argc, char **argv)
{
    int w, h, n, lo = 255, hi = 0;
    long i;
    unsigned char *p = argc > 1 ? stbi_load(argv[1], &w, &h, &n, 3) : NULL;
    if (!p) return 1;
    if (argc == 4) {
        long at = 3 * ((long)atoi(argv[3]) * w + atoi(argv[2]));
        printf("%d %d %d\n", p[at], p[at + 1], p[at + 2]);
        return 0;
    }
    for (i = 0; i < 3L * w * h; i++) {
        if (p[i] < lo) lo = p[i];
        if (p[i] > hi) hi = p[i];
    }
    printf("%d %d\n", lo, hi);
    return 0;
}
EOF_C
newdir
# a flat mid-grey image (sRGB 128, binary PGM), a unit square facing +z with UVs
{ printf 'P5\n64 64\n255\n'; head -c 4096 /dev/zero | tr '\0' '\200'; } >grey.pgm
printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n' >square_uv.obj
CMD="$HELPER_CC $STB_INC pixstat.c (test helper)"
if $HELPER_CC -O2 -w $STB_INC "$W/pixstat.c" -o "$W/pixstat" -lm 2>"$W/err"; then
    # sRGB 128 is linear 0.216; decoded twice it would come out darker, never
    # decoded it would be encoded to 188: the atlas and its mip stay 128.
    expect_ok "synth a flat mid-grey image" synth grey.pgm grey_atlas.png --tile 16 --mips
    CMD="pixstat grey_atlas.png"
    check "synth keeps sRGB 128 grey (no double conversion)" "128 128" "$("$W/pixstat" grey_atlas.png 2>&1)" \
        "$([ "$("$W/pixstat" grey_atlas.png 2>/dev/null)" = "128 128" ]; echo $?)"
    check "synth --mips: the mip of flat grey stays 128" "128 128" "$("$W/pixstat" grey_atlas_mip1.png 2>&1)" \
        "$([ "$("$W/pixstat" grey_atlas_mip1.png 2>/dev/null)" = "128 128" ]; echo $?)"
    # Rendered face-on, lit by 0.32 ambient + 0.72 key (cos 45 deg) + 0.22
    # fill (cos 63.4 deg) = 0.928 in linear light: 0.216 * 0.928 encodes to
    # 124. A double gamma would give about 182 (never decoded) or 51 (never
    # encoded).
    expect_ok "render a flat mid-grey texture" render square_uv.obj grey.pgm view.png --size 64x64 --yaw 0 --pitch 0
    CMD="pixstat view.png 32 32"
    px=$("$W/pixstat" view.png 32 32 2>/dev/null)
    check "render: mid-grey stays mid-grey (no double gamma)" "r g b each 124 +- 4" "$px" \
        "$(printf '%s\n' "$px" | awk '{exit !(NF == 3 && $1 >= 120 && $1 <= 128 && $2 == $1 && $3 == $1)}'; echo $?)"
    # --unlit draws the texture's colour as it is (what tests/import_check.sh
    # compares Blender's emission render with): a flat colour comes out as
    # exactly that colour, where the lit picture above is darker.
    expect_ok "render a flat mid-grey texture --unlit" render square_uv.obj grey.pgm unlit.png --size 64x64 \
        --yaw 0 --pitch 0 --unlit
    CMD="pixstat unlit.png 32 32"
    check "render --unlit: flat grey 128 is drawn as 128 (no lighting)" "128 128 128" \
        "$("$W/pixstat" unlit.png 32 32 2>&1)" "$([ "$("$W/pixstat" unlit.png 32 32 2>/dev/null)" = "128 128 128" ]; echo $?)"
    { printf 'P6\n4 4\n255\n'; for k in $(seq 16); do printf '\310\144\062'; done; } >orange.ppm
    expect_ok "render a flat orange texture --unlit" render square_uv.obj orange.ppm orange.png --size 64x64 \
        --yaw 20 --pitch 10 --unlit
    CMD="pixstat orange.png 32 32"
    check "render --unlit: flat (200, 100, 50) is drawn as exactly that colour" "200 100 50" \
        "$("$W/pixstat" orange.png 32 32 2>&1)" "$([ "$("$W/pixstat" orange.png 32 32 2>/dev/null)" = "200 100 50" ]; echo $?)"
    expect_ok "render the flat orange texture lit" render square_uv.obj orange.ppm orange_lit.png --size 64x64 \
        --yaw 20 --pitch 10
    CMD="pixstat orange_lit.png 32 32"
    check "render: lit, the flat orange is not its texture's colour (so --unlit changed something)" \
        "not 200 100 50" "$("$W/pixstat" orange_lit.png 32 32 2>&1)" \
        "$([ "$("$W/pixstat" orange_lit.png 32 32 2>/dev/null)" != "200 100 50" ]; echo $?)"
else
    fail "helper for reading pixels" "$CMD" "compiles" "$(head -c 300 "$W/err")"
fi
# one quad has no interior edge: the summary says the seams were not measured
expect_ok "tile a one-quad mesh" tile square_uv.obj ../in/tex.png one
check "tile one quad: seam score not measured" "'seam score: not measured (reason)'" "$OUT" \
    "$(printf '%s' "$OUT" | grep -qE 'seam score: not measured \(.+\)' && [ -z "$(summary_seam)" ]; echo $?)"
# the report says how many edges it measured of how many
expect_ok "tile the torus for the seam report" tile ../in/torus.obj ../in/tex.png t
check "tile: seam score names the edges measured" "'seam score X (N of M edges'" "$OUT" \
    "$(printf '%s' "$OUT" | grep -qE 'seam score -?[0-9.]+ \([0-9]+ of [0-9]+ edges'; echo $?)"
cd "$W" || exit 1
# --unlit draws no lighting, which is all --normal would change
expect_usage_error "render --unlit with --normal" render ../in/torus.obj ../in/tex.png view.png --unlit \
    --normal ../in/tex.png
err_mentions "render --unlit with --normal: names both" 'unlit.*normal'

# ======================================================================
# Command-line conventions (issue 11, item 5)
# ======================================================================
# An OUT_PREFIX ending in a known extension loses it: "out.obj" writes
# out.obj + out.mtl, never out.obj.obj, in every command that takes a prefix
# (.glb and .gltf choose those formats: below).
prefix_case() {
    local what=$1 expect=$2
    shift 2
    newdir
    expect_ok "$what" "$@"
    CMD="ls after tiledtex $*"
    check "$what: writes $expect" "$expect" "$(ls | tr '\n' ' ')" \
        "$(for f in $expect; do [ -s "$f" ] || exit 1; done; ! ls | grep -qE '\.(obj|mtl|png|glb|gltf)\.'; echo $?)"
    cd "$W" || exit 1
}
prefix_case "tile OUT_PREFIX out.obj" "out.obj out.mtl out.png" tile ../in/torus.obj ../in/tex.png out.obj
check "tile OUT_PREFIX out.obj: mtllib names out.mtl" "mtllib out.mtl" "$(grep mtllib "$W/d$NEWDIR_N/out.obj" 2>&1)" \
    "$(grep -qx 'mtllib out.mtl' "$W/d$NEWDIR_N/out.obj" 2>/dev/null; echo $?)"
prefix_case "tile OUT_PREFIX out.PNG" "out.obj out.mtl out.png" tile ../in/torus.obj ../in/tex.png out.PNG
prefix_case "lapped OUT_PREFIX l.mtl" "l.obj l.mtl l.png" lapped ../in/torus.obj ../in/lap.png l.mtl --scale 1.5
prefix_case "hpm OUT_PREFIX h.Obj" "h.obj h.mtl" hpm ../in/torus.obj ../in/lap.png h.Obj
prefix_case "polycube OUT_PREFIX p.OBJ" "p.obj p.mtl p.png p_polycube.obj" polycube ../in/spheretri.obj ../in/tex.png \
    p.OBJ --resolution 4

# "-" is the standard output where a command writes one file, and refused
# (usage error, no file called "-") where it writes several.
for c in tile lapped hpm polycube; do
    expect_usage_error "$c OUT_PREFIX -" $c ../in/spheretri.obj ../in/lap.png -
    err_mentions "$c OUT_PREFIX -: says why" "standard output"
done
expect_usage_error "map - --atlas (OBJ + MTL)" map ../in/torus.obj - --atlas ../in/tex.png
expect_usage_error "synth - --mips (several PNGs)" synth ../in/lap.png - --mips
newdir
run render ../in/torus.obj ../in/tex.png - --size 32x32
check "render to -: a PNG on stdout, no file" "exit 0, stdout starting \\x89PNG, empty directory" \
    "exit $RC, stdout $(head -c 4 "$W/out" | od -An -c | tr -s ' '), files: $(ls -A)" \
    "$([ $RC -eq 0 ] && [ "$(head -c 4 "$W/out" | od -An -tx1 | tr -d ' ')" = 89504e47 ] && [ -z "$(ls -A)" ]; echo $?)"
run generate texture - --size 32
check "generate texture to -: a 32x32 PNG on stdout" "exit 0, 32 32" "exit $RC, $(png_size "$W/out")" \
    "$([ $RC -eq 0 ] && [ "$(png_size "$W/out")" = "32 32" ] && [ -z "$(ls -A)" ]; echo $?)"
run generate mesh - --shape torus
check "generate mesh to -: the OBJ on stdout, no summary" "exit 0, only OBJ lines" "exit $RC, $(head -c 200 "$W/out")" \
    "$([ $RC -eq 0 ] && grep -q '^f ' "$W/out" && ! grep -q '^wrote' "$W/out" && [ -z "$(ls -A)" ]; echo $?)"
run map ../in/torus.obj -
check "map to -: the OBJ with UVs on stdout" "exit 0, vt and f lines, no file" "exit $RC, $(head -c 200 "$W/out")" \
    "$([ $RC -eq 0 ] && grep -q '^vt ' "$W/out" && grep -q '^f ' "$W/out" && ! grep -q '^\.\./in/torus\.obj:' "$W/out" &&
       [ -z "$(ls -A)" ]; echo $?)"
cd "$W" || exit 1

# --up: an axis name or X,Y,Z wherever it exists, the same meaning in both forms
newdir
expect_ok "render --up z" render ../in/torus.obj ../in/tex.png z.png --size 48x48 --up z
expect_ok "render --up 0,0,3" render ../in/torus.obj ../in/tex.png zv.png --size 48x48 --up 0,0,3
CMD="cmp z.png zv.png"
check "render --up 0,0,3 draws what --up z does" "identical PNGs" "$(cmp z.png zv.png 2>&1)" \
    "$(cmp -s z.png zv.png; echo $?)"
expect_ok "render --up 1,1,0 (a slanted up)" render ../in/torus.obj ../in/tex.png s.png --size 48x48 --up 1,1,0
expect_ok "lapped --up z" lapped ../in/torus.obj ../in/lap.png a --pasting --scale 1.5 --up z
expect_ok "lapped --up 0,0,1" lapped ../in/torus.obj ../in/lap.png b --pasting --scale 1.5 --up 0,0,1
CMD="cmp a.obj b.obj (but the mtllib line)"
check "lapped --up z pastes as --up 0,0,1" "identical OBJs" "$(diff <(grep -v mtllib a.obj 2>&1) <(grep -v mtllib b.obj 2>&1) | head -3)" \
    "$(cmp -s <(grep -v mtllib a.obj 2>/dev/null) <(grep -v mtllib b.obj 2>/dev/null) && [ -s a.obj ]; echo $?)"
cd "$W" || exit 1
expect_usage_error "render --up w" render ../in/torus.obj ../in/tex.png v.png --up w
expect_usage_error "render --up 0,0,0" render ../in/torus.obj ../in/tex.png v.png --up 0,0,0
expect_usage_error "lapped --up w" lapped ../in/torus.obj ../in/lap.png out --up w

# --quiet (or -q, before or after the command): nothing but errors - no
# summary on stdout, no progress, report or warning line on stderr; the
# files are still written.
quiet_case() {
    local what=$1 file=$2
    shift 2
    newdir
    run "$@"
    check "$what: silent" "exit 0, nothing on stdout or stderr, $file written" \
        "exit $RC, stdout: $OUT, stderr: $ERR, files: $(ls | tr '\n' ' ')" \
        "$([ $RC -eq 0 ] && [ -z "$OUT" ] && [ -z "$ERR" ] && [ -s "$file" ]; echo $?)"
    cd "$W" || exit 1
}
quiet_case "tile --quiet (triangles: the quadrangulation line too)" o.png tile ../in/spheretri.obj ../in/tex.png o --quiet
quiet_case "-q lapped" o.obj -q lapped ../in/torus.obj ../in/lap.png o --scale 1.5
quiet_case "hpm -q" o.obj hpm ../in/torus.obj ../in/lap.png o -q
quiet_case "polycube --quiet" o.png polycube ../in/spheretri.obj ../in/tex.png o --resolution 4 --quiet
quiet_case "synth --quiet" a.png synth ../in/tex.png a.png --quiet
quiet_case "map --quiet" o.obj map ../in/torus.obj o.obj --quiet
quiet_case "render --quiet" v.png render ../in/torus.obj ../in/tex.png v.png --size 32x32 --quiet
quiet_case "generate texture --quiet" t.png --quiet generate texture t.png --size 32
quiet_case "generate mesh -q" m.obj generate mesh m.obj --shape torus -q
expect_error "--quiet still prints errors" --quiet tile ../in/nope.obj ../in/tex.png out
err_mentions "--quiet still prints errors: names the file" 'nope\.obj'

# help for a command that does not exist is a usage error like any other
expect_usage_error "help nosuch" help nosuch
err_mentions "help nosuch: names it" "nosuch"

# -V and --version print the header's version and exit 0
VERSION=$(sed -n 's/^#define TILEDTEX_VERSION_STRING "\(.*\)"$/\1/p' "$ROOT/tiledtex.h")
for flag in -V --version; do
    run $flag
    check "$flag prints the version" "exit 0, stdout 'tiledtex $VERSION'" "exit $RC, stdout: $OUT, stderr: $ERR" \
        "$([ $RC -eq 0 ] && [ "$OUT" = "tiledtex $VERSION" ] && [ -n "$VERSION" ]; echo $?)"
done

# ======================================================================
# The input's normals (vn) carried into every OBJ output
# ======================================================================
# The unit sphere of triangles with deliberately turned normals: at vertex
# p the file says R p, p turned 90 degrees about z, (-y, x, z), which the
# tool would never compute. Carried linearly (within each face) to a new
# point sum w_i p_i and renormalised, they stay R p / |p| there exactly,
# for any number of steps: so every output corner's vn must be R of its
# vertex, normalised. TURN is the sign: -1 writes -R p (facing inward).
# tilted_obj SOURCE TURN > FILE
tilted_obj() {
    awk -v turn="$2" '
        $1 == "v" { print; n++; x[n] = $2; y[n] = $3; z[n] = $4; next }
        $1 == "vn" { next }
        $1 == "f" { if (!normals) { for (i = 1; i <= n; i++) printf "vn %.9g %.9g %.9g\n", -turn * y[i], turn * x[i], turn * z[i]; normals = 1 }
                    printf "f"; for (i = 2; i <= NF; i++) { split($i, c, "/"); printf " %s//%s", c[1], c[1] }; print ""; next }
        { print }' "$1"
}
# normals_against FILE MODE: "corners worst": face corners with a vn, and the
# worst angle in degrees between a corner's vn and its vertex's expected
# normal: MODE turned = R p, radial = p; a corner without a vn counts 180.
normals_against() {
    awk -v mode="$2" '
        $1 == "v"  { nv++; x[nv] = $2; y[nv] = $3; z[nv] = $4 }
        $1 == "vn" { nn++; a[nn] = $2; b[nn] = $3; c[nn] = $4 }
        $1 == "f"  { for (i = 2; i <= NF; i++) {
                         corners++; split($i, p, "/"); v = p[1]; q = p[3]
                         if (q == "" || q < 1 || q > nn) { worst = 180; continue }
                         ex = mode == "turned" ? -y[v] : x[v]; ey = mode == "turned" ? x[v] : y[v]; ez = z[v]
                         d = ex * a[q] + ey * b[q] + ez * c[q]
                         d = d / sqrt((ex * ex + ey * ey + ez * ez) * (a[q] * a[q] + b[q] * b[q] + c[q] * c[q]))
                         if (d > 1) d = 1
                         angle = atan2(sqrt(1 - d * d), d) * 57.2957795
                         if (angle > worst) worst = angle } }
        END { printf "%d %.6f\n", corners, worst }' "$1" 2>/dev/null
}
# check_turned WHAT FILE: every corner of FILE has the file's turned normal
# (within 0.01 degrees: 9 digits written, float arithmetic)
check_turned() {
    local corners worst
    read -r corners worst <<<"$(normals_against "$2" turned)"
    check "$1: the input's (turned) normals at every corner, interpolated where new vertices are" \
        "worst angle to R p under 0.01 degrees" "$worst degrees over $corners corners" \
        "$(awk -v c="${corners:-0}" -v w="${worst:-x}" 'BEGIN { exit !(c > 0 && w ~ /^[0-9.]+$/ && w + 0 < 0.01) }'; echo $?)"
}
tilted_obj "$W/in/spheretri.obj" 1 >"$W/in/sphere_turned.obj"
newdir
expect_ok "tile, normals from the file" tile ../in/sphere_turned.obj ../in/tex.png t --tile 16 --subdivide 1
check_turned "tile (quadrangulated, --subdivide 1)" t.obj
expect_ok "map --subdivide 2, normals from the file" map ../in/sphere_turned.obj m.obj --subdivide 2
check_turned "map --subdivide 2" m.obj
expect_ok "lapped --subdivide 1 --bake, normals from the file" lapped ../in/sphere_turned.obj ../in/lap.png l \
    --subdivide 1 --bake 128 --patches 1 --pasting
check_turned "lapped --subdivide 1: the pasting OBJ" l.obj
check_turned "lapped --subdivide 1: the baked OBJ" l_baked.obj
expect_ok "hpm, normals from the file" hpm ../in/sphere_turned.obj ../in/lap.png h
check_turned "hpm" h.obj
expect_ok "polycube, normals from the file" polycube ../in/sphere_turned.obj ../in/tex.png p --tile 16 --resolution 6
check_turned "polycube (split triangles)" p.obj
# the same sphere with the normals `generate` computes: the same files but for the normals
expect_ok "tile, the same sphere with computed normals" tile ../in/spheretri.obj ../in/tex.png plain --tile 16 \
    --subdivide 1
CMD="diff t.obj plain.obj"
# (the f lines compared without their vn indices: distinct normals are
# written once each, so other normals may share other vn lines)
check "tile: the file's normals change the vn lines and nothing else" "same v/vt lines and v/vt of f lines, different vn lines" \
    "$(diff <(grep -v '^#' t.obj) <(grep -v '^#' plain.obj) 2>&1 | grep -c '^[<>] vn') vn lines differ" \
    "$(diff -q <(grep -E '^(v|vt) ' t.obj) <(grep -E '^(v|vt) ' plain.obj) >/dev/null &&
        diff -q <(grep '^f ' t.obj | sed 's|/[0-9]*\( \|$\)|\1|g') <(grep '^f ' plain.obj | sed 's|/[0-9]*\( \|$\)|\1|g') >/dev/null &&
        ! diff -q <(grep '^vn ' t.obj) <(grep '^vn ' plain.obj) >/dev/null; echo $?)"
cd "$W" || exit 1

# a vn on some corners only: computed normals, and a note
tilted_obj "$W/in/spheretri.obj" 1 | awk '$1 == "f" && ++k % 2 == 0 { gsub(/\/\/[0-9]+/, ""); } { print }' \
    >"$W/in/sphere_some_normals.obj"
newdir
expect_ok "map, a vn on some corners only" map ../in/sphere_some_normals.obj m.obj
read -r corners worst <<<"$(normals_against m.obj radial)"
check "map, a vn on some corners only: a note, and computed (radial, not turned) normals" \
    "one note '1920 of 3840 face corners have no usable normal', worst angle to p under 10 degrees" \
    "stderr: $ERR; worst $worst degrees" \
    "$(printf '%s' "$ERR" | grep -c '1920 of 3840 face corners have no usable normal' | grep -qx 1 &&
        awk -v w="${worst:-x}" 'BEGIN { exit !(w ~ /^[0-9.]+$/ && w + 0 < 10) }'; echo $?)"
cd "$W" || exit 1

# --weld: a sphere with every triangle's own three vertices (and normals),
# welded; the corners keep their normals
awk '$1 == "v" { n++; p[n] = $2 " " $3 " " $4 }
     $1 == "vn" { m++; q[m] = $2 " " $3 " " $4 }
     $1 == "f" { f = f "f"; for (i = 2; i <= NF; i++) { split($i, c, "/"); k++; vp[k] = p[c[1]]; vq[k] = q[c[3]]
                 f = f " " k "//" k } f = f "\n" }
     END { for (i = 1; i <= k; i++) print "v " vp[i]; for (i = 1; i <= k; i++) print "vn " vq[i]; printf "%s", f }' \
    "$W/in/sphere_turned.obj" >"$W/in/sphere_turned_unwelded.obj"
newdir
expect_ok "--weld lapped, normals from the file" --weld lapped ../in/sphere_turned_unwelded.obj ../in/lap.png l \
    --patches 1
read -r corners worst <<<"$(normals_against l.obj turned)"
check "--weld lapped: the sphere welded (1280 triangles, no --weld note), each corner with its own turned normal" \
    "'1280 triangles', worst angle to R p under 0.01 degrees" "$OUT $ERR; worst $worst degrees" \
    "$(printf '%s' "$OUT" | grep -q '1280 triangles' && ! printf '%s' "$ERR" | grep -q -- '--weld' &&
        awk -v w="${worst:-x}" 'BEGIN { exit !(w ~ /^[0-9.]+$/ && w + 0 < 0.01) }'; echo $?)"
cd "$W" || exit 1

# an inside-out sphere: its normals turn round with its faces when they
# followed the inward winding (-R p), and stay when they faced out (R p)
for turn in -1 1; do
    tilted_obj "$W/in/spheretri.obj" "$turn" | awk '$1 == "f" { print "f", $2, $4, $3; next } { print }' \
        >"$W/in/sphere_inward_$turn.obj"
    newdir
    expect_ok "polycube inside-out, file normals ${turn/1/R} p" polycube ../in/sphere_inward_$turn.obj ../in/tex.png p \
        --tile 16 --resolution 6
    check_turned "polycube inside-out sphere whose normals were ${turn/1/R} p" p.obj
    cd "$W" || exit 1
done

# a face naming a normal that does not exist is an error at its line
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//2 3//1\n' >"$W/in/bad_vn.obj"
expect_error "map, a vn index out of range" map ../in/bad_vn.obj m.obj
err_mentions "a vn index out of range: the line and the normal named" 'bad_vn\.obj:5: face refers to normal 2 but only 1 is defined'
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//-2\n' >"$W/in/bad_vn_relative.obj"
expect_error "hpm, a relative vn index out of range" hpm ../in/bad_vn_relative.obj ../in/lap.png h
err_mentions "a relative vn index out of range: named" 'normal -2'

# ======================================================================
# glTF output (.glb): tile, lapped, hpm, polycube; --triangles
# ======================================================================
# glb_probe: a test helper built from the tool's own gltf.c. It reads the
# container (header, chunks) and the BIN chunk's numbers, so the checks
# below need no JSON or glTF library; and it writes a GLB with every
# material slot through gltf_write, the way a command hands over its maps.
cat >"$W/glb_probe.c" <<'EOF_C'
/* glb_probe check FILE.glb           "ok" and the JSON chunk on one line, or "bad: why" (exit 1)
   glb_probe floats FILE.glb OFF N    N little-endian floats from byte OFF of the BIN chunk, %.9g a line
   glb_probe ushorts|uints FILE.glb OFF N   N little-endian 16/32-bit integers, one a line
   glb_probe bytes FILE.glb OFF N     N bytes of the BIN chunk, raw, on stdout
   glb_probe write OUT.glb MAPS       a quad and a triangle through gltf_write, with the maps named in MAPS
                                      (comma-separated: base normal roughness metallic occlusion small_metallic,
                                      or none); prints the error and exits 1 when gltf_write refuses */
#define TILEDTEX_IMPLEMENTATION
#include "tiledtex.h"
#include "tool.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
static unsigned long u32(const unsigned char *p) { return p[0] | (unsigned long)p[1] << 8 | (unsigned long)p[2] << 16 | (unsigned long)p[3] << 24; }
static int bad(const char *why) { printf("bad: %s\n", why); return 1; }
static tt_image *flat(int size, float r, float g, float b)
{
    tt_image *image;
    int i;
    if (tt_image_create(size, size, NULL, &image, NULL) != TT_OK) exit(3);
    for (i = 0; i < size * size; i++) {
        image->pixels[4 * i] = r; image->pixels[4 * i + 1] = g; image->pixels[4 * i + 2] = b; image->pixels[4 * i + 3] = 1;
    }
    return image;
}
int main(int argc, char **argv)
{
    unsigned char *data;
    size_t size;
    char err[512];
    if (argc == 4 && strcmp(argv[1], "write") == 0) {
        static const float pos[15] = {0,0,0, 1,0,0, 1,1,0, 0,1,0, 2,0.5f,0};
        static const int corner_vert[7] = {0, 1, 2, 3, 1, 4, 2}, face_size[2] = {4, 3};
        static const float uv[14] = {0,0, 1,0, 1,1, 0,1, 1,0, 1.5f,0.5f, 1,1};
        /* the triangle's last corner has no normal (zero): it takes its face's, (0, 0, 1) */
        static const float normal[21] = {0,0,1, 0,0,1, 0,0,1, 0,0,1, 0,0,1, 0,0,1, 0,0,0};
        obj_write_desc mesh;
        tool_material material;
        const char *maps = argv[3];
        unsigned char *glb;
        size_t glb_size;
        FILE *f;
        memset(&mesh, 0, sizeof mesh);
        mesh.nverts = 5; mesh.pos = pos; mesh.nfaces = 2; mesh.face_size = face_size;
        mesh.corner_vert = corner_vert; mesh.corner_uv = uv; mesh.corner_normal = normal;
        memset(&material, 0, sizeof material);
        material.name = "probe";
        if (strstr(maps, "base")) material.base_color = flat(8, 0.2f, 0.4f, 0.6f);
        if (strstr(maps, "normal")) material.normal = flat(8, 0.5f, 0.5f, 1.0f);
        if (strstr(maps, "roughness")) material.roughness = flat(8, 0.25f, 0.25f, 0.25f);
        if (strstr(maps, "small_metallic")) material.metallic = flat(4, 0.5f, 0.5f, 0.5f);
        else if (strstr(maps, "metallic")) material.metallic = flat(8, 0.5f, 0.5f, 0.5f);
        if (strstr(maps, "occlusion")) material.occlusion = flat(8, 0.75f, 0.75f, 0.75f);
        if (gltf_write(&mesh, &material, "probe", &glb, &glb_size, err, sizeof err) != 0) {
            printf("gltf_write: %s\n", err);
            return 1;
        }
        f = fopen(argv[2], "wb");
        if (!f || fwrite(glb, 1, glb_size, f) != glb_size || fclose(f) != 0) return 3;
        free(glb);
        tt_image_free((tt_image *)material.base_color); tt_image_free((tt_image *)material.normal);
        tt_image_free((tt_image *)material.roughness); tt_image_free((tt_image *)material.metallic);
        tt_image_free((tt_image *)material.occlusion);
        return 0;
    }
    if (argc < 3 || tool_read_file(argv[2], &data, &size, err, sizeof err) != 0) return 2;
    if (strcmp(argv[1], "check") == 0) {
        unsigned long json_length, bin_length;
        if (size < 28 || memcmp(data, "glTF", 4) != 0) return bad("no glTF magic");
        if (u32(data + 4) != 2) return bad("version is not 2");
        if (u32(data + 8) != size) return bad("the header's length is not the file's");
        json_length = u32(data + 12);
        if (memcmp(data + 16, "JSON", 4) != 0) return bad("the first chunk is not JSON");
        if (json_length % 4 || 20 + json_length + 8 > size) return bad("the JSON chunk's length");
        bin_length = u32(data + 20 + json_length);
        if (memcmp(data + 24 + json_length, "BIN\0", 4) != 0) return bad("the second chunk is not BIN");
        if (bin_length % 4 || 28 + json_length + bin_length != size) return bad("the BIN chunk's length");
        if (memchr(data + 20, '\n', json_length)) return bad("a newline in the JSON (this helper prints it on one line)");
        printf("ok\n%.*s\n", (int)json_length, (const char *)data + 20);
        return 0;
    }
    if (argc == 5) {
        unsigned long json_length = u32(data + 12), bin = 28 + json_length, offset = strtoul(argv[3], NULL, 10),
                      count = strtoul(argv[4], NULL, 10), i;
        unsigned long width = strcmp(argv[1], "ushorts") == 0 ? 2 : strcmp(argv[1], "bytes") == 0 ? 1 : 4;
        if (bin + offset + count * width > size) return bad("past the end of the BIN chunk");
        for (i = 0; i < count; i++) {
            const unsigned char *p = data + bin + offset + width * i;
            if (strcmp(argv[1], "floats") == 0) {
                unsigned long bits = u32(p);
                uint32_t b32 = (uint32_t)bits;
                float value;
                memcpy(&value, &b32, 4);
                printf("%.9g\n", value);
            } else if (width == 2) printf("%u\n", (unsigned)(p[0] | p[1] << 8));
            else if (width == 4) printf("%lu\n", u32(p));
            else putchar(*p);
        }
        return 0;
    }
    return 2;
}
EOF_C
GLB_PROBE=""
CMD="$HELPER_CC glb_probe.c examples/gltf.c image_io.c png_write.c executor.c tool_io.c obj.c format_number.c (test helper)"
if $HELPER_CC -std=c99 -O1 -w -pthread -I"$ROOT" -I"$ROOT/examples" $STB_INC "$W/glb_probe.c" "$ROOT/examples/gltf.c" \
    "$ROOT/examples/image_io.c" "$ROOT/examples/png_write.c" "$ROOT/examples/executor.c" "$ROOT/examples/tool_io.c" \
    "$ROOT/examples/obj.c" "$ROOT/examples/format_number.c" -o "$W/glb_probe" -lm 2>"$W/err"; then
    GLB_PROBE=$W/glb_probe
else
    fail "helper for GLB files" "$CMD" "compiles" "$(head -c 300 "$W/err")"
fi

# The Khronos validator, when tests/ensure_deps.sh could install it (node and
# npm's gltf-validator in build/gltf-validator): every GLB below goes through
# it. Without it those checks are skipped, and said so once.
GLTF_VALIDATOR=""
if command -v node >/dev/null 2>&1 && node "$ROOT/tests/gltf_validate.js" --version >/dev/null 2>&1; then
    GLTF_VALIDATOR=yes
else
    echo "note: the glTF validator is not installed (node + npm's gltf-validator; bash tests/ensure_deps.sh test" \
        "installs it as root): the GLB files are checked without it"
fi
# validate WHAT FILE: 0 errors from the Khronos validator (skipped without it)
validate() {
    local report
    [ -n "$GLTF_VALIDATOR" ] || return 0
    report=$(node "$ROOT/tests/gltf_validate.js" "$2" 2>&1)
    CMD="node tests/gltf_validate.js $2"
    check "$1: the Khronos glTF validator finds no error" "0 errors" "$report" \
        "$(printf '%s' "$report" | grep -q ': 0 errors' && ! printf '%s' "$report" | grep -q '^  error'; echo $?)"
}

# GLB_JSON is the JSON chunk of the last glb_check.
# glb_check WHAT FILE: a well-formed GLB container (1 check)
glb_check() {
    local out
    GLB_JSON=""
    if [ -z "$GLB_PROBE" ]; then return; fi
    out=$("$GLB_PROBE" check "$2" 2>&1)
    CMD="glb_probe check $2"
    check "$1: a GLB: magic, version 2, length, a JSON then a BIN chunk, 4-byte aligned" "ok" "$(printf '%s' "$out" | head -1)" \
        "$([ "$(printf '%s' "$out" | head -1)" = ok ]; echo $?)"
    GLB_JSON=$(printf '%s\n' "$out" | sed -n 2p)
}
# json_items NAME: the objects of GLB_JSON's top-level array NAME, one a line
json_items() {
    printf '%s' "$GLB_JSON" | awk -v name="\"$1\":[" '
        { s = s $0 }
        END {
            i = index(s, name)
            if (!i) exit 1
            depth = 0; item = ""
            for (i += length(name); i <= length(s); i++) {
                c = substr(s, i, 1)
                if (depth == 0 && c == "]") break
                if (c == "[" || c == "{") depth++
                if (c == "]" || c == "}") depth--
                if (depth == 0 && c == ",") { print item; item = ""; continue }
                item = item c
            }
            if (item != "") print item
        }'
}
# json_number TEXT FIELD: the first "FIELD":N in TEXT
json_number() { printf '%s' "$1" | grep -oE "\"$2\":[0-9]+" | head -1 | cut -d: -f2; }
# glb_accessor FILE N: accessor N's numbers, one a line (floats or indices)
glb_accessor() {
    local accessor view count type components offset kind start
    accessor=$(json_items accessors | sed -n "$(($2 + 1))p")
    view=$(json_number "$accessor" bufferView)
    count=$(json_number "$accessor" count)
    type=$(printf '%s' "$accessor" | grep -oE '"type":"[A-Z0-9]+"' | cut -d'"' -f4)
    case $type in VEC3) components=3 ;; VEC2) components=2 ;; *) components=1 ;; esac
    case $(json_number "$accessor" componentType) in 5126) kind=floats ;; 5123) kind=ushorts ;; *) kind=uints ;; esac
    offset=$(json_number "$(json_items bufferViews | sed -n "$((view + 1))p")" byteOffset)
    start=$(json_number "$accessor" byteOffset)
    "$GLB_PROBE" $kind "$1" "$((${offset:-0} + ${start:-0}))" "$((count * components))"
}
# glb_image FILE SLOT OUT.png: the embedded image named SLOT (baseColor,
# normal, metallicRoughness, occlusion) written out
glb_image() {
    local image view
    image=$(json_items images | grep "\"name\":\"$2\"")
    view=$(json_items bufferViews | sed -n "$(($(json_number "$image" bufferView) + 1))p")
    "$GLB_PROBE" bytes "$1" "$(json_number "$view" byteOffset)" "$(json_number "$view" byteLength)" >"$3"
}
# corner_set FILE.obj: every corner of every face as "x y z u v", sorted, unique
corner_set() {
    awk '$1 == "v" { v[++nv] = $2 " " $3 " " $4 } $1 == "vt" { t[++nt] = $2 " " $3 }
         $1 == "f" { for (i = 2; i <= NF; i++) { split($i, p, "/"); print v[p[1]] " " t[p[2]] } }' "$1" | sort -u
}
# glb_uvs_match_obj FILE.glb FILE.obj: "M N E": of the N distinct (position,
# texture coordinate) corners of the OBJ, M are vertices of the GLB with v
# flipped (glTF's v runs down from the image's top row), and E vertices of
# the GLB are none of the OBJ's corners (within 1e-6)
glb_uvs_match_obj() {
    awk '
        function key(u, v) { return int(u * 1000 + 1e6) " " int(v * 1000 + 1e6) }
        # the OBJ corner at (x, y, z, u, v), or 0
        function near(x, y, z, u, v,   du, dv, i, n, ids, c) {
            for (du = -1; du <= 1; du++) for (dv = -1; dv <= 1; dv++) {
                n = split(bucket[key(u + du / 1000, v + dv / 1000)], ids, " ")
                for (i = 1; i <= n; i++) {
                    split(corner[ids[i]], c, " ")
                    if ((c[1] - x) ^ 2 + (c[2] - y) ^ 2 + (c[3] - z) ^ 2 < 1e-12 && (c[4] - u) ^ 2 < 1e-12 &&
                        (c[5] - v) ^ 2 < 1e-12) return ids[i]
                }
            }
            return 0
        }
        FNR == NR { corner[++nobj] = $0; bucket[key($4, $5)] = bucket[key($4, $5)] " " nobj; next }
        { id = near($1, $2, $3, $4, 1 - $5); if (id) { if (!(id in matched)) found++; matched[id] = 1 } else extra++ }
        END { printf "%d %d %d\n", found, nobj, extra }' <(corner_set "$2") \
        <(paste -d' ' <(glb_accessor "$1" "$(json_number "$GLB_JSON" POSITION)" | paste -d' ' - - -) \
                      <(glb_accessor "$1" "$(json_number "$GLB_JSON" TEXCOORD_0)" | paste -d' ' - -))
}

# --- tile: OUT_PREFIX.glb, and --format glb, write the same one file -----
newdir
expect_ok "tile OUT.glb" tile ../in/torus.obj ../in/tex.png t.glb
CMD="ls after tiledtex tile ../in/torus.obj ../in/tex.png t.glb"
check "tile OUT.glb: writes t.glb and nothing else" "t.glb" "$(ls | tr '\n' ' ')" "$([ "$(ls)" = t.glb ]; echo $?)"
check "tile OUT.glb: the summary names it" "'wrote t.glb'" "$OUT" "$(printf '%s' "$OUT" | grep -q '^wrote t\.glb'; echo $?)"
# (the object inside is named after the file: the same name, in another folder)
mkdir f
expect_ok "tile --format glb" tile ../in/torus.obj ../in/tex.png f/t --format glb
expect_ok "tile, the same as an OBJ" tile ../in/torus.obj ../in/tex.png t
CMD="cmp t.glb f/t.glb"
check "tile: OUT_PREFIX.glb and --format glb write the same file" "identical" "$(cmp t.glb f/t.glb 2>&1)" \
    "$(cmp -s t.glb f/t.glb && [ -s t.glb ]; echo $?)"
glb_check "tile GLB" t.glb
if [ -n "$GLB_JSON" ]; then
    J=$GLB_JSON
    check "tile GLB: one material 'tiled' with the atlas as baseColorTexture" \
        "baseColorTexture, material tiled, 1 image/png called baseColor" "$J" \
        "$(printf '%s' "$J" | grep -q '"name":"tiled","pbrMetallicRoughness":{"baseColorTexture":{"index":0}' &&
           [ "$(json_items images | wc -l)" -eq 1 ] && json_items images | grep -q '"mimeType":"image/png","name":"baseColor"' &&
           ! printf '%s' "$J" | grep -qE 'normalTexture|occlusionTexture|metallicRoughnessTexture'; echo $?)"
    check "tile GLB: not metal, matte, two-sided, clamped texture, named after the file" \
        "metallicFactor 0, roughnessFactor 1, doubleSided, wrap 33071, node t" "$J" \
        "$(printf '%s' "$J" | grep -q '"metallicFactor":0,"roughnessFactor":1' && printf '%s' "$J" | grep -q '"doubleSided":true' &&
           printf '%s' "$J" | grep -q '"wrapS":33071,"wrapT":33071' && printf '%s' "$J" | grep -q '"nodes":\[{"mesh":0,"name":"t"}'; echo $?)"
    # the atlas embedded is the PNG the OBJ's MTL names, byte for byte
    glb_image t.glb baseColor atlas_in_glb.png
    CMD="cmp atlas_in_glb.png t.png"
    check "tile GLB: its image is the atlas PNG" "identical to t.png" "$(cmp atlas_in_glb.png t.png 2>&1; png_size atlas_in_glb.png)" \
        "$(cmp -s atlas_in_glb.png t.png; echo $?)"
    # triangles: two per quad; positions: the OBJ's bounding box
    quads=$(grep -c '^f ' t.obj)
    indices=$(json_number "$(json_items accessors | sed -n "$(($(json_number "$J" indices) + 1))p")" count)
    check "tile GLB: two triangles per quad of the OBJ" "$((6 * quads)) indices" "$indices" \
        "$([ "${indices:-0}" -eq $((6 * quads)) ] && [ "$quads" -gt 0 ]; echo $?)"
    read -r found total extra <<<"$(glb_uvs_match_obj t.glb t.obj)"
    CMD="GLB POSITION and TEXCOORD_0 against the OBJ's corners (v flipped)"
    check "tile GLB: the OBJ's corners, texture coordinates with v flipped for glTF's top-left origin" \
        "every distinct (v, vt) corner of the OBJ is a vertex, no other" "$found of $total found, $extra others" \
        "$([ "${total:-0}" -gt 0 ] && [ "$found" = "$total" ] && [ "$extra" = 0 ]; echo $?)"
    # every index names a vertex; every normal is unit length
    nverts=$(json_number "$(json_items accessors | sed -n 1p)" count)
    CMD="GLB indices and NORMAL of t.glb"
    bad=$(glb_accessor t.glb "$(json_number "$J" indices)" | awk -v n="$nverts" '$1 >= n { bad++ } END { print bad + 0 }')
    check "tile GLB: every index names one of the vertices" "0 out of range" "$bad of $indices (vertices $nverts)" \
        "$([ "$bad" = 0 ] && [ "${nverts:-0}" -gt 0 ]; echo $?)"
    bad=$(glb_accessor t.glb "$(json_number "$J" NORMAL)" |
        awk '{ s += $1 * $1 } NR % 3 == 0 { if (s < 0.9999 || s > 1.0001) bad++; s = 0; n++ } END { print bad + 0, n + 0 }')
    check "tile GLB: unit normals" "0 not unit length, one per vertex" "$bad" "$([ "$bad" = "0 $nverts" ]; echo $?)"
fi
validate "tile GLB" t.glb
# the standard output takes the one file (whose object is then "tiledtex")
expect_ok "tile OUT.glb named tiledtex.glb" tile ../in/torus.obj ../in/tex.png f/tiledtex.glb
run tile ../in/torus.obj ../in/tex.png - --format glb
CMD="tiledtex tile ../in/torus.obj ../in/tex.png - --format glb | cmp - f/tiledtex.glb"
check "tile - --format glb: the GLB on stdout, no summary, no file" "exit 0, the bytes of f/tiledtex.glb" \
    "exit $RC, $(cmp "$W/out" f/tiledtex.glb 2>&1), files: $(ls | tr '\n' ' ')" \
    "$([ $RC -eq 0 ] && cmp -s "$W/out" f/tiledtex.glb && [ ! -e ./- ] && [ ! -e -.glb ]; echo $?)"
cd "$W" || exit 1

# --- lapped: the GLB holds the pastes baked ---------------------------------
newdir
expect_ok "lapped OUT.glb (bakes by itself)" lapped ../in/torus.obj ../in/lap.png l.glb --scale 1.5

CMD="ls after tiledtex lapped ../in/torus.obj ../in/lap.png l.glb"
check "lapped OUT.glb: writes l.glb alone (no pasting OBJ, no patch PNG)" "l.glb" "$(ls | tr '\n' ' ')" \
    "$([ "$(ls)" = l.glb ]; echo $?)"
glb_side=$(printf '%s\n' "$OUT" | sed -n 's/^bake size \([0-9]*\): .*/\1/p')
check "lapped OUT.glb: says the side it chose and baked at it" "'bake size N: ...', 'wrote l.glb (the pastes baked into NxN'" \
    "$OUT" "$([ -n "$glb_side" ] && printf '%s' "$OUT" | grep -q "^wrote l\.glb (the pastes baked into ${glb_side}x${glb_side}"; echo $?)"
glb_check "lapped GLB" l.glb
if [ -n "$GLB_JSON" ]; then
    check "lapped GLB: one material, lapped_baked, with the baked texture" "material lapped_baked, one ${glb_side}x${glb_side} image" \
        "$GLB_JSON" "$(printf '%s' "$GLB_JSON" | grep -q '"name":"lapped_baked","pbrMetallicRoughness":{"baseColorTexture"' &&
                      [ "$(json_items materials | wc -l)" -eq 1 ] && glb_image l.glb baseColor baked.png &&
                      [ "$(png_size baked.png)" = "$glb_side $glb_side" ]; echo $?)"
fi
validate "lapped GLB" l.glb
expect_ok "lapped --format glb --bake 256" lapped ../in/torus.obj ../in/lap.png l2 --scale 1.5 --format glb --bake 256
expect_ok "lapped --bake 256, as OBJ" lapped ../in/torus.obj ../in/lap.png l2 --scale 1.5 --bake 256
glb_check "lapped --bake 256 GLB" l2.glb
if [ -n "$GLB_JSON" ]; then
    glb_image l2.glb baseColor baked256.png
    CMD="cmp baked256.png l2.png"
    check "lapped GLB --bake 256: the baked texture of the OBJ's" "identical PNGs" "$(cmp baked256.png l2.png 2>&1)" \
        "$(cmp -s baked256.png l2.png; echo $?)"
    read -r found total extra <<<"$(glb_uvs_match_obj l2.glb l2.obj)"
    CMD="GLB TEXCOORD_0 against l2.obj's vt"
    check "lapped GLB: the baked OBJ's texture coordinates, v flipped" "all, no other" "$found of $total, $extra others" \
        "$([ "${total:-0}" -gt 0 ] && [ "$found" = "$total" ] && [ "$extra" = 0 ]; echo $?)"
fi
validate "lapped --bake 256 GLB" l2.glb
cd "$W" || exit 1

# --- hpm: IMAGE embedded, repeated only under --toroidal --------------------
newdir
expect_ok "hpm --format glb" hpm ../in/torus.obj ../in/lap.png h --format glb
CMD="ls after tiledtex hpm ../in/torus.obj ../in/lap.png h --format glb"
check "hpm --format glb: h.glb alone" "h.glb" "$(ls | tr '\n' ' ')" "$([ "$(ls)" = h.glb ]; echo $?)"
glb_check "hpm GLB" h.glb
if [ -n "$GLB_JSON" ]; then
    check "hpm GLB: material hpm with IMAGE, clamped" "material hpm, wrap 33071, a 64x64 image" "$GLB_JSON" \
        "$(printf '%s' "$GLB_JSON" | grep -q '"name":"hpm","pbrMetallicRoughness":{"baseColorTexture"' &&
           printf '%s' "$GLB_JSON" | grep -q '"wrapS":33071' && glb_image h.glb baseColor image.png &&
           [ "$(png_size image.png)" = "64 64" ]; echo $?)"
fi
validate "hpm GLB" h.glb
# the object is named after the file; glTF's JSON must be UTF-8, so a byte
# that is not (a Latin-1 name) becomes '?', and quotes are escaped
latin1_name=$(printf 'caf\351 "q"')
expect_ok "hpm into a Latin-1 file name" hpm ../in/torus.obj ../in/lap.png "$latin1_name.glb"
cp "$latin1_name.glb" latin1.glb
glb_check "hpm GLB with a Latin-1 name" latin1.glb
check "hpm GLB with a Latin-1 name: the object's name is UTF-8 JSON" '"name":"caf? \"q\""' "$GLB_JSON" \
    "$(printf '%s' "$GLB_JSON" | grep -qF '"nodes":[{"mesh":0,"name":"caf? \"q\""}]'; echo $?)"
validate "hpm GLB with a Latin-1 name" latin1.glb
expect_ok "hpm --toroidal OUT.glb" hpm ../in/torus.obj ../in/lap.png ht.glb --toroidal
glb_check "hpm --toroidal GLB" ht.glb
check "hpm --toroidal GLB: the texture repeats" "wrapS/wrapT 10497" "$GLB_JSON" \
    "$(printf '%s' "$GLB_JSON" | grep -q '"wrapS":10497,"wrapT":10497'; echo $?)"
validate "hpm --toroidal GLB" ht.glb
expect_ok "hpm, the same as an OBJ" hpm ../in/torus.obj ../in/lap.png h
glb_check "hpm GLB again" h.glb
if [ -n "$GLB_JSON" ]; then
    read -r found total extra <<<"$(glb_uvs_match_obj h.glb h.obj)"
    CMD="GLB TEXCOORD_0 against h.obj's vt"
    check "hpm GLB: the OBJ's texture coordinates, v flipped" "all, no other" "$found of $total, $extra others" \
        "$([ "${total:-0}" -gt 0 ] && [ "$found" = "$total" ] && [ "$extra" = 0 ]; echo $?)"
fi
cd "$W" || exit 1

# --- polycube: the textured mesh only ---------------------------------------
newdir
expect_ok "polycube OUT.glb" polycube ../in/spheretri.obj ../in/tex.png p.glb --resolution 4
CMD="ls after tiledtex polycube ../in/spheretri.obj ../in/tex.png p.glb --resolution 4"
check "polycube OUT.glb: p.glb alone (no polycube surface)" "p.glb" "$(ls | tr '\n' ' ')" "$([ "$(ls)" = p.glb ]; echo $?)"
glb_check "polycube GLB" p.glb
if [ -n "$GLB_JSON" ]; then
    check "polycube GLB: one mesh, material tiled with the atlas" "1 mesh, 1 node, material tiled" "$GLB_JSON" \
        "$([ "$(json_items meshes | wc -l)" -eq 1 ] && [ "$(json_items nodes | wc -l)" -eq 1 ] &&
           printf '%s' "$GLB_JSON" | grep -q '"name":"tiled","pbrMetallicRoughness":{"baseColorTexture"'; echo $?)"
fi
validate "polycube GLB" p.glb
cd "$W" || exit 1

# --- .gltf: the GLB's scene as text, with its arrays and images beside it -----
# gltf_same_as_glb WHAT STEM: STEM.gltf, STEM.bin and STEM_*.png hold what
# STEM.glb holds: the .bin is the BIN chunk's arrays (the GLB's images come
# after them), each PNG the embedded image of its name, and the JSON names
# the .bin with its length; then the validator (which reads the files the
# URIs name)
gltf_same_as_glb() {
    local what=$1 stem=$2 bin_size json slot
    glb_check "$what (its GLB)" "$stem.glb"
    [ -n "$GLB_JSON" ] || return
    bin_size=$(stat -c %s "$stem.bin" 2>/dev/null || echo 0)
    CMD="glb_probe bytes $stem.glb 0 $bin_size | cmp - $stem.bin"
    check "$what: $stem.bin is the GLB's arrays" "identical" "$bin_size bytes" \
        "$([ "$bin_size" -gt 0 ] && "$GLB_PROBE" bytes "$stem.glb" 0 "$bin_size" | cmp -s - "$stem.bin"; echo $?)"
    for slot in $(json_items images | grep -oE '"name":"[A-Za-z]+"' | cut -d'"' -f4); do
        glb_image "$stem.glb" "$slot" "glb_$slot.png"
        CMD="cmp glb_$slot.png ${stem}_$slot.png"
        check "$what: ${stem}_$slot.png is the GLB's $slot image" "identical" "$(ls -l "${stem}_$slot.png" 2>&1)" \
            "$(cmp -s "glb_$slot.png" "${stem}_$slot.png"; echo $?)"
        rm -f "glb_$slot.png"
    done
    json=$(tr -d '\n' <"$stem.gltf")
    CMD="$stem.gltf"
    check "$what: the JSON names $stem.bin and its length" "\"buffers\":[{\"uri\":\"$stem.bin\",\"byteLength\":$bin_size}]" \
        "$(printf '%s' "$json" | grep -oE '"buffers":\[[^]]*\]')" \
        "$(printf '%s' "$json" | grep -qF "\"buffers\":[{\"uri\":\"$stem.bin\",\"byteLength\":$bin_size}]"; echo $?)"
    validate "$what" "$stem.gltf"
}
# gltf_case WHAT STEM EXPECTED_FILES ARGS...: the command run twice in a
# fresh folder, OUT_PREFIX STEM.glb then STEM.gltf; exactly the GLB and
# EXPECTED_FILES are left, and the .gltf holds what the GLB does
gltf_case() {
    local what=$1 stem=$2 expected=$3
    shift 3
    newdir
    expect_ok "$what OUT.glb" "$@" "$stem.glb"
    expect_ok "$what OUT.gltf" "$@" "$stem.gltf"
    check "$what OUT.gltf: the summary names the files" "wrote $stem.gltf, $stem.bin, ${stem}_*.png" "$OUT" \
        "$(printf '%s' "$OUT" | grep -qF "wrote $stem.gltf, $stem.bin, ${stem}_*.png"; echo $?)"
    CMD="ls after tiledtex $* $stem.gltf"
    check "$what OUT.gltf: its files and nothing else" "$expected $stem.glb" "$(ls | tr '\n' ' ')" \
        "$([ "$(ls | sort | tr '\n' ' ')" = "$(printf '%s\n' $expected "$stem.glb" | sort | tr '\n' ' ')" ]; echo $?)"
    gltf_same_as_glb "$what glTF" "$stem"
    cd "$W" || exit 1
}
gltf_case "tile" t "t.gltf t.bin t_baseColor.png" tile ../in/torus.obj ../in/tex.png
gltf_case "hpm" h "h.gltf h.bin h_baseColor.png" hpm ../in/torus.obj ../in/lap.png
gltf_case "polycube" p "p.gltf p.bin p_baseColor.png" polycube ../in/spheretri.obj ../in/tex.png --resolution 4
gltf_case "lapped" l "l.gltf l.bin l_baseColor.png" lapped ../in/torus.obj ../in/lap.png --bake 128
# --format gltf is the same as a name ending in .gltf; a name with a space
# and a letter beyond ASCII is written as it is, and the JSON's URIs are
# percent-encoded (the validator reads the files through them)
newdir
expect_ok "tile --format gltf" tile ../in/torus.obj ../in/tex.png t --format gltf
mkdir f
expect_ok "tile OUT.gltf in another folder" tile ../in/torus.obj ../in/tex.png f/t.gltf
CMD="cmp t.gltf f/t.gltf; cmp t.bin f/t.bin"
check "tile: --format gltf and OUT_PREFIX.gltf write the same files" "identical" "$(ls . f | tr '\n' ' ')" \
    "$(cmp -s t.gltf f/t.gltf && cmp -s t.bin f/t.bin && cmp -s t_baseColor.png f/t_baseColor.png; echo $?)"
name=$'m \303\251'   # "m é", the é in UTF-8
expect_ok "tile OUT.gltf with a space and a non-ASCII letter" tile ../in/torus.obj ../in/tex.png "$name.gltf"
CMD="grep uri '$name.gltf'"
check "tile OUT.gltf '$name': percent-encoded URIs" "\"uri\":\"m%20%C3%A9.bin\" and m%20%C3%A9_baseColor.png" \
    "$(grep -oE '"uri":"[^"]*"' "$name.gltf" 2>&1 | tr '\n' ' ')" \
    "$(grep -qF '"uri":"m%20%C3%A9.bin"' "$name.gltf" && grep -qF '"uri":"m%20%C3%A9_baseColor.png"' "$name.gltf" &&
       [ -s "$name.bin" ] && [ -s "${name}_baseColor.png" ]; echo $?)"
validate "tile OUT.gltf '$name'" "$name.gltf"
cd "$W" || exit 1

# --- what a GLB is refused with ----------------------------------------------
expect_usage_error "tile OUT.glb --format obj (they disagree)" tile ../in/torus.obj ../in/tex.png o.glb --format obj
err_mentions "tile OUT.glb --format obj: says why" "names a GLB.*format obj"
expect_usage_error "hpm OUT.obj --format glb (they disagree)" hpm ../in/torus.obj ../in/lap.png o.obj --format glb
err_mentions "hpm OUT.obj --format glb: names o.glb" "o\.glb"
expect_usage_error "polycube OUT.gltf --format glb (a GLB is not .gltf)" polycube ../in/spheretri.obj ../in/tex.png o.gltf \
    --format glb
expect_usage_error "lapped --pasting into a GLB" lapped ../in/torus.obj ../in/lap.png p.glb --scale 1.5 --pasting
err_mentions "lapped --pasting into a GLB: says a glTF file holds the bake" 'pasting writes the pasting OBJ; a glTF file holds the pastes baked'
expect_usage_error "lapped --format fbx" lapped ../in/torus.obj ../in/lap.png o --format fbx
err_mentions "lapped --format fbx: names the formats" "obj, glb or gltf"
expect_usage_error "tile OUT.gltf --format obj (they disagree)" tile ../in/torus.obj ../in/tex.png o.gltf --format obj
err_mentions "tile OUT.gltf --format obj: says why" "names a glTF.*format obj"
expect_usage_error "hpm OUT.obj --format gltf (they disagree)" hpm ../in/torus.obj ../in/lap.png o.obj --format gltf
err_mentions "hpm OUT.obj --format gltf: names o.gltf" "o\.gltf"
expect_usage_error "hpm - --format gltf (several files)" hpm ../in/torus.obj ../in/lap.png - --format gltf
expect_usage_error "tile --mips with a .gltf" tile ../in/torus.obj ../in/tex.png o.gltf --mips
expect_usage_error "tile --format without a value" tile ../in/torus.obj ../in/tex.png o --format
expect_usage_error "tile --mips with a GLB" tile ../in/torus.obj ../in/tex.png o.glb --mips
expect_usage_error "hpm - (OBJ: several files)" hpm ../in/torus.obj ../in/lap.png -
err_mentions "hpm -: says --format glb makes one file" "add .*format glb"
expect_usage_error "map --format glb (map writes OBJ)" map ../in/torus.obj o.obj --format glb

# --- --triangles: fans of triangles with the same corners --------------------
newdir
expect_ok "tile" tile ../in/torus.obj ../in/tex.png q
expect_ok "tile --triangles" tile ../in/torus.obj ../in/tex.png tr --triangles
CMD="tiledtex tile ../in/torus.obj ../in/tex.png tr --triangles"
faces=$(awk '$1 == "f" { n[NF - 1]++ } END { for (k in n) printf "%d-corner:%d ", k, n[k] }' tr.obj)
check "tile --triangles: only triangles, two per quad" "3-corner:$((2 * $(grep -c '^f ' q.obj)))" "$faces" \
    "$([ "$faces" = "3-corner:$((2 * $(grep -c '^f ' q.obj))) " ]; echo $?)"
check "tile --triangles: the same vertices, vt and vn lines" "identical v/vt/vn lines" "differ" \
    "$(cmp -s <(grep -E '^(v|vt|vn) ' q.obj) <(grep -E '^(v|vt|vn) ' tr.obj) && grep -q '^vt ' q.obj; echo $?)"
check "tile --triangles: every corner keeps its position and texture coordinate" "the same set of (v, vt) corners" \
    "$(diff <(corner_set q.obj) <(corner_set tr.obj) | head -3)" \
    "$(cmp -s <(corner_set q.obj) <(corner_set tr.obj) && [ -n "$(corner_set q.obj)" ]; echo $?)"
check "tile --triangles: each triangle a fan of its quad (q1 q2 q3, q1 q3 q4)" "fans from each quad's first corner" \
    "$(awk '$1 == "f" { print $2, $3, $4; print $2, $4, $5 }' q.obj | head -2)" \
    "$(cmp -s <(awk '$1 == "f" { print $2, $3, $4; print $2, $4, $5 }' q.obj) <(awk '$1 == "f" { print $2, $3, $4 }' tr.obj); echo $?)"
read -r corners nvn bad creased <<<"$(normals_report tr.obj)"
check "tile --triangles: a unit normal (vn) at every triangle corner" "0 corners without one" "$bad of $corners" \
    "$([ "${corners:-0}" -gt 0 ] && [ "${bad:-1}" = 0 ]; echo $?)"
expect_ok "map --triangles" map ../in/double-torus.obj m.obj --triangles
expect_ok "map" map ../in/double-torus.obj mq.obj
check "map --triangles: only triangles, the same corners" "3-corner faces only, the same (v, vt) set" \
    "$(awk '$1 == "f" { n[NF - 1]++ } END { for (k in n) printf "%d-corner:%d ", k, n[k] }' m.obj)" \
    "$([ "$(awk '$1 == "f" && NF != 4' m.obj | wc -l)" -eq 0 ] && cmp -s <(corner_set m.obj) <(corner_set mq.obj) &&
       [ "$(grep -c '^f ' m.obj)" -eq $((2 * $(grep -c '^f ' mq.obj))) ]; echo $?)"
expect_ok "polycube --triangles" polycube ../in/spheretri.obj ../in/tex.png pc --resolution 4 --triangles
check "polycube --triangles: the polycube surface as triangles too" "3-corner faces only in pc_polycube.obj" \
    "$(awk '$1 == "f" { n[NF - 1]++ } END { for (k in n) printf "%d-corner:%d ", k, n[k] }' pc_polycube.obj)" \
    "$([ "$(awk '$1 == "f" && NF != 4' pc_polycube.obj pc.obj | wc -l)" -eq 0 ] && grep -q '^f ' pc_polycube.obj; echo $?)"
expect_ok "hpm --triangles" hpm ../in/torus.obj ../in/lap.png ht --triangles
expect_ok "lapped --triangles" lapped ../in/torus.obj ../in/lap.png lt --scale 1.5 --triangles
check "hpm and lapped --triangles: their OBJs are triangles" "3-corner faces only" \
    "$(awk '$1 == "f" && NF != 4' ht.obj lt.obj | head -2)" \
    "$([ "$(awk '$1 == "f" && NF != 4' ht.obj lt.obj | wc -l)" -eq 0 ]; echo $?)"
cd "$W" || exit 1

# --- every material slot, through gltf_write as a command calls it ----------
if [ -n "$GLB_PROBE" ]; then
    newdir
    CMD="glb_probe write all.glb base,normal,roughness,metallic,occlusion"
    out=$("$GLB_PROBE" write all.glb base,normal,roughness,metallic,occlusion 2>&1)
    check "gltf_write with every map" "exit 0" "$out" "$([ -s all.glb ]; echo $?)"
    glb_check "every map" all.glb
    J=$GLB_JSON
    check "every map: each slot names its own texture" \
        "baseColorTexture 0, metallicRoughnessTexture 2, normalTexture 1, occlusionTexture 3, metallicFactor 1" "$J" \
        "$(printf '%s' "$J" | grep -q '"pbrMetallicRoughness":{"baseColorTexture":{"index":0},"metallicRoughnessTexture":{"index":2},"metallicFactor":1,"roughnessFactor":1},"normalTexture":{"index":1},"occlusionTexture":{"index":3}' &&
           [ "$(json_items textures | wc -l)" -eq 4 ] && [ "$(json_items images | wc -l)" -eq 4 ]; echo $?)"
    check "every map: a quad and a triangle sharing an edge make 5 vertices, 3 triangles (a zero normal takes its face's)" \
        "POSITION count 5, 9 indices" "$(json_items accessors | tr '\n' ' ')" \
        "$([ "$(json_number "$(json_items accessors | sed -n 1p)" count)" = 5 ] &&
           [ "$(json_number "$(json_items accessors | sed -n "$(($(json_number "$J" indices) + 1))p")" count)" = 9 ]; echo $?)"
    CMD="glb_probe: POSITION min/max"
    check "every map: POSITION's bounds" "min [0,0,0], max [2,1,0]" "$(json_items accessors | sed -n 1p)" \
        "$(json_items accessors | sed -n 1p | grep -q '"min":\[0,0,0\],"max":\[2,1,0\]'; echo $?)"
    if [ -x "$W/pixstat" ]; then
        # linear 0.2 0.4 0.6 is sRGB 124 170 203; the data maps keep their bytes
        for slot in "baseColor:124 170 203" "normal:128 128 255" "metallicRoughness:255 64 128" "occlusion:191 191 191"; do
            name=${slot%%:*}
            want=${slot##*:}
            glb_image all.glb "$name" "$name.png"
            px=$("$W/pixstat" "$name.png" 3 3 2>&1)
            CMD="pixstat $name.png 3 3 (from all.glb)"
            check "every map: the $name texture's bytes" "$want" "$px" "$([ "$px" = "$want" ]; echo $?)"
        done
    fi
    validate "every map" all.glb
    out=$("$GLB_PROBE" write rough.glb base,roughness 2>&1)
    glb_check "roughness without metallic" rough.glb
    check "roughness without metallic: metalness 0 from the factor, the texture a grey roughness image" \
        "metallicFactor 0, the texture's texel 64 64 64 in a grey PNG (colour type 0)" \
        "$GLB_JSON" "$(printf '%s' "$GLB_JSON" | grep -q '"metallicRoughnessTexture":{"index":1},"metallicFactor":0,' &&
                       glb_image rough.glb metallicRoughness mr.png &&
                       [ "$(od -An -tu1 -j25 -N1 mr.png | tr -d ' ')" = 0 ] &&
                       { [ ! -x "$W/pixstat" ] || [ "$("$W/pixstat" mr.png 0 0)" = "64 64 64" ]; }; echo $?)"
    validate "roughness without metallic" rough.glb
    out=$("$GLB_PROBE" write bad.glb roughness,small_metallic 2>&1)
    CMD="glb_probe write bad.glb roughness,small_metallic"
    check "roughness and metallic of different sizes are refused" "an error naming both sizes, no file" "$out" \
        "$(printf '%s' "$out" | grep -q '8x8 and the metallic map 4x4' && [ ! -e bad.glb ]; echo $?)"
    out=$("$GLB_PROBE" write plain.glb none 2>&1)
    glb_check "no map at all" plain.glb
    check "no map at all: no texture, image or sampler" "none" "$GLB_JSON" \
        "$(! printf '%s' "$GLB_JSON" | grep -qE '"(textures|images|samplers)"' && [ -n "$GLB_JSON" ]; echo $?)"
    validate "no map at all" plain.glb
    cd "$W" || exit 1
fi

# ======================================================================
# Material maps (issue 11, item 1): one layout for every map
# ======================================================================
cat >"$W/maps.c" <<'EOF_C'
/* maps: the test helper for material maps.
     maps pbr IN.png STEM [ydown]   height (luminance), normal (from the height's slopes, 4 per
                                    unit per texel, +Y up, or y down) and roughness maps of IN
     maps coords W H OUT.png        r = x, g = y (bytes): where each texel came from
     maps const W H R G B OUT.png   one colour
     maps slope HEIGHT NORMAL       median and 90th percentile (degrees) of the angle between
                                    the direction a normal map tilts and the one the height map's
                                    slopes imply, where both tilt
     maps turns NORMAL X Y          the share of tilted texels whose tilt is (X, Y) (bytes, +Y
                                    up) turned by 0, 1, 2, 3 quarter turns counter-clockwise,
                                    within 10 degrees
     maps origin IMAGE COORDS ATLAS the share of atlas texels equal (within 2 per channel) to
                                    IMAGE's texel at the position COORDS' atlas gives there
     maps diff A B                  the largest difference of a byte of r, g, b (-1: sizes differ) */
#define STB_IMAGE_IMPLEMENTATION
#include "stb_image.h"
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include "stb_image_write.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
static int by_value(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}
static float angle(float ax, float ay, float bx, float by)
{
    float c = (ax * bx + ay * by) / (sqrtf(ax * ax + ay * ay) * sqrtf(bx * bx + by * by));
    return acosf(c > 1.0f ? 1.0f : (c < -1.0f ? -1.0f : c)) * 57.29578f;
}
int main(int argc, char **argv)
{
    int w, h, n, x, y;
    char path[4096];
    if (argc >= 4 && strcmp(argv[1], "pbr") == 0) {
        unsigned char *p = stbi_load(argv[2], &w, &h, &n, 3), *o;
        float *L;
        if (!p) return 1;
        L = malloc(sizeof(float) * w * h);
        o = malloc(3 * (size_t)w * h);
        for (y = 0; y < h; y++)
            for (x = 0; x < w; x++) {
                unsigned char *q = p + 3 * (y * w + x);
                L[y * w + x] = (0.299f * q[0] + 0.587f * q[1] + 0.114f * q[2]) / 255.0f;
            }
        for (x = 0; x < w * h; x++) o[3 * x] = o[3 * x + 1] = o[3 * x + 2] = (unsigned char)(L[x] * 255.0f + 0.5f);
        snprintf(path, sizeof path, "%s_height.png", argv[3]);
        if (!stbi_write_png(path, w, h, 3, o, 3 * w)) return 1;
        for (x = 0; x < w * h; x++) o[3 * x] = o[3 * x + 1] = o[3 * x + 2] = (unsigned char)(255.0f - L[x] * 200.0f);
        snprintf(path, sizeof path, "%s_roughness.png", argv[3]);
        if (!stbi_write_png(path, w, h, 3, o, 3 * w)) return 1;
        for (y = 0; y < h; y++)
            for (x = 0; x < w; x++) {
                int xl = x > 0 ? x - 1 : x, xr = x < w - 1 ? x + 1 : x, yu = y > 0 ? y - 1 : y, yd = y < h - 1 ? y + 1 : y;
                float nx = -(L[y * w + xr] - L[y * w + xl]) * 4.0f, ny = (L[yd * w + x] - L[yu * w + x]) * 4.0f;
                float len = sqrtf(nx * nx + ny * ny + 1.0f);
                if (argc > 4) ny = -ny;
                o[3 * (y * w + x)] = (unsigned char)lrintf((nx / len * 0.5f + 0.5f) * 255.0f);
                o[3 * (y * w + x) + 1] = (unsigned char)lrintf((ny / len * 0.5f + 0.5f) * 255.0f);
                o[3 * (y * w + x) + 2] = (unsigned char)lrintf((1.0f / len * 0.5f + 0.5f) * 255.0f);
            }
        snprintf(path, sizeof path, "%s_normal.png", argv[3]);
        return !stbi_write_png(path, w, h, 3, o, 3 * w);
    }
    if (argc == 5 && strcmp(argv[1], "coords") == 0) {
        unsigned char *o;
        w = atoi(argv[2]);
        h = atoi(argv[3]);
        o = malloc(3 * (size_t)w * h);
        for (y = 0; y < h; y++)
            for (x = 0; x < w; x++) {
                o[3 * (y * w + x)] = (unsigned char)x;
                o[3 * (y * w + x) + 1] = (unsigned char)y;
                o[3 * (y * w + x) + 2] = 0;
            }
        return !stbi_write_png(argv[4], w, h, 3, o, 3 * w);
    }
    if (argc == 8 && strcmp(argv[1], "const") == 0) {
        unsigned char *o;
        w = atoi(argv[2]);
        h = atoi(argv[3]);
        o = malloc(3 * (size_t)w * h);
        for (x = 0; x < w * h; x++) {
            o[3 * x] = (unsigned char)atoi(argv[4]);
            o[3 * x + 1] = (unsigned char)atoi(argv[5]);
            o[3 * x + 2] = (unsigned char)atoi(argv[6]);
        }
        return !stbi_write_png(argv[7], w, h, 3, o, 3 * w);
    }
    if (argc == 4 && strcmp(argv[1], "slope") == 0) {
        int w2, h2, count = 0;
        unsigned char *H = stbi_load(argv[2], &w, &h, &n, 1), *N = stbi_load(argv[3], &w2, &h2, &n, 3);
        float *angles;
        if (!H || !N || w != w2 || h != h2) return 1;
        angles = malloc(sizeof(float) * w * h);
        for (y = 1; y < h - 1; y++)
            for (x = 1; x < w - 1; x++) {
                float ex = -(H[y * w + x + 1] - H[y * w + x - 1]) / 255.0f * 4.0f;
                float ey = (H[(y + 1) * w + x] - H[(y - 1) * w + x]) / 255.0f * 4.0f;
                const unsigned char *p = N + 3 * (y * w + x);
                float nx = p[0] / 127.5f - 1.0f, ny = p[1] / 127.5f - 1.0f, nz = p[2] / 127.5f - 1.0f;
                if (sqrtf(ex * ex + ey * ey) < 0.08f || sqrtf(nx * nx + ny * ny) < 0.08f * sqrtf(nx * nx + ny * ny + nz * nz))
                    continue;
                angles[count++] = angle(ex, ey, nx, ny);
            }
        if (count < 100) return 1;
        qsort(angles, (size_t)count, sizeof(float), by_value);
        printf("%.2f %.2f %d\n", angles[count / 2], angles[count * 9 / 10], count);
        return 0;
    }
    if (argc == 5 && strcmp(argv[1], "turns") == 0) {
        unsigned char *N = stbi_load(argv[2], &w, &h, &n, 3);
        float vx = atoi(argv[3]) / 127.5f - 1.0f, vy = atoi(argv[4]) / 127.5f - 1.0f;
        long counts[4] = {0, 0, 0, 0}, tilted = 0;
        int k;
        if (!N) return 1;
        for (x = 0; x < w * h; x++) {
            float nx = N[3 * x] / 127.5f - 1.0f, ny = N[3 * x + 1] / 127.5f - 1.0f;
            if (sqrtf(nx * nx + ny * ny) < 0.05f) continue;
            tilted++;
            for (k = 0; k < 4; k++) {
                float c = cosf(k * 1.5707963f), s = sinf(k * 1.5707963f);
                if (angle(nx, ny, c * vx - s * vy, s * vx + c * vy) < 10.0f) counts[k]++;
            }
        }
        if (tilted == 0) return 1;
        printf("%.3f %.3f %.3f %.3f\n", (double)counts[0] / tilted, (double)counts[1] / tilted,
               (double)counts[2] / tilted, (double)counts[3] / tilted);
        return 0;
    }
    if (argc == 4 && strcmp(argv[1], "diff") == 0) {
        int w2, h2, most = 0;
        unsigned char *A = stbi_load(argv[2], &w, &h, &n, 3), *B = stbi_load(argv[3], &w2, &h2, &n, 3);
        if (!A || !B) return 1;
        if (w != w2 || h != h2) most = -1;
        for (x = 0; most >= 0 && x < 3 * w * h; x++)
            if (abs(A[x] - B[x]) > most) most = abs(A[x] - B[x]);
        printf("%d\n", most);
        return 0;
    }
    if (argc == 5 && strcmp(argv[1], "origin") == 0) {
        int cw, ch, aw, ah, k;
        long same = 0;
        unsigned char *I = stbi_load(argv[2], &w, &h, &n, 3), *C = stbi_load(argv[3], &cw, &ch, &n, 3),
                      *A = stbi_load(argv[4], &aw, &ah, &n, 3);
        if (!I || !C || !A || cw != aw || ch != ah) return 1;
        for (x = 0; x < aw * ah; x++) {
            int sx = C[3 * x], sy = C[3 * x + 1], ok = 1;
            if (sx >= w || sy >= h) continue;
            for (k = 0; k < 3; k++) ok &= abs(A[3 * x + k] - I[3 * (sy * w + sx) + k]) <= 2;
            same += ok;
        }
        printf("%.3f\n", (double)same / ((double)aw * ah));
        return 0;
    }
    return 2;
}
EOF_C
newdir
MD=$PWD
CMD="$HELPER_CC $STB_INC maps.c (test helper)"
if $HELPER_CC -O2 -w $STB_INC "$W/maps.c" -o "$W/maps" -lm 2>"$W/err"; then
    MAPS=$W/maps
    # a 256 x 256 material: the colour, its height, the normal map its slopes imply (+Y up
    # and y down) and a roughness map; a map of where each texel is; an "up" normal map
    "$MAPS" pbr ../in/tex.png m && "$MAPS" pbr ../in/tex.png dx ydown && "$MAPS" coords 256 256 coords.png &&
        "$MAPS" const 256 256 128 200 218 upmap.png && "$MAPS" const 128 128 128 128 255 small.png
    check "material helper makes its maps" "m_normal.png m_height.png coords.png upmap.png" "$(ls)" \
        "$([ -s m_normal.png ] && [ -s dx_normal.png ] && [ -s coords.png ] && [ -s upmap.png ]; echo $?)"

    # generate texture --material: the pavement's own maps beside it, the normal map the
    # one its height implies
    expect_ok "generate texture --material" generate texture g.png --size 128 --material
    check "generate --material: the maps beside OUT.png, each its size" "g_normal/_height/_roughness/_ao.png 128 128" \
        "$(for m in normal height roughness ao; do printf '%s: %s; ' $m "$(png_size g_$m.png)"; done; ls g_metallic.png 2>&1)" \
        "$(for m in normal height roughness ao; do [ "$(png_size g_$m.png)" = "128 128" ] || exit 1; done
            [ ! -e g_metallic.png ]; echo $?)"
    slope=$("$MAPS" slope g_height.png g_normal.png 2>&1)
    CMD="maps slope g_height.png g_normal.png"
    check "generate --material: the normal map follows the height map's slopes" "median <= 3 deg" "$slope" \
        "$(printf '%s\n' "$slope" | awk '{exit !(NF == 3 && $1 <= 3)}'; echo $?)"
    expect_usage_error "generate --material to the standard output" generate texture - --material
    cd "$MD" || exit 1

    # tile: an atlas per map, one layout; the MTL names them
    expect_ok "tile with a material" tile ../in/torus.obj ../in/tex.png t --tile 48 --normal m_normal.png \
        --roughness m_roughness.png --height m_height.png --metallic coords.png --ao m_height.png
    check "tile: one atlas per map, of the colour's size" "t_normal/_roughness/_metallic/_ao/_height.png, $(png_size t.png)" \
        "$(for m in normal roughness metallic ao height; do printf '%s: %s; ' $m "$(png_size t_$m.png)"; done)" \
        "$(for m in normal roughness metallic ao height; do [ "$(png_size t_$m.png)" = "$(png_size t.png)" ] || exit 1; done; echo $?)"
    check "tile: the MTL names every map" "map_Bump -bm 1 / norm t_normal.png, map_Pr, map_Pm, disp, an AO comment" \
        "$(cat t.mtl)" \
        "$(grep -qx 'map_Bump -bm 1 t_normal.png' t.mtl && grep -qx 'norm t_normal.png' t.mtl &&
            grep -qx 'map_Pr t_roughness.png' t.mtl && grep -qx 'map_Pm t_metallic.png' t.mtl &&
            grep -qx 'disp t_height.png' t.mtl && grep -q '^# ambient occlusion: t_ao.png' t.mtl; echo $?)"
    expect_ok "tile the colour alone" tile ../in/torus.obj ../in/tex.png alone --tile 48
    check "tile: the maps change nothing of the colour's atlas" "cmp equal" "$(cmp t.png alone.png 2>&1)" \
        "$(cmp -s t.png alone.png; echo $?)"
    check "tile: the same map twice gives the same atlas" "t_height.png = t_ao.png" "$(cmp t_height.png t_ao.png 2>&1)" \
        "$(cmp -s t_height.png t_ao.png; echo $?)"
    # synth: the same maps' atlases beside ATLAS.png, the very ones tile made
    expect_ok "synth with a material" synth ../in/tex.png s.png --tile 48 --normal m_normal.png --height m_height.png
    check "synth: the colour and normal atlases are tile's" "s.png = t.png, s_normal.png = t_normal.png" \
        "$(cmp s.png t.png 2>&1; cmp s_normal.png t_normal.png 2>&1)" \
        "$(cmp -s s.png t.png && cmp -s s_normal.png t_normal.png && cmp -s s_height.png t_height.png; echo $?)"
    # one layout: where the map of positions says an atlas texel came from, the colour
    # atlas shows that very texel of the colour image (blends aside); the control, the
    # positions laid out by another seed's tiles, agrees only by chance
    expect_ok "tile: positions by another seed (control)" tile ../in/torus.obj ../in/tex.png other --tile 48 \
        --seed 9 --metallic coords.png
    same=$("$MAPS" origin ../in/tex.png t_metallic.png t.png 2>&1)
    control=$("$MAPS" origin ../in/tex.png other_metallic.png t.png 2>&1)
    CMD="maps origin ../in/tex.png t_metallic.png t.png (and other_metallic.png)"
    check "tile: every map is cut where the colour is" "share >= 0.6 (control, another seed's: <= 0.2)" \
        "$same (control $control)" \
        "$(awk -v a="$same" -v b="$control" 'BEGIN{exit !(a >= 0.6 && b <= 0.2)}'; echo $?)"
    # normals turned with the content: the normal atlas tilts where the height atlas's
    # slopes say; read as y-down (a wrong turn of every vector) it does not
    slope=$("$MAPS" slope t_height.png t_normal.png 2>&1)
    CMD="maps slope t_height.png t_normal.png"
    check "tile: the normal atlas follows the height atlas's slopes" "median <= 5 deg, p90 <= 45" "$slope" \
        "$(printf '%s\n' "$slope" | awk '{exit !(NF == 3 && $1 <= 5 && $2 <= 45)}'; echo $?)"
    expect_ok "tile: a +Y-up normal map read as y-down (control)" tile ../in/torus.obj ../in/tex.png flip --tile 48 \
        --normal m_normal.png --normal-y-down --height m_height.png
    slope=$("$MAPS" slope flip_height.png flip_normal.png 2>&1)
    check "tile: the control's normals disagree with the slopes" "median above 20 deg" "$slope" \
        "$(printf '%s\n' "$slope" | awk '{exit !(NF == 3 && $1 > 20)}'; echo $?)"
    expect_ok "tile: a y-down normal map with --normal-y-down" tile ../in/torus.obj ../in/tex.png dxt --tile 48 \
        --normal dx_normal.png --normal-y-down --height m_height.png
    slope=$("$MAPS" slope dxt_height.png dxt_normal.png 2>&1)
    check "tile --normal-y-down: written +Y up, following the slopes" "median <= 5 deg" "$slope" \
        "$(printf '%s\n' "$slope" | awk '{exit !(NF == 3 && $1 <= 5)}'; echo $?)"
    # a constant tilt "up" (0, 0.57): the bottom and top sides' bands keep it or turn it
    # half a turn, the left and right sides' turn it a quarter: all four directions show
    expect_ok "tile a constant 'up' normal map" tile ../in/torus.obj ../in/tex.png up --tile 48 --normal upmap.png
    turns=$("$MAPS" turns up_normal.png 128 200 2>&1)
    CMD="maps turns up_normal.png 128 200"
    check "tile: a constant up reads as its quarter turns where bands are turned" \
        "each of 0, 90, 180, 270 degrees on >= 5% of the texels, >= 90% in all" "$turns" \
        "$(printf '%s\n' "$turns" | awk '{exit !(NF == 4 && $1 >= 0.05 && $2 >= 0.05 && $3 >= 0.05 && $4 >= 0.05 &&
            $1 + $2 + $3 + $4 >= 0.9)}'; echo $?)"

    # polycube: plain and upright tiles, each map in every quarter of the atlas
    expect_ok "polycube with a material" polycube ../in/spheretri.obj ../in/tex.png p --resolution 4 --tile 48 \
        --normal m_normal.png --height m_height.png
    check "polycube: the maps have the atlas's size" "$(png_size p.png)" "$(png_size p_normal.png), $(png_size p_height.png)" \
        "$([ "$(png_size p_normal.png)" = "$(png_size p.png)" ] && [ "$(png_size p_height.png)" = "$(png_size p.png)" ]; echo $?)"
    # A data map is grey (r = g = b): one channel, PNG colour type 0; the colour atlas RGB (type 2).
    check "polycube: the height map is a grey PNG, the colour atlas RGB" "colour types 0 and 2" \
        "$(od -An -tu1 -j25 -N1 p_height.png | tr -d ' ') and $(od -An -tu1 -j25 -N1 p.png | tr -d ' ')" \
        "$([ "$(od -An -tu1 -j25 -N1 p_height.png | tr -d ' ')" = 0 ] && [ "$(od -An -tu1 -j25 -N1 p.png | tr -d ' ')" = 2 ]; echo $?)"
    slope=$("$MAPS" slope p_height.png p_normal.png 2>&1)
    CMD="maps slope p_height.png p_normal.png"
    check "polycube: the normal atlas follows the height atlas's slopes" "median <= 5 deg" "$slope" \
        "$(printf '%s\n' "$slope" | awk '{exit !(NF == 3 && $1 <= 5)}'; echo $?)"

    # lapped: each patch's window of each map, and the bake turns the normals into the atlas
    # (a plane, pastes turned at random, the atlas a little finer than the patches)
    { for j in 0 1 2 3 4 5 6 7 8 9 10 11 12; do for i in 0 1 2 3 4 5 6 7 8 9 10 11 12; do
          echo "v $i $j 0"; echo "vt $(awk -v i=$i 'BEGIN{print i/12}') $(awk -v j=$j 'BEGIN{print j/12}')"; done; done
      for j in $(seq 0 11); do for i in $(seq 0 11); do a=$((j * 13 + i + 1)); b=$((a + 1)); c=$((a + 14)); d=$((a + 13))
          echo "f $a/$a $b/$b $c/$c"; echo "f $a/$a $c/$c $d/$d"; done; done; } >plane.obj
    expect_ok "lapped with a material" lapped plane.obj ../in/tex.png l --isotropic --scale 8 --patches 1 \
        --bake 512 --bake-uv mesh --normal m_normal.png --height m_height.png --pasting
    check "lapped: the patch's maps and the baked maps" "l_patch_normal.png, l_patch_height.png, l_baked_normal.png, ..." \
        "$(ls l_*)" \
        "$([ -s l_patch_normal.png ] && [ -s l_patch_height.png ] && [ -s l_baked_normal.png ] && [ -s l_baked_height.png ]; echo $?)"
    check "lapped: both MTLs name the normal maps" "norm l_patch_normal.png, norm l_baked_normal.png" \
        "$(grep -h norm l.mtl l_baked.mtl)" \
        "$(grep -qx 'norm l_patch_normal.png' l.mtl && grep -qx 'norm l_baked_normal.png' l_baked.mtl; echo $?)"
    slope=$("$MAPS" slope l_baked_height.png l_baked_normal.png 2>&1)
    CMD="maps slope l_baked_height.png l_baked_normal.png"
    check "lapped --bake: the baked normals follow the baked height's slopes" "median <= 15 deg" "$slope" \
        "$(printf '%s\n' "$slope" | awk '{exit !(NF == 3 && $1 <= 15)}'; echo $?)"
    expect_ok "lapped: y-down read of a +Y-up map (control)" lapped plane.obj ../in/tex.png lc --isotropic --scale 8 \
        --patches 1 --bake 512 --bake-uv mesh --normal m_normal.png --normal-y-down --height m_height.png --pasting
    slope=$("$MAPS" slope lc_baked_height.png lc_baked_normal.png 2>&1)
    check "lapped: the control's baked normals disagree" "median above 30 deg" "$slope" \
        "$(printf '%s\n' "$slope" | awk '{exit !(NF == 3 && $1 > 30)}'; echo $?)"

    # the GLB of a material: normal, metallicRoughness and occlusion textures beside the
    # colour, the normal map the very atlas the OBJ run wrote; lapped's and hpm's too
    expect_ok "tile a material into a GLB" tile ../in/torus.obj ../in/tex.png t.glb --tile 48 --normal m_normal.png \
        --roughness m_roughness.png --height m_height.png --metallic coords.png --ao m_height.png
    err_mentions "tile GLB with --height: says glTF has no height map" "no height map"
    glb_check "tile GLB with a material" t.glb
    check "tile GLB: the material has every texture glTF takes" "normalTexture, metallicRoughnessTexture, occlusionTexture" \
        "$GLB_JSON" "$(printf '%s' "$GLB_JSON" | grep -q '"normalTexture"' &&
            printf '%s' "$GLB_JSON" | grep -q '"metallicRoughnessTexture"' &&
            printf '%s' "$GLB_JSON" | grep -q '"occlusionTexture"'; echo $?)"
    if [ -n "$GLB_PROBE" ]; then
        glb_image t.glb normal glb_normal.png
        most=$("$MAPS" diff glb_normal.png t_normal.png 2>&1)
        CMD="maps diff glb_normal.png t_normal.png"
        check "tile GLB: its normal map is the OBJ run's normal atlas" "the same pixels (largest difference 0)" \
            "$most" "$([ "$most" = 0 ]; echo $?)"
    fi
    validate "tile GLB with a material" t.glb
    # the same material as a .gltf: a PNG per texture beside it, the GLB's images
    mkdir g && cp t.glb g/ && cd g || exit 1
    expect_ok "tile a material into a .gltf" tile ../../in/torus.obj ../../in/tex.png t.gltf --tile 48 \
        --normal ../m_normal.png --roughness ../m_roughness.png --height ../m_height.png --metallic ../coords.png \
        --ao ../m_height.png
    CMD="ls g after tiledtex tile ... t.gltf with a material"
    check "tile .gltf with a material: a PNG per texture" \
        "t.bin t.glb t.gltf t_baseColor.png t_metallicRoughness.png t_normal.png t_occlusion.png" "$(ls | tr '\n' ' ')" \
        "$([ "$(ls | tr '\n' ' ')" = "t.bin t.glb t.gltf t_baseColor.png t_metallicRoughness.png t_normal.png t_occlusion.png " ]
           echo $?)"
    gltf_same_as_glb "tile .gltf with a material" t
    cd .. || exit 1
    # with a normal map, a tangent per vertex: unit, across the normal, w = +-1, and along
    # +u (the first triangle's texture axis)
    if [ -n "$GLB_PROBE" ]; then
        tangents=$(glb_accessor t.glb "$(json_number "$GLB_JSON" TANGENT)" | paste -d' ' - - - -)
        normals=$(glb_accessor t.glb "$(json_number "$GLB_JSON" NORMAL)" | paste -d' ' - - -)
        bad=$(paste -d' ' <(printf '%s\n' "$tangents") <(printf '%s\n' "$normals") | awk '
            NF == 7 { n++; l = sqrt($1*$1 + $2*$2 + $3*$3); d = $1*$5 + $2*$6 + $3*$7
                      if (l < 0.999 || l > 1.001 || d > 0.001 || d < -0.001 || ($4 != 1 && $4 != -1)) bad++ }
            END { print (n > 0 ? bad + 0 : "none") }')
        CMD="glb_accessor t.glb TANGENT / NORMAL"
        check "tile GLB: a unit tangent across each normal, w = +-1" "0 bad of $(printf '%s\n' "$tangents" | wc -l)" \
            "$bad" "$([ "$bad" = 0 ]; echo $?)"
        # a square whose u runs along +x and v along +y: every tangent is (1, 0, 0), w = 1
        printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n' >square.obj
        expect_ok "tile a square into a GLB with a normal map" tile square.obj small.png square.glb --tile 48 \
            --normal small.png
        glb_check "square GLB" square.glb
        tangents=$(glb_accessor square.glb "$(json_number "$GLB_JSON" TANGENT)" | paste -d' ' - - - - | sort -u)
        CMD="glb_accessor square.glb TANGENT"
        check "square GLB: the tangent runs along +u, the bitangent along +v" "1 0 0 1" "$tangents" \
            "$(printf '%s\n' "$tangents" | awk 'NF == 4 && ($1 < 0.9999 || $2*$2 > 1e-8 || $3*$3 > 1e-8 || $4 != 1) {bad++}
                END {exit !(NR > 0 && bad == 0)}'; echo $?)"
        expect_ok "tile a GLB without a normal map" tile ../in/torus.obj ../in/tex.png plain.glb --tile 48
        glb_check "tile GLB without a normal map" plain.glb
        check "tile GLB without a normal map: no tangents" "no TANGENT" "$GLB_JSON" \
            "$(! printf '%s' "$GLB_JSON" | grep -q TANGENT; echo $?)"
    fi
    expect_ok "lapped: a material baked into a GLB" lapped plane.obj ../in/tex.png lg.glb --scale 8 --patches 1 \
        --bake 128 --normal m_normal.png --roughness m_roughness.png
    glb_check "lapped GLB with a material" lg.glb
    check "lapped GLB: the baked normal and roughness maps" "normalTexture, metallicRoughnessTexture" "$GLB_JSON" \
        "$(printf '%s' "$GLB_JSON" | grep -q '"normalTexture"' &&
            printf '%s' "$GLB_JSON" | grep -q '"metallicRoughnessTexture"'; echo $?)"
    validate "lapped GLB with a material" lg.glb
    expect_ok "hpm: a material into a GLB" hpm ../in/torus.obj ../in/tex.png hg.glb --normal m_normal.png --ao m_height.png
    validate "hpm GLB with a material" hg.glb
    expect_ok "polycube: a material into a GLB" polycube ../in/spheretri.obj ../in/tex.png pg.glb --resolution 4 \
        --tile 48 --normal m_normal.png --metallic m_roughness.png
    validate "polycube GLB with a material" pg.glb

    # hpm: the UVs serve every map as they are; each is copied beside the OBJ as IMAGE is
    # (--reference-image: named where it is); a y-down normal map is rewritten +Y up
    expect_ok "hpm with a material" hpm ../in/torus.obj ../in/tex.png h --normal m_normal.png --roughness m_roughness.png
    check "hpm: the MTL names the maps' copies" "norm h_normal.png, map_Pr h_roughness.png" "$(cat h.mtl)" \
        "$(grep -qx 'norm h_normal.png' h.mtl && grep -qx 'map_Pr h_roughness.png' h.mtl &&
           cmp -s h_normal.png m_normal.png && cmp -s h_roughness.png m_roughness.png; echo $?)"
    expect_ok "hpm with a material, --reference-image" hpm ../in/torus.obj ../in/tex.png hr --normal m_normal.png \
        --roughness m_roughness.png --reference-image
    check "hpm --reference-image: the MTL names the maps where they are" "norm m_normal.png, map_Pr m_roughness.png" \
        "$(cat hr.mtl)" \
        "$(grep -qx 'norm m_normal.png' hr.mtl && grep -qx 'map_Pr m_roughness.png' hr.mtl && [ ! -e hr_normal.png ]
           echo $?)"
    expect_ok "hpm --normal-y-down" hpm ../in/torus.obj ../in/tex.png hd --normal dx_normal.png --normal-y-down
    check "hpm --normal-y-down: writes hd_normal.png +Y up and names it" "norm hd_normal.png" "$(cat hd.mtl)" \
        "$(grep -qx 'norm hd_normal.png' hd.mtl && [ -s hd_normal.png ]; echo $?)"
    px_in=$("$W/pixstat" m_normal.png 17 23 2>/dev/null)
    px_out=$("$W/pixstat" hd_normal.png 17 23 2>/dev/null)
    CMD="pixstat m_normal.png / hd_normal.png 17 23"
    check "hpm --normal-y-down: the rewritten map is the +Y-up map" "$px_in (within 2)" "$px_out" \
        "$(printf '%s\n%s\n' "$px_in" "$px_out" | awk 'NR==1{a=$1;b=$2;c=$3} NR==2{exit !(NF==3 && ($1-a)^2<=4 && ($2-b)^2<=4 && ($3-c)^2<=4)}'; echo $?)"

    # render --normal: the lighting changes; refused on a pasting mesh
    expect_ok "render with the normal map" render t.obj t.png nm.png --size 64x64 --normal t_normal.png
    expect_ok "render without it" render t.obj t.png plain.png --size 64x64 --no-materials
    check "render --normal: the normal map changes the picture" "files differ" "identical" \
        "$(! cmp -s nm.png plain.png; echo $?)"
    expect_ok "render with the MTL's normal map" render t.obj t.png auto.png --size 64x64
    check "render: the material's normal map (norm) lights the surface as --normal does" "cmp equal" \
        "$(cmp auto.png nm.png 2>&1)" "$(cmp -s auto.png nm.png; echo $?)"
    # a square facing the camera, u to the right and v up the screen: a normal map tilted
    # towards the key light (upper left) brightens it, one tilted away darkens it
    printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n' >sq.obj
    "$MAPS" const 64 64 80 176 218 towards.png && "$MAPS" const 64 64 176 80 218 away.png
    for n in towards away; do
        expect_ok "render a square with the normal map '$n'" render sq.obj small.png sq_$n.png --size 32x32 \
            --yaw 0 --pitch 0 --normal $n.png
    done
    expect_ok "render the square unmapped" render sq.obj small.png sq_flat.png --size 32x32 --yaw 0 --pitch 0
    # the file's own normals light it as Blender would: tilted up-left (towards the key light)
    # the square is brighter than with the normals computed, tilted down-right darker
    for n in "-0.5 0.5 0.7:up" "0.5 -0.5 0.7:down"; do
        { printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn %s\n' "${n%%:*}"
          printf 'f 1/1/1 2/2/1 3/3/1 4/4/1\n'; } >sq_vn_${n##*:}.obj
        expect_ok "render a square with its own normals (${n##*:})" render sq_vn_${n##*:}.obj small.png \
            sq_vn_${n##*:}.png --size 32x32 --yaw 0 --pitch 0
    done
    lit=$(for n in up flat down; do f=sq_vn_$n.png; [ $n = flat ] && f=sq_flat.png; "$W/pixstat" $f 16 16 | awk '{print $1}'; done | tr '\n' ' ')
    CMD="pixstat sq_vn_up.png / sq_flat.png / sq_vn_down.png 16 16"
    check "render: the file's normals (vn) shade the surface" "up-left > computed > down-right" "$lit" \
        "$(printf '%s\n' "$lit" | awk '{exit !(NF == 3 && $1 > $2 && $2 > $3)}'; echo $?)"
    lit=$(for n in towards flat away; do "$W/pixstat" sq_$n.png 16 16 | awk '{print $1}'; done | tr '\n' ' ')
    CMD="pixstat sq_towards.png / sq_flat.png / sq_away.png 16 16"
    check "render --normal: tilted towards the light is brighter, away darker (u right, v up)" \
        "towards > flat > away" "$lit" "$(printf '%s\n' "$lit" | awk '{exit !(NF == 3 && $1 > $2 && $2 > $3)}'; echo $?)"

    # bad input (each in an empty directory of its own)
    expect_error "render --normal on a pasting mesh" render "$MD/l.obj" "$MD/l_patch.png" v.png \
        --normal "$MD/l_patch_normal.png"
    err_mentions "render --normal on a pasting mesh: says to render the bake" "bake"
    expect_error "a map of another size" tile "$W/in/torus.obj" "$W/in/tex.png" bad --normal "$MD/small.png"
    err_mentions "a map of another size: names both sizes" "128x128.*256x256"
    expect_usage_error "--normal-y-down without --normal" tile "$W/in/torus.obj" "$W/in/tex.png" bad --normal-y-down
    expect_usage_error "--roughness without a value" lapped "$W/in/torus.obj" "$W/in/tex.png" bad --roughness
    expect_error "a missing map" polycube "$W/in/spheretri.obj" "$W/in/tex.png" bad --height nope.png
    err_mentions "a missing map: names it" "nope\.png"
    cd "$MD" || exit 1
    run tile ../in/torus.obj ../in/tex.png m --height m_height.png
    check "a map's output that would replace an input map is refused" "exit 1, m_height.png unchanged" \
        "exit $RC: $ERR" "$([ $RC -eq 1 ] && "$MAPS" slope m_height.png m_normal.png >/dev/null; echo $?)"
else
    fail "helper for material maps" "$CMD" "compiles" "$(head -c 300 "$W/err")"
fi
cd "$W" || exit 1

# ======================================================================
# Progress on a terminal
# ======================================================================
# pty_watch runs the tool on a pseudo-terminal and notes when each piece of
# text between carriage returns arrives: a progress line comes within a
# second, is redrawn at least once a second, never shows 100 %, and is gone
# before the summary; nothing of it with -q or without a terminal.
cat >"$W/pty_watch.c" <<'EOF_C'
/* pty_watch FRAMES CMD ARGS...: run CMD with its standard output and error
   on a new pseudo-terminal, as a user's shell would, and write FRAMES: one
   line "SECONDS TEXT" for each piece of text between carriage returns and
   newlines, SECONDS when it arrived, then "end SECONDS". Exits with CMD's
   status. */
#define _XOPEN_SOURCE 700
#include <fcntl.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

int main(int argc, char **argv)
{
    char text[4096], piece[65536];
    size_t length = 0;
    int master, status;
    double start;
    pid_t child;
    FILE *frames;
    if (argc < 3 || !(frames = fopen(argv[1], "w"))) return 125;
    master = posix_openpt(O_RDWR | O_NOCTTY);
    if (master < 0 || grantpt(master) != 0 || unlockpt(master) != 0) return 125;
    start = now();
    child = fork();
    if (child < 0) return 125;
    if (child == 0) {
        int slave;
        setsid();
        slave = open(ptsname(master), O_RDWR);
        if (slave < 0) _exit(125);
        dup2(slave, 1);
        dup2(slave, 2);
        execv(argv[2], argv + 2);
        _exit(126);
    }
    for (;;) {
        struct pollfd p;
        ssize_t n, i;
        p.fd = master;
        p.events = POLLIN;
        if (poll(&p, 1, 100) <= 0) {
            if (waitpid(child, &status, WNOHANG) == child) break;
            continue;
        }
        n = read(master, piece, sizeof piece);
        if (n <= 0) break;  /* EIO: the child closed the terminal */
        for (i = 0; i < n; i++) {
            if (piece[i] == '\r' || piece[i] == '\n') {
                while (length > 0 && text[length - 1] == ' ') length--;
                if (length > 0) fprintf(frames, "%.3f %.*s\n", now() - start, (int)length, text);
                length = 0;
            } else if (length < sizeof text - 1) {
                text[length++] = piece[i];
            }
        }
    }
    if (length > 0) fprintf(frames, "%.3f %.*s\n", now() - start, (int)length, text);
    if (waitpid(child, &status, 0) != child && !WIFEXITED(status)) status = 0;
    fprintf(frames, "end %.3f\n", now() - start);
    fclose(frames);
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}
EOF_C
CMD="$HELPER_CC pty_watch.c (test helper)"
if $HELPER_CC -O1 -w "$W/pty_watch.c" -o "$W/pty_watch" 2>"$W/err"; then
    newdir
    "$TOOL" generate mesh t.obj --shape torus >/dev/null 2>&1
    # 24576 triangles and their bake: about a second at -O2, a few under the sanitizers
    CMD="pty_watch frames.txt tiledtex lapped t.obj ../in/lap.png out --scale 0.6 --subdivide 2"
    "$W/pty_watch" frames.txt "$TOOL" lapped t.obj ../in/lap.png out --scale 0.6 --subdivide 2 >/dev/null 2>&1
    RC=$?
    check "progress: the run on a terminal" "exit 0" "exit $RC" "$([ $RC -eq 0 ]; echo $?)"
    # the frames before the summary (which starts with the mesh's name)
    awk '$2 == "t.obj:" { exit } $1 != "end" { print }' frames.txt >progress.txt
    stages=$(sed -n 's/^[0-9.]* tiledtex: \([a-z][^:(]*\).*/\1/p' progress.txt | sed 's/ *$//' | sort -u | tr '\n' ',')
    check "progress: a line naming each stage (pasting, baking, writing, ...)" "at least 3 stages" "$stages" \
        "$([ "$(printf '%s' "$stages" | tr ',' '\n' | grep -c .)" -ge 3 ]; echo $?)"
    check "progress: never at 100 % while work goes on" "no '100.0%' before the summary" \
        "$(grep '100\.0%' progress.txt | head -2)" "$(! grep -q '100\.0%' progress.txt; echo $?)"
    timing=$(awk '$1 == "end" { end = $2 } $2 == "t.obj:" && !summary { summary = $1 }
                  $2 == "tiledtex:" && !summary { if (!first) first = $1; if ($1 - last > gap && first) gap = $1 - last; last = $1 }
                  END { if (summary - last > gap) gap = summary - last; printf "%.2f %.2f %.2f", first, gap, end }' frames.txt)
    read -r first gap end <<<"$timing"
    check "progress: the first line within a second, then at least one a second (2 s allowed on a loaded machine)" \
        "first <= 1.5 s, gaps <= 2 s" "first $first s, largest gap $gap s, run $end s" \
        "$(awk -v f="$first" -v g="$gap" 'BEGIN { exit !(f > 0 && f <= 1.5 && g <= 2) }'; echo $?)"
    check "progress: erased before the summary, which starts a line of its own" \
        "'t.obj: 24576 triangles' and 'wrote out.obj' as whole lines" "$(grep -E 't\.obj: |wrote ' frames.txt | head -3)" \
        "$(grep -qE '^[0-9.]+ t\.obj: 24576 triangles' frames.txt && grep -qE '^[0-9.]+ wrote out\.obj' frames.txt; echo $?)"
    "$W/pty_watch" quiet.txt "$TOOL" -q lapped t.obj ../in/lap.png q --scale 0.6 --subdivide 2 >/dev/null 2>&1
    check "progress: nothing with -q" "no line but 'end'" "$(head -3 quiet.txt)" \
        "$([ "$(grep -vc '^end ' quiet.txt)" = 0 ]; echo $?)"
    run lapped t.obj ../in/lap.png p --scale 0.6 --subdivide 2
    check "progress: nothing when stderr is not a terminal" "stderr without a carriage return" "$(od -c "$W/err" | head -3)" \
        "$([ $RC -eq 0 ] && ! grep -q $'\r' "$W/err"; echo $?)"
    cd "$W" || exit 1
else
    fail "helper for the progress line" "$CMD" "compiles" "$(head -c 300 "$W/err")"
fi

# ======================================================================
# Sanitizers
# ======================================================================
CMD="all $RUNS runs"
[ $SANITIZER_REPORTS -eq 0 ] && pass   # each report was already counted as a failure

echo "$PASS passed, $FAIL failed"
[ "$FAIL" -eq 0 ]
