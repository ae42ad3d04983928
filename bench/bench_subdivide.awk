# bench/bench_subdivide.awk - cut every triangle of an OBJ 1-to-4 at its edge
# midpoints (one new vertex per edge, shared by the faces on both sides), as
# a scanner at twice the density would give the same shape: the mesh the
# scale figures grow by 4x. Reads `v` and triangle `f` lines (v, v/vt,
# v/vt/vn and v//vn indices; negative indices are relative); writes `v` and
# `f` lines only.
#   awk -f bench/bench_subdivide.awk IN.obj > OUT.obj
function idx(token, n) {
    sub(/\/.*/, "", token)
    n = token + 0
    return n < 0 ? nv + n + 1 : n
}
function mid(a, b,   key) {
    key = a < b ? a " " b : b " " a
    if (!(key in midpoint)) {
        nv++
        x[nv] = (x[a] + x[b]) / 2; y[nv] = (y[a] + y[b]) / 2; z[nv] = (z[a] + z[b]) / 2
        midpoint[key] = nv
    }
    return midpoint[key]
}
$1 == "v" { nv++; x[nv] = $2; y[nv] = $3; z[nv] = $4; norig = nv; next }
$1 == "f" {
    if (NF != 4) { print "bench_subdivide: line " NR " is not a triangle" > "/dev/stderr"; failed = 1; exit 1 }
    nf++; fa[nf] = idx($2); fb[nf] = idx($3); fc[nf] = idx($4)
}
END {
    if (failed) exit 1
    for (f = 1; f <= nf; f++) {
        ab[f] = mid(fa[f], fb[f]); bc[f] = mid(fb[f], fc[f]); ca[f] = mid(fc[f], fa[f])
    }
    for (i = 1; i <= nv; i++) printf "v %.9g %.9g %.9g\n", x[i], y[i], z[i]
    for (f = 1; f <= nf; f++) {
        printf "f %d %d %d\nf %d %d %d\n", fa[f], ab[f], ca[f], ab[f], fb[f], bc[f]
        printf "f %d %d %d\nf %d %d %d\n", ca[f], bc[f], fc[f], ab[f], bc[f], ca[f]
    }
}
