#!/usr/bin/env bash
# tests/import_check.sh - do other programs open what the tool writes?
#
#   bash tests/import_check.sh TOOL        (e.g. build/tiledtex)
#
# For each pipeline (tile, lapped, hpm, polycube) it writes the default
# output, OBJ and GLB, of a small torus and a 256x256 texture, copies the
# files to another folder and deletes the originals (a texture found only
# where it was written would be a missing texture once the folder moves),
# then, from the new folder:
#   * with assimp (`assimp info`, Debian's assimp-utils): each file imports,
#     every texture it refers to is embedded or beside it, and it has as many
#     triangles as the file holds;
#   * with Blender (tests/import_check.py; glTF importer for the GLB, Blender
#     3.4's default OBJ importer for the OBJ): the same, and an unlit Cycles
#     render from `tiledtex render`'s viewpoint within 8/255 of `tiledtex
#     render --unlit`, and a control (the texture coordinates' v flipped)
#     that must be far from it.
# Each program missing is one "skip ..." line, and its checks are not run.
# Prints "ok   ..." / "FAIL ..." per check and, last, "N passed, M failed";
# exits non-zero when M > 0.
set -u

if [ $# -ne 1 ] || [ -z "$1" ]; then
    echo "usage: bash tests/import_check.sh TOOL" >&2
    echo "0 passed, 1 failed"
    exit 2
fi
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
TOOL=$1
case $TOOL in
    */*) TOOL=$(cd "$(dirname "$TOOL")" 2>/dev/null && pwd)/$(basename "$TOOL") ;;
    *) TOOL=$(command -v "$TOOL" || echo "$TOOL") ;;
esac

PASS=0
FAIL=0
pass() { PASS=$((PASS + 1)); echo "ok   $1"; }
fail() {
    FAIL=$((FAIL + 1))
    echo "FAIL $1"
    if [ -n "${2:-}" ]; then printf '%s\n' "$2" | head -n 12 | sed 's/^/     | /'; fi
}
finish() {
    echo "$PASS passed, $FAIL failed"
    [ "$FAIL" -eq 0 ] && exit 0
    exit 1
}

if [ ! -x "$TOOL" ]; then
    fail "import: $1 is not an executable"
    finish
fi

# BLENDER= or ASSIMP= (empty) skips that program; a path picks another build.
BLENDER=${BLENDER-$(command -v blender)}
ASSIMP=${ASSIMP-$(command -v assimp)}
if [ -z "$BLENDER" ] && [ -z "$ASSIMP" ]; then
    echo "skip import test: neither Blender nor assimp is installed (apt-get install blender assimp-utils)" \
        "or both left out (BLENDER=, ASSIMP=)"
    finish
fi
[ -n "$BLENDER" ] || echo "skip import test in Blender: blender is not installed (apt-get install blender)"
# import_check.py compares pictures with numpy, which a Blender installed
# without its recommended packages lacks: installed when root, else skipped
# with the command.
blender_has_numpy() { "$BLENDER" -b --python-exit-code 1 --python-expr "import numpy" >/dev/null 2>&1; }
if [ -n "$BLENDER" ] && ! blender_has_numpy; then
    if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
        echo "installing python3-numpy (Blender's Python has no numpy) ..."
        DEBIAN_FRONTEND=noninteractive apt-get install -y -qq python3-numpy >/dev/null 2>&1 || true
    fi
    if ! blender_has_numpy; then
        echo "skip import test in Blender: its Python has no numpy (apt-get install python3-numpy)"
        BLENDER=
    fi
fi
if [ -z "$BLENDER" ] && [ -z "$ASSIMP" ]; then
    finish
fi
[ -n "$ASSIMP" ] || echo "skip import test in assimp: assimp is not installed (apt-get install assimp-utils)"

W=$(mktemp -d "${TMPDIR:-/tmp}/tiledtex-import.XXXXXX") || exit 1
trap 'cd /; rm -rf "$W"' EXIT
cd "$W" || exit 1
export LC_ALL=C
PIPELINES="tile lapped hpm polycube"
# The size of both renders: large enough that the stones of the texture show
# (so the v-flipped control is far off), small enough for Cycles to be quick.
RENDER_SIZE=256

if ! log=$("$TOOL" -q generate mesh m.obj --shape torus 2>&1 && "$TOOL" -q generate texture t.png --size 256 2>&1); then
    fail "import: cannot generate the inputs" "$log"
    finish
fi
mkdir moved pictures

# The files in the moved folder that the checks below read.
ready=""
for p in $PIPELINES; do
    mkdir "written_$p"
    if log=$(cd "written_$p" && "$TOOL" -q "$p" ../m.obj ../t.png "$p.obj" 2>&1 &&
        "$TOOL" -q "$p" ../m.obj ../t.png "$p.glb" 2>&1) &&
        mkdir "moved/$p" && cp "written_$p"/* "moved/$p/" && rm -r "written_$p" &&
        log=$("$TOOL" -q render "moved/$p/$p.obj" "moved/$p/$p.png" "pictures/reference_$p.png" \
            --size "${RENDER_SIZE}x$RENDER_SIZE" --unlit 2>&1); then
        pass "import: $p writes its OBJ and GLB, moved to another folder, and render --unlit draws the OBJ"
        ready="$ready $p"
    else
        fail "import: $p: writing, moving or rendering its output failed" "$log"
    fi
done

# assimp: `assimp info FILE` prints "Faces: N" (after triangulating) and the
# textures the materials refer to: "*K" is the K-th embedded texture, anything
# else a file relative to the model's folder.
assimp_check() {
    local p=$1 file=$2 kind=$3 info expected got embedded refs missing="" ref
    if ! info=$("$ASSIMP" info "$file" 2>&1); then
        fail "assimp: $p $kind does not import" "$(printf '%s\n' "$info" | grep -iE 'error|fail' | head -n 5)"
        fail "assimp: $p $kind: triangle count: not imported"
        return
    fi
    embedded=$(printf '%s\n' "$info" | sed -n 's/^Textures (embed\.): *\([0-9]*\).*/\1/p' | head -n 1)
    while IFS= read -r ref; do
        case $ref in
            "*"*) [ "${ref#\*}" -lt "${embedded:-0}" ] 2>/dev/null || missing="$missing $ref" ;;
            *) [ -f "$(dirname "$file")/$ref" ] || missing="$missing $ref" ;;
        esac
    done < <(printf '%s\n' "$info" | sed -n '/^Texture Refs:/,/^$/p' | sed -n "s/^ *'\(.*\)'$/\1/p")
    refs=$(printf '%s\n' "$info" | sed -n '/^Texture Refs:/,/^$/p' | grep -c "^ *'")
    if [ "$refs" -gt 0 ] && [ -z "$missing" ]; then
        pass "assimp: $p $kind imports from the moved folder, its $refs texture reference(s) found"
    else
        fail "assimp: $p $kind: texture references $refs, missing:${missing:- none}"
    fi
    got=$(printf '%s\n' "$info" | sed -n 's/^Faces: *\([0-9]*\).*/\1/p' | head -n 1)
    if [ "$kind" = OBJ ]; then
        expected=$(awk '$1 == "f" { n += NF - 3 } END { print n + 0 }' "$file")
    elif command -v python3 >/dev/null 2>&1; then
        expected=$(python3 "$ROOT/tests/mesh_counts.py" "$file" 2>&1)
    else
        echo "skip assimp: $p GLB triangle count: python3 (which reads the GLB's JSON) is not installed"
        return
    fi
    if [ "$got" = "$expected" ]; then
        pass "assimp: $p $kind: $got triangles imported, the file holds $expected"
    else
        fail "assimp: $p $kind: ${got:-no} triangles imported, the file holds $expected"
    fi
}

if [ -n "$ASSIMP" ]; then
    for p in $ready; do
        assimp_check "$p" "moved/$p/$p.glb" GLB
        assimp_check "$p" "moved/$p/$p.obj" OBJ
    done
fi

# Blender: one run for every file (it takes seconds to start); each file
# (4 arguments) is the 4 checks tests/import_check.py prints for it.
if [ -n "$BLENDER" ] && [ -n "$ready" ]; then
    jobs=()
    for p in $ready; do
        jobs+=("blender: $p GLB" gltf "$W/moved/$p/$p.glb" "$W/pictures/reference_$p.png"
            "blender: $p OBJ" obj "$W/moved/$p/$p.obj" "$W/pictures/reference_$p.png")
    done
    # Blender's OBJ importer looks for a texture in the current directory
    # before the OBJ's own: start it where there is nothing to find.
    mkdir empty
    expected_checks=$((${#jobs[@]} / 4 * 4))   # files x checks per file
    (cd empty && nice "$BLENDER" -b --factory-startup --python-exit-code 1 --python "$ROOT/tests/import_check.py" -- \
        --size "$RENDER_SIZE" "$W/pictures" "${jobs[@]}" >"$W/blender.log" 2>&1)
    status=$?
    results=$(grep -E '^(ok   |FAIL )' blender.log)
    printf '%s\n' "$results"
    reported=$(printf '%s\n' "$results" | grep -c -E '^(ok   |FAIL )')
    failed=$(printf '%s\n' "$results" | grep -c '^FAIL ')
    PASS=$((PASS + reported - failed))
    FAIL=$((FAIL + failed))
    if [ "$reported" -lt "$expected_checks" ] || [ "$status" -ne 0 ]; then
        fail "blender: stopped after $reported of $expected_checks checks, exit status $status" \
            "$(grep -vE '^(ok   |FAIL |Fra:|Progress:)' blender.log | tail -n 12)"
    fi
fi

if [ "$FAIL" -gt 0 ]; then
    mkdir -p "$ROOT/build/import_check" && cp pictures/*.png "$ROOT/build/import_check/" 2>/dev/null &&
        echo "note: the pictures compared are in build/import_check/ (reference_*.png: tiledtex render --unlit)"
fi
finish
