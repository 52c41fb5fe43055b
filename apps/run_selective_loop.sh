#!/usr/bin/env bash
# Regenerate the table, plots and pictures of docs/selective_sensing.md: the simulated
# coarse-to-fine loop against uniform scans of the paper's three scenes.
#
# Usage: apps/run_selective_loop.sh BUILD_DIR [OUT_DIR] [IMAGES_DIR]
#   OUT_DIR     table.md, <scene>.dat, clouds and windows (default: selective)
#   IMAGES_DIR  the PNGs (default: docs/images beside this script); needs gnuplot,
#               and xvfb-run for the viewer's pictures (skipped without it)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
build=${1:?usage: $0 BUILD_DIR [OUT_DIR] [IMAGES_DIR]}
out=${2:-selective}
images=${3:-$here/../docs/images}
loop_tool="$build/apps/pcl_selective_seg_selective_loop"
if [ ! -x "$loop_tool" ]; then
  echo "$0: no $loop_tool: give the build folder of a built checkout" >&2
  exit 2
fi
# The plots need gnuplot: checked before the 32 loop runs (minutes), not after them.
if ! command -v gnuplot > /dev/null; then
  echo "$0: gnuplot not found: install it (apt-get install gnuplot-nox)" >&2
  exit 2
fi
mkdir -p "$out" "$images"

"$loop_tool" -out "$out" | tee "$out/log.txt"

# One run is one draw of the sensor's random streams (rays, dropouts, noise, texture):
# the same on 31 other seeds, summarized in OUT/seeds.md (final round against the
# finest uniform scan, per scene and seed, and the mean ratio). 32 draws: the mean of
# eight has a standard error of up to 0.1 (docs/selective_sensing.md).
seeds="$(seq -s " " 1 31)"
for seed in $seeds; do
  mkdir -p "$out/seed_$seed"
  "$loop_tool" -out "$out/seed_$seed" -seed "$seed" \
    > "$out/seed_$seed/log.txt"
done
{
  echo "| scene | seed | finest uniform: points, accuracy (mm) | selective: points, accuracy (mm) | ratio |"
  echo "|---|---|---|---|---|"
  for scene in cube chair door; do
    dirs=("$out")
    for seed in $seeds; do dirs+=("$out/seed_$seed"); done
    for dir in "${dirs[@]}"; do
      seed=42
      [ "$dir" = "$out" ] || seed=${dir##*seed_}
      awk -F'|' -v scene="$scene" -v seed="$seed" '
        $2 == " " scene " " && $3 ~ /uniform/ {dp = $4 + 0; da = $7 + 0}
        $2 == " " scene " " && $3 ~ /selective/ {sp = $4 + 0; sa = $7 + 0; sf = $5; gsub(/ /, "", sf)}
        END {printf "| %s | %s | %d, %.2f | %d (%s), %.2f | %.2f |\n", scene, seed, dp, da, sp, sf, sa, sa / da}
      ' "$dir/table.md"
    done
  done
  echo
} > "$out/seeds.md"
awk -F'|' 'NR > 2 && NF > 3 {gsub(/ /, "", $2); n[$2]++; r[$2] += $6} END {for (s in n) printf "mean ratio, %s: %.2f over %d seeds\n", s, r[s] / n[s], n[s]}' \
  "$out/seeds.md" | sort >> "$out/seeds.md"
cat "$out/seeds.md"

# Where the gap is, by the kind of true edge (the last columns of
# <scene>_boundary_errors.dat: depth jump, crease angle, inside a scanned window),
# pooled over the 32 draws: OUT/kinds.md.
{
  echo "| scene | true edge | points (share) | inside a window | finest uniform (mm) | selective (mm) | ratio | share of the gap |"
  echo "|---|---|---|---|---|---|---|---|"
  for scene in cube chair door; do
    cat "$out/${scene}_boundary_errors.dat" "$out"/seed_*/"${scene}_boundary_errors.dat" |
      awk -v scene="$scene" '
        !/^#/ && NF >= 7 {
          if ($5 == 1) k = "1 depth jump"
          else if ($6 ~ /nan/) k = "5 undetermined"
          else if ($6 + 0 > 30) k = "2 crease > 30 deg"
          else if ($6 + 0 >= 20) k = "3 crease 20-30 deg"
          else k = "4 crease < 20 deg"
          n[k]++; w[k] += $7; u[k] += $3; s[k] += $4; N++; U += $3; S += $4
        }
        END {
          for (k in n)
            printf "%s|| %s | %s | %d (%.1f%%) | %.0f%% | %.2f | %.2f | %.2f | %s |\n",
              k, scene, substr(k, 3), n[k], 100 * n[k] / N, 100 * w[k] / n[k],
              1000 * u[k] / n[k], 1000 * s[k] / n[k], s[k] / u[k],
              (S > U ? sprintf("%.0f%%", 100 * (s[k] - u[k]) / (S - U)) : "-")
        }' | sort | sed 's/^[^|]*||/|/'
  done
} > "$out/kinds.md"
cat "$out/kinds.md"

# Boundary accuracy against points acquired, one panel per scene.
gnuplot <<GNUPLOT
set terminal pngcairo size 1500,480 font ",11"
set output "$images/selective_accuracy.png"
set multiplot layout 1,3 title "Boundary accuracy (mean distance from a true edge to the nearest segment boundary) against points acquired"
set xlabel "points acquired (thousands)"
set ylabel "boundary accuracy, mean [mm]"
set grid
set key top right
do for [scene in "cube chair door"] {
  file = "$out/".scene.".dat"
  dense_points = system("awk '!/^#/ && NF {p=\$1} /^# selective/ {exit} END {print p}' \"".file."\"")
  dense_acc = system("awk '!/^#/ && NF {a=\$3} /^# selective/ {exit} END {print a*1000}' \"".file."\"")
  set title scene
  set arrow 1 from dense_points*0.3/1000, graph 0 to dense_points*0.3/1000, graph 1 nohead dt 2 lc rgb "gray40"
  set arrow 2 from graph 0, first dense_acc*1.1 to graph 1, first dense_acc*1.1 nohead dt 3 lc rgb "gray40"
  plot file index 0 using (\$1/1000):(\$3*1000) with linespoints pt 7 lc rgb "#1f77b4" title "uniform scans", \
       file index 1 using (\$1/1000):(\$3*1000) with linespoints pt 5 lc rgb "#d62728" title "selective: coarse, then rounds", \
       NaN with lines dt 2 lc rgb "gray40" title "30% of the finest scan's points", \
       NaN with lines dt 3 lc rgb "gray40" title "1.1 x its accuracy (the target)"
}
unset multiplot
GNUPLOT

# Where the error is on the cube: each true edge point coloured by its distance.
gnuplot <<GNUPLOT
set terminal pngcairo size 1200,560 font ",11"
set output "$images/selective_cube_errors.png"
set multiplot layout 1,2 title "cube: distance from each ground-truth boundary point to the nearest segment boundary [mm] (sensor angles)"
set yrange [*:*] reverse
set cbrange [0:30]
set palette rgb 33,13,10
set xlabel "theta [rad]"
set ylabel "phi [rad]"
set size ratio -1
set title "uniform scan at the fine step (100% of its points)"
plot "$out/cube_boundary_errors.dat" using 1:2:(\$3*1000) with points pt 7 ps 0.4 palette notitle
set title "selective loop (coarse scan + 3 rounds)"
plot "$out/cube_boundary_errors.dat" using 1:2:(\$4*1000) with points pt 7 ps 0.4 palette notitle
unset multiplot
GNUPLOT

# The viewer's pictures: coarse result, the windows chosen on it, the refined result;
# for the cube also every window scanned and the uniform scan at the fine step.
if command -v xvfb-run > /dev/null; then
  viewer="$build/apps/pcl_selective_seg_viewer"
  shot() {
    xvfb-run -a -s "-screen 0 1280x1024x24 -noreset" "$viewer" "$@" -size 640x480 -no_legend \
      > /dev/null
  }
  for scene in cube chair door; do
    voxel=$(cat "$out/${scene}_min_voxel.txt")
    shot "$out/${scene}_coarse.pcd" -min_voxel_m "$voxel" -view mesh \
      -screenshot "$images/selective_${scene}_coarse.png"
    shot "$out/${scene}_coarse.pcd" -min_voxel_m "$voxel" \
      -roi_json "$out/${scene}_coarse_rois.json" \
      -screenshot "$images/selective_${scene}_windows.png"
    shot "$out/${scene}_refined.pcd" -min_voxel_m "$voxel" -view mesh \
      -screenshot "$images/selective_${scene}_refined.png"
  done
  shot "$out/cube_refined.pcd" -min_voxel_m "$(cat "$out/cube_min_voxel.txt")" \
    -roi_json "$out/cube_windows.json" -screenshot "$images/selective_cube_all_windows.png"
  shot "$out/cube_dense.pcd" -screenshot "$images/selective_cube_dense.png"
else
  echo "xvfb-run not found: the viewer's pictures are not made" >&2
fi
echo "wrote $out/table.md and the pictures in $images"
