#!/usr/bin/env bash
# bench/bench_scale.sh TOOL - how each pipeline's cost grows with the mesh, and
# what a second core gains: `make bench` runs it. Prints `name value unit`
# lines on stdout (notes and the targets on stderr).
#
# Meshes: a real scan, the 96,966-triangle horse of ../shared/data (or
# $BENCH_DATA/meshes/horse.obj), and the same scan cut 1-to-4 once and twice
# (387,864 and 1,551,456 triangles: bench/bench_subdivide.awk), with the
# 512 x 512 gravel photo. Each of tile, tile-remesh (tile --up z --remesh
# auto: the scan remeshed into quads along the field first), hpm, polycube
# and lapped (--bake 2048) runs as a user runs it, files in and out, at -j 1
# and -j 2:
#   scale_P_Nk_cpu_j1        CPU seconds (user + system) at -j 1, what the
#                            targets compare: other jobs' load does not count
#   scale_P_Nk_wall_j1/_j2   wall seconds at -j 1 and -j 2
#   scale_P_Nk_wall_j2_over_j1
#   scale_P_Nk_identical_j2  1 when every output file of -j 2 equals -j 1's
#   scale_lapped_Nk_bake_wall_j1/_j2/_j2_over_j1
#                            the bake stage alone, wall seconds as the tool
#                            reports them ("bake: ... s wall")
#   scale_P_Nk_peak_j1       peak resident memory, MiB
#   scale_P_Nk_v030_cpu / _v030_peak / _cpu_over_v030
#                            v0.3.0, built in the same run from its commit,
#                            on the same input: the figures to beat
#   scale_P_cpu_growth_4x / _16x
#                            CPU at 4x (16x) the faces over CPU at 1x
#   scale_P_97k_cancel_seconds
#                            Ctrl-C halfway through the 97k run: seconds
#                            until the tool has exited (target <= 1)
# Targets: growth_4x <= 5; the 16x run finishes; at 97k faces
# lapped <= 4 s, hpm <= 2.5 s, polycube <= 3 s, tile <= 0.3 s, tile-remesh <= 1.5 s CPU, peak memory
# no higher than v0.3.0's; -j 2 identical, wall <= 0.65x (tile synthesis, the
# lapped bake, polycube) or 0.8x (hpm) of -j 1.
#
# The 97k figures and the synthesis are each the median of 5 runs.
#
# Environment: BENCH_SCALES="1 4 16" (which sizes), BENCH_RUNS=5 (runs at 97k
# faces, odd), BENCH_V030=0 (skip the
# v0.3.0 build), BENCH_TIMEOUT=900 (seconds a run may take),
# BENCH_V030_TIMEOUT=240 (v0.3.0's lapped grows as n^2: at 16x it is stopped
# and reported as not finished).
set -u
cd "$(dirname "$0")/.." || exit 1
tool=${1:-build/tiledtex}
data=${BENCH_DATA:-../shared/data}
scales=${BENCH_SCALES:-1 4 16}
small_runs=${BENCH_RUNS:-5}
timeout=${BENCH_TIMEOUT:-900}
old_timeout=${BENCH_V030_TIMEOUT:-240}
# The last commit of v0.3.0: its tool is built from this commit's files.
v030_commit=012b20206d48dc711f69cba70b2f58df6ea6e4a6
work=build/bench-scale
mkdir -p "$work" || exit 1
run=build/bench_run

mesh0=$data/meshes/horse.obj
photo=$data/textures/gravel_gray.png
if [ ! -f "$mesh0" ] || [ ! -f "$photo" ]; then
    echo "bench_scale: no $mesh0 or $photo (the development data set; set BENCH_DATA): skipped" >&2
    exit 0
fi

# The meshes, made once and kept in build/.
cp "$mesh0" "$work/horse_x1.obj"
for s in 4 16; do
    if [ ! -s "$work/horse_x$s.obj" ]; then
        prev=$work/horse_x$((s / 4)).obj
        awk -f bench/bench_subdivide.awk "$prev" >"$work/horse_x$s.obj.part" &&
            mv "$work/horse_x$s.obj.part" "$work/horse_x$s.obj" || { echo "bench_scale: subdividing failed" >&2; exit 1; }
    fi
done

old=""
if [ "${BENCH_V030:-1}" != 0 ]; then
    if [ -x "$work/v030/tiledtex" ] ||
        { rm -rf "$work/v030" && mkdir -p "$work/v030" &&
          git archive "$v030_commit" tiledtex.h examples | tar -x -C "$work/v030" &&
          (cd "$work/v030" && ${CC:-cc} -O2 -g -std=c99 -I. \
              $(pkg-config --cflags stb 2>/dev/null || echo -I/usr/include/stb) examples/*.c -o tiledtex -lm); }; then
        old=$work/v030/tiledtex
    else
        echo "bench_scale: could not build v0.3.0 from commit $v030_commit (no git history?): no ratios" >&2
    fi
fi

# figure NAME VALUE UNIT
figure() { echo "$1 $2 $3"; }
ratio() { awk -v a="$1" -v b="$2" 'BEGIN { if (b > 0) printf "%.3f", a / b; else print "nan" }'; }
mib() { awk -v k="$1" 'BEGIN { printf "%.1f", k / 1024 }'; }

# measure TOOL SECONDS DIR JOBS PIPELINE MESH [RUNS]: runs it in DIR (made
# afresh), sets cpu wall peak status. With RUNS (odd) it runs that many times
# and keeps the median of each figure: a run of a second or less on a shared
# machine varies by a fifth from one run to the next.
# pipeline_args PIPELINE: sets sub (the command) and extra (its options):
# tile-remesh is tile remeshing the scan along --up z first.
pipeline_args() {
    sub=$1 extra=()
    case $1 in
        lapped) extra=(--bake 2048) ;;
        tile-remesh) sub=tile extra=(--up z --remesh auto) ;;
    esac
}

measure() {
    local tool_=$1 limit=$2 dir=$3 jobs=$4 pipeline=$5 mesh=$6 runs=${7:-1} extra=() jflag=() i sub
    local cpus=() walls=() peaks=() bakes=()
    pipeline_args "$pipeline"
    [ -n "$jobs" ] && jflag=(-j "$jobs")
    for ((i = 0; i < runs; i++)); do
        rm -rf "$dir" && mkdir -p "$dir"
        read -r cpu wall peak status < <("$run" "$limit" sh -c 'exec "$@" >"$0/log" 2>&1' "$dir" \
            "$tool_" "${jflag[@]}" "$sub" "$mesh" "$photo" "$dir/out" "${extra[@]}")
        [ "$status" = 0 ] || return
        cpus+=("$cpu") walls+=("$wall") peaks+=("$peak")
        # the bake stage's own wall time, as the tool reports it
        bakes+=("$(sed -n 's/^bake: .* texels in \([0-9.]*\) s wall.*/\1/p' "$dir/log")")
    done
    cpu=$(median "${cpus[@]}") wall=$(median "${walls[@]}") peak=$(median "${peaks[@]}")
    bake=
    [ -n "${bakes[0]}" ] && bake=$(median "${bakes[@]}")
}

# median NUMBER...: the middle one.
median() { printf '%s\n' "$@" | sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }

# measure_cancel PIPELINE MESH WALL NAME: Ctrl-C (SIGINT) halfway through a
# run, by its wall time at -j 1: the seconds until the tool has exited (the
# library call cancelled through its progress callback). Target: <= 1 s.
measure_cancel() {
    local dir=$work/$1-cancel extra=() start end rc sub
    rm -rf "$dir" && mkdir -p "$dir"
    pipeline_args "$1"
    "$tool" -j 1 "$sub" "$2" "$photo" "$dir/out" "${extra[@]}" >"$dir/log" 2>&1 &
    local pid=$!
    sleep "$(awk -v w="$3" 'BEGIN { printf "%.2f", w / 2 }')"
    start=$(date +%s.%N)
    kill -INT "$pid" 2>/dev/null
    wait "$pid"
    rc=$?
    end=$(date +%s.%N)
    if [ "$rc" = 130 ]; then
        figure "${4}_cancel_seconds" "$(awk -v a="$start" -v b="$end" 'BEGIN { printf "%.3f", b - a }')" s
    else
        echo "bench_scale: $1 interrupted halfway: status $rc ($(tail -n 1 "$dir/log"))" >&2
    fi
    rm -rf "$dir"
}

# Tile synthesis alone (the paper's 256 tiles of 128 texels, and the PNG):
# what a second core gains there.
measure_synth() {
    local dir=$work/synth-j$1 i cpus=() walls=()
    for ((i = 0; i < small_runs; i++)); do
        rm -rf "$dir" && mkdir -p "$dir"
        read -r cpu wall peak status < <("$run" "$timeout" sh -c 'exec "$@" >"$0/log" 2>&1' "$dir" \
            "$tool" -j "$1" synth "$photo" "$dir/atlas.png" --colors 2 --tile 128)
        [ "$status" = 0 ] || return
        cpus+=("$cpu") walls+=("$wall")
    done
    cpu=$(median "${cpus[@]}") wall=$(median "${walls[@]}")
}
measure_synth 1
if [ "$status" = 0 ]; then
    synth_wall1=$wall
    figure scale_synth_n2_cpu_j1 "$cpu" s
    figure scale_synth_n2_wall_j1 "$wall" s
    measure_synth 2
    if [ "$status" = 0 ]; then
        figure scale_synth_n2_wall_j2 "$wall" s
        figure scale_synth_n2_wall_j2_over_j1 "$(ratio "$wall" "$synth_wall1")" x
        cmp -s "$work/synth-j1/atlas.png" "$work/synth-j2/atlas.png" && same=1 || same=0
        figure scale_synth_n2_identical_j2 "$same" bool
    fi
else
    echo "bench_scale: synth: status $status ($(tail -n 1 "$work/synth-j1/log"))" >&2
fi

for p in tile tile-remesh hpm polycube lapped; do
    declare -A cpu1=()
    for s in $scales; do
        mesh=$work/horse_x$s.obj
        faces=$(grep -c '^f' "$mesh")
        name=scale_${p}_$((faces / 1000))k
        runs=1
        [ "$s" = 1 ] && runs=$small_runs
        measure "$tool" "$timeout" "$work/$p-x$s-j1" 1 "$p" "$mesh" "$runs"
        if [ "$status" != 0 ]; then
            echo "bench_scale: $p on $faces faces at -j 1: status $status ($(tail -n 1 "$work/$p-x$s-j1/log"))" >&2
            figure "${name}_finished" 0 bool
            continue
        fi
        cpu1[$s]=$cpu
        wall1=$wall
        bake1=$bake
        figure "${name}_cpu_j1" "$cpu" s
        figure "${name}_wall_j1" "$wall" s
        figure "${name}_peak_j1" "$(mib "$peak")" MiB
        measure "$tool" "$timeout" "$work/$p-x$s-j2" 2 "$p" "$mesh" "$runs"
        if [ "$status" = 0 ]; then
            same=1
            for f in "$work/$p-x$s-j1"/out*; do
                cmp -s "$f" "$work/$p-x$s-j2/$(basename "$f")" || same=0
            done
            figure "${name}_wall_j2" "$wall" s
            figure "${name}_wall_j2_over_j1" "$(ratio "$wall" "$wall1")" x
            if [ -n "$bake1" ] && [ -n "$bake" ]; then
                figure "${name}_bake_wall_j1" "$bake1" s
                figure "${name}_bake_wall_j2" "$bake" s
                figure "${name}_bake_wall_j2_over_j1" "$(ratio "$bake" "$bake1")" x
            fi
            figure "${name}_identical_j2" "$same" bool
        else
            echo "bench_scale: $p on $faces faces at -j 2: status $status" >&2
        fi
        if [ -n "$old" ] && [ "$p" != tile-remesh ]; then    # v0.3.0 had no --remesh
            measure "$old" "$old_timeout" "$work/$p-x$s-v030" "" "$p" "$mesh"
            if [ "$status" = 0 ]; then
                figure "${name}_v030_cpu" "$cpu" s
                figure "${name}_v030_peak" "$(mib "$peak")" MiB
                figure "${name}_cpu_over_v030" "$(ratio "${cpu1[$s]}" "$cpu")" x
            else
                echo "bench_scale: v0.3.0's $p on $faces faces: status $status (not finished in ${old_timeout} s)" >&2
            fi
        fi
        rm -rf "$work/$p-x$s-j2" "$work/$p-x$s-v030"
        [ "$s" = 1 ] && measure_cancel "$p" "$mesh" "$wall1" "$name"
    done
    for s in 4 16; do
        if [ -n "${cpu1[1]:-}" ] && [ -n "${cpu1[$s]:-}" ]; then
            figure "scale_${p}_cpu_growth_${s}x" "$(ratio "${cpu1[$s]}" "${cpu1[1]}")" x
        fi
    done
    unset cpu1
done
