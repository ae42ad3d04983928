#!/usr/bin/env bash
# bench/bench_tool.sh TOOL - the tool end to end, as a user runs it: `tiledtex
# tile` on a 116,162-triangle torus (241 x 241 quads, each split in two) and
# a procedural 512 x 512 texture, reading and writing files. Prints
# `tool_tile_116k_triangles MS ms`, the median of 5 runs (target: under 1 s).
set -u
tool=${1:-build/tiledtex}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
awk 'BEGIN {
  n = 241; R = 1.0; r = 0.35; pi = 3.14159265358979
  for (j = 0; j < n; j++) for (i = 0; i < n; i++) {
    u = 2 * pi * i / n; v = 2 * pi * j / n
    printf "v %.6f %.6f %.6f\n", (R + r * cos(v)) * cos(u), r * sin(v), (R + r * cos(v)) * sin(u)
  }
  for (j = 0; j < n; j++) for (i = 0; i < n; i++) {
    a = j * n + i + 1; b = j * n + (i + 1) % n + 1
    c = ((j + 1) % n) * n + (i + 1) % n + 1; d = ((j + 1) % n) * n + i + 1
    printf "f %d %d %d\nf %d %d %d\n", a, d, c, a, c, b
  }
}' >"$dir/torus.obj"
"$tool" generate texture "$dir/stone.png" >/dev/null || { echo "bench_tool: generate texture failed" >&2; exit 1; }
times=()
for run in 1 2 3 4 5; do
  start=$(date +%s%N)
  "$tool" tile "$dir/torus.obj" "$dir/stone.png" "$dir/out$run" >/dev/null 2>"$dir/err" ||
    { echo "bench_tool: tiledtex tile failed: $(cat "$dir/err")" >&2; exit 1; }
  times+=($(( ($(date +%s%N) - start) / 1000000 )))
done
median=$(printf '%s\n' "${times[@]}" | sort -n | sed -n 3p)
echo "tool_tile_116k_triangles $median ms"
echo "bench_tool: runs ${times[*]} ms" >&2
