#!/bin/sh
# run_fuzz.sh — runs one libFuzzer harness for ctest (fuzz/CMakeLists.txt): ARTIFACTS is
# a folder for what it finds; the rest is the harness and its arguments. When the run
# fails, every input it wrote is printed in Base64 (the end of a CI log is all one may
# have of a run on another machine): `base64 -d > input` and replay it with the harness.
set -u
artifacts=$1
shift
rm -rf "$artifacts"
mkdir -p "$artifacts"
"$@" -artifact_prefix="$artifacts/"
rc=$?
if [ "$rc" -ne 0 ]; then
  for f in "$artifacts"/*; do
    [ -f "$f" ] || continue
    echo "valo: the input that failed: $(basename "$f"), $(wc -c < "$f") bytes, in Base64:"
    head -c 65536 "$f" | base64 -w 0
    echo
  done
fi
exit "$rc"
