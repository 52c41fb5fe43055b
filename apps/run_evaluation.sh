#!/usr/bin/env bash
# Regenerate the tables of docs/evaluation.md: simulate the paper's three scenes at two
# density / noise levels, with the stereo-like sensor and with a depth camera's regular
# grid, then compare every method on them and on the mOSD frames.
#
# Usage: apps/run_evaluation.sh BUILD_DIR [SHARED_DATA_DIR] [OUT_DIR]
set -euo pipefail
build=${1:?usage: $0 BUILD_DIR [SHARED_DATA_DIR] [OUT_DIR]}
shared=${2:-$(dirname "$0")/../../shared/data}
out=${3:-evaluation}
mkdir -p "$out"
sim="$build/apps/pcl_selective_seg_simulate"
# Level A: the paper's point counts, low noise (sigma = 0.0005 r^2).
# Level B: three times denser, four times the noise (sigma = 0.002 r^2: 5 mm at 1.6 m).
for scene in cube chair door; do
  "$sim" -scene "$scene" -density 1 -noise 0.0005 -density_ratio 10 -seed 42 \
    -o "$out/${scene}_A.pcd" > /dev/null
  "$sim" -scene "$scene" -density 3 -noise 0.002 -density_ratio 10 -seed 42 \
    -o "$out/${scene}_B.pcd" > /dev/null
  # The same levels seen by a depth camera: rays on a regular grid (straight rows and
  # columns in theta and phi, as a pinhole camera's pixels), uniform density, 1% dropouts.
  "$sim" -scene "$scene" -density 1 -noise 0.0005 -density_ratio 1 -jitter 0 \
    -dropout 0.01 -seed 42 -o "$out/${scene}_A_grid.pcd" > /dev/null
  "$sim" -scene "$scene" -density 3 -noise 0.002 -density_ratio 1 -jitter 0 \
    -dropout 0.01 -seed 42 -o "$out/${scene}_B_grid.pcd" > /dev/null
done
clouds=("$out"/*_A.pcd "$out"/*_B.pcd "$out"/*_A_grid.pcd "$out"/*_B_grid.pcd)
for frame in learn0 learn17 test0; do
  [ -f "$shared/mosd/$frame.pcd" ] && clouds+=("$shared/mosd/$frame.pcd")
done
"$build/apps/pcl_selective_seg_compare" "${clouds[@]}" -o "$out/table.md"
echo "wrote $out/table.md"
