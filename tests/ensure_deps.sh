#!/usr/bin/env bash
# Make sure what `make demo` or `make test` needs is installed: a C and a C++
# compiler, and stb_image (Debian: libstb-dev) for the tool; for the tests also
# clang and tcc, the other compilers the header must build with.
#   bash tests/ensure_deps.sh demo|test
# As root with apt-get, installs what is missing; otherwise prints the one
# command to run and fails.
set -u
mode=${1:-test}
need=()
have_stb() {
  local dir
  for dir in $(pkg-config --cflags-only-I stb 2>/dev/null | sed 's/-I//g') /usr/include/stb /usr/local/include/stb; do
    if [ -f "$dir/stb_image.h" ] && [ -f "$dir/stb_image_write.h" ]; then return 0; fi
  done
  return 1
}
command -v cc >/dev/null 2>&1 || need+=(gcc)
command -v make >/dev/null 2>&1 || need+=(make)
have_stb || need+=(libstb-dev)
if [ "$mode" = test ]; then
  command -v g++ >/dev/null 2>&1 || need+=(g++)
  command -v clang >/dev/null 2>&1 || need+=(clang)
  command -v tcc >/dev/null 2>&1 || need+=(tcc)
fi
[ ${#need[@]} -eq 0 ] && exit 0
if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
  echo "installing ${need[*]} (needed by make $mode) ..."
  export DEBIAN_FRONTEND=noninteractive
  if apt-get install -y -qq "${need[@]}" >/dev/null 2>&1 ||
     { apt-get update -qq >/dev/null 2>&1 && apt-get install -y -qq "${need[@]}" >/dev/null 2>&1; }; then
    exit 0
  fi
  echo "could not install ${need[*]}: run  apt-get update && apt-get install ${need[*]}  and try again" >&2
  exit 1
fi
echo "make $mode needs ${need[*]}: run  sudo apt-get install ${need[*]}  and try again" >&2
exit 1
