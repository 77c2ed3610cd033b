#!/usr/bin/env bash
# Installs the Debian packages valo builds against, only when something is missing.
# --optional adds what the optional parts and their tests need: clang 14 and libFuzzer
# (the fuzz harnesses), OpenMPI (the many-machines build and its tests) and Chromium
# (the compare report's page test), SDL2 with Xvfb and xdotool (the viewer and its test).
set -euo pipefail
pkgs=(build-essential cmake pkg-config libassimp-dev libstb-dev libopenexr-dev libcjson-dev libembree-dev)
for a in "$@"; do [ "$a" = "--optional" ] && pkgs+=(clang-14 libfuzzer-14-dev libopenmpi-dev openmpi-bin chromium libsdl2-dev xvfb xdotool); done
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then exit 0; fi
echo "valo: installing ${missing[*]}" >&2
SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
