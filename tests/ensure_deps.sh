#!/usr/bin/env bash
# Make sure what `make demo` or `make test` needs is installed: a C and a C++
# compiler, and stb_image (Debian: libstb-dev) for the tool; for the tests also
# clang and tcc, the other compilers the header must build with, and the
# Khronos glTF validator (npm's gltf-validator, run by node) for the GLB files.
#   bash tests/ensure_deps.sh demo|test
# As root with apt-get, installs what is missing; otherwise prints the one
# command to run and fails. The validator is optional: without it the
# end-to-end tests say that they skipped it, so failing to install it only
# prints why.
set -u
mode=${1:-test}

# node and npm from Debian, then gltf-validator into the build tree, where
# tests/gltf_validate.js looks for it.
validator_dir="$(cd "$(dirname "$0")/.." && pwd)/build/gltf-validator"
ensure_validator() {
  if command -v node >/dev/null 2>&1 && [ -f "$validator_dir/node_modules/gltf-validator/package.json" ]; then
    return 0
  fi
  local install="npm install --prefix build/gltf-validator gltf-validator"
  if [ "$(id -u)" != 0 ] || ! command -v apt-get >/dev/null 2>&1; then
    echo "the GLB checks of make test need the glTF validator: run  sudo apt-get install nodejs npm && $install" >&2
    return 0
  fi
  if ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; then
    echo "installing nodejs npm (the glTF validator's runtime, for make test) ..."
    export DEBIAN_FRONTEND=noninteractive
    apt-get install -y -qq nodejs npm >/dev/null 2>&1 ||
      { apt-get update -qq >/dev/null 2>&1 && apt-get install -y -qq nodejs npm >/dev/null 2>&1; } ||
      { echo "could not install nodejs npm: the GLB files will not be validated" >&2; return 0; }
  fi
  echo "installing gltf-validator into build/gltf-validator (for make test) ..."
  npm install --prefix "$validator_dir" --no-audit --no-fund gltf-validator >/dev/null 2>&1 ||
    echo "could not install gltf-validator ($install): the GLB files will not be validated" >&2
  return 0
}
[ "$mode" = test ] && ensure_validator
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
