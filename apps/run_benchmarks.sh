#!/usr/bin/env bash
# Regenerate docs/performance.md and docs/images/performance_scaling.png: the Google
# Benchmark suite (this pipeline per stage and pcl::NormalEstimation +
# pcl::RegionGrowing on the same clouds), and the peak memory of the command-line tool.
#
# Usage: apps/run_benchmarks.sh BUILD_DIR [SHARED_DATA_DIR]
# Needs python3 (standard library only) and gnuplot for the plot.
set -euo pipefail
build=${1:?usage: $0 BUILD_DIR [SHARED_DATA_DIR]}
shared=${2:-$(dirname "$0")/../../shared/data}
repo=$(cd "$(dirname "$0")/.." && pwd)
# The suite, then the simulator and the tool for the peak memory: all checked before
# the suite (minutes), not after it.
for exe in test/selseg_benchmark apps/pcl_selective_seg_simulate apps/pcl_selective_seg; do
  if [ ! -x "$build/$exe" ]; then
    echo "$0: no $build/$exe: give the build folder of a built checkout" >&2
    exit 2
  fi
done
# The report needs python3 and gnuplot, checked likewise.
for tool in python3 gnuplot; do
  if ! command -v "$tool" > /dev/null; then
    echo "$0: $tool not found: install it (apt-get install ${tool/gnuplot/gnuplot-nox})" >&2
    exit 2
  fi
done
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# Spell probe: the 46k pipeline alone on one thread, then on two, just before and just
# after the suite. On a virtual machine the two vCPUs sometimes get one core's
# throughput between them (a slow spell), and then two threads are hardly faster than
# one: the report says which spell the run began and ended in.
probe() {
  local threads
  for threads in 1 2; do
    OMP_NUM_THREADS=$threads "$build/test/selseg_benchmark" \
      --benchmark_filter='^BM_Pipeline_Door/46255/' \
      --benchmark_out="$work/probe_$1_$threads.json" --benchmark_out_format=json > /dev/null
  done
}

load_before=$(cut -d' ' -f1-3 /proc/loadavg)
probe before
SELSEG_DATA="$shared" "$build/test/selseg_benchmark" \
  --benchmark_enable_random_interleaving=true \
  --benchmark_out="$work/benchmark.json" --benchmark_out_format=json
load_after=$(cut -d' ' -f1-3 /proc/loadavg)
probe after
# SELSEG_BENCHMARK_JSON=FILE keeps a copy of the raw results.
if [ -n "${SELSEG_BENCHMARK_JSON:-}" ]; then cp "$work/benchmark.json" "$SELSEG_BENCHMARK_JSON"; fi

# Peak memory of the command-line tool on the same simulated door scans.
for n in 10000 46255 300000 1000000 3000000; do
  density=$(python3 -c "print($n / 46140)")
  "$build/apps/pcl_selective_seg_simulate" -scene door -density "$density" \
    -density_ratio 10 -o "$work/door_$n.pcd" > /dev/null
done
python3 "$repo/apps/perf_report.py" --benchmark "$work/benchmark.json" \
  --tool "$build/apps/pcl_selective_seg" --scans "$work" \
  --markdown "$repo/docs/performance.md" --plot "$repo/docs/images/performance_scaling.png" \
  --load "$load_before" "$load_after" \
  --probe "$work/probe_before_1.json" "$work/probe_before_2.json" \
  "$work/probe_after_1.json" "$work/probe_after_2.json"
