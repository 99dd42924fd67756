#!/usr/bin/env bash
# Every Khronos sample model in $PHANTOGRAM_DATA/models/khronos written as a .usdz by Pixar's
# library (glb_to_usdz.py) and rendered beside its glTF (frame 1 of the tilt sweep, mono); prints
# each frame's RMSE, usdz against glTF (ImageMagick's `compare`, 16-bit: "abs (share)").
# Needs the converter's throwaway environment as $PY (see glb_to_usdz.py) and a release build of
# the CLI. Usage: PY=/tmp/v/bin/python benchmarks/usd/khronos_as_usdz.sh [OUT_DIR]
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
out=${1:-/tmp/khronos-usd}
data=${PHANTOGRAM_DATA:?set PHANTOGRAM_DATA}/models/khronos
cli="$root/target/release/phantogram"
mkdir -p "$out"
for dir in "$data"/*/; do
  m=$(basename "$dir")
  src=$(ls "$dir"glTF-Binary/*.glb 2>/dev/null | head -1 || true)
  [ -z "$src" ] && src=$(ls "$dir"glTF/*.gltf 2>/dev/null | head -1 || true)
  [ -z "$src" ] && continue
  "${PY:?set PY}" "$root/benchmarks/usd/glb_to_usdz.py" "$src" "$out/$m.usdz" > /dev/null 2>&1
  for kind in gltf usdz; do
    file=$src; [ $kind = usdz ] && file="$out/$m.usdz"
    "$cli" render --log "$root/assets/logs/tilt-sweep.pglog" --out "$out/r_${kind}_$m" "$file" \
      --every 6000 --anaglyph mono > /dev/null 2>&1
  done
  echo "$m $(compare -metric RMSE "$out/r_gltf_$m/frame_00001.png" "$out/r_usdz_$m/frame_00001.png" null: 2>&1 || true)"
done
