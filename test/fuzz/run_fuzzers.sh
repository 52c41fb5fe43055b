#!/usr/bin/env bash
# Fuzz every target of a -DSELSEG_FUZZ=ON build for a bounded time, both at once (one
# per core), starting from the seed corpus and the regression inputs.
#   bash test/fuzz/run_fuzzers.sh BUILD_DIR [SECONDS_PER_TARGET=120]
# SELSEG_FUZZ_SEED (default 1) fixes libFuzzer's random seed, so a run explores the
# same inputs in the same order on every machine (a time limit only cuts it shorter):
# CI then fails only when a change opens a path, not by the luck of the draw. Set
# SELSEG_FUZZ_SEED=0 for a fresh random seed (long runs, hunting).
# New interesting inputs go to BUILD_DIR/fuzz/corpus/TARGET (not into the sources). A
# crash, leak, timeout or out-of-memory stops that target, leaves the input in
# BUILD_DIR/fuzz/ as TARGET-crash-..., and fails this script: fix the bug, then copy
# the input into test/fuzz/regressions/TARGET/ so that it is replayed by ctest forever.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
build=${1:?usage: run_fuzzers.sh BUILD_DIR [SECONDS]}
seconds=${2:-120}
seed=${SELSEG_FUZZ_SEED:-1}
# With the fixed seed, each target also stops after the inputs a 120 s run explored on
# the development machine, so a faster machine does not run past what was checked.
declare -A max_runs=([fuzz_segmentation]=14000 [fuzz_scan_io]=1200000)
if [ "$seconds" -le 0 ]; then echo "fuzz: skipped (0 s)"; exit 0; fi
out="$build/fuzz"
mkdir -p "$out"
export ASAN_OPTIONS="${ASAN_OPTIONS:-halt_on_error=1:abort_on_error=1:detect_leaks=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}"
export LSAN_OPTIONS="${LSAN_OPTIONS:-suppressions=$here/../../.ci/lsan.supp}"

pids=()
targets=(fuzz_segmentation fuzz_scan_io)
for t in "${targets[@]}"; do
  exe="$build/test/fuzz/$t"
  if [ ! -x "$exe" ]; then
    echo "fuzz: $exe not built (configure with -DSELSEG_FUZZ=ON and clang)" >&2
    exit 1
  fi
  mkdir -p "$out/corpus/$t"
  inputs=("$out/corpus/$t" "$here/corpus/$t")
  [ -d "$here/regressions/$t" ] && inputs+=("$here/regressions/$t")
  # 8 KB inputs: hundreds of points or a small file; 10 s per input is a hang;
  # 2 GB of memory for a few KB of input is a blow-up.
  runs=-1
  [ "$seed" != 0 ] && runs=${max_runs[$t]}
  "$exe" -seed="$seed" -runs="$runs" -max_total_time="$seconds" -max_len=8192 -timeout=10 -rss_limit_mb=2048 \
    -print_final_stats=1 -artifact_prefix="$out/$t-" "${inputs[@]}" \
    > "$out/$t.log" 2>&1 &
  pids+=($!)
done
status=0
for i in "${!targets[@]}"; do
  t=${targets[$i]}
  if wait "${pids[$i]}"; then
    runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$out/$t.log" | grep -o '[0-9]*$' || echo "?")
    echo "fuzz: $t: no finding in ${seconds} s, $runs inputs executed"
  else
    status=1
    echo "fuzz: $t FAILED; the end of its log ($out/$t.log):" >&2
    tail -n 60 "$out/$t.log" >&2
    ls "$out"/"$t"-* >&2 2>/dev/null || true
  fi
done
exit $status
