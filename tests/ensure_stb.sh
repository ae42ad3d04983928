#!/usr/bin/env bash
# Make sure stb_image / stb_image_write (Debian: libstb-dev) are installed.
# Installs them when running as root with apt-get; otherwise prints the command.
set -u
for dir in $(pkg-config --cflags-only-I stb 2>/dev/null | sed 's/-I//g') /usr/include/stb /usr/local/include/stb; do
  if [ -f "$dir/stb_image.h" ] && [ -f "$dir/stb_image_write.h" ]; then exit 0; fi
done
if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
  echo "installing libstb-dev (stb_image for the tiledtex tool) ..."
  if apt-get install -y -qq libstb-dev >/dev/null 2>&1 || { apt-get update -qq >/dev/null 2>&1 && apt-get install -y -qq libstb-dev >/dev/null 2>&1; }; then
    exit 0
  fi
fi
echo "stb_image is missing: run  sudo apt-get install libstb-dev  and try again" >&2
exit 1
