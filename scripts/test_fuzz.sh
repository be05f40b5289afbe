#!/usr/bin/env bash
# The libFuzzer targets of fuzz/ (one per input reader, fuzz/README.md) built with clang into
# build-fuzz and each run for a fixed budget from its corpus, with a fixed seed: any crash, sanitizer
# report (ASan + UBSan), uncaught exception, hang (> 10 s on one input) or out-of-memory fails the
# script, and the input that did it is kept in build-fuzz/findings/. New inputs the runs find go to a
# scratch folder; the corpus in the source tree is not touched.
# Usage: scripts/test_fuzz.sh [seconds per target (default 20)]   env: FUZZ_SEED (default 1), JOBS (2: targets
# built and run two at a time)
set -euo pipefail
cd "$(dirname "$0")/.."

SECONDS_EACH="${1:-${FUZZ_SECONDS:-20}}"
SEED="${FUZZ_SEED:-1}"
JOBS="${JOBS:-2}"
TARGETS="fuzz_csv fuzz_model_yaml fuzz_scenario_yaml fuzz_candump fuzz_column_map fuzz_opensim_storage fuzz_controller_yaml fuzz_mcap"
command -v clang++ >/dev/null || { echo "test_fuzz: clang++ not found (scripts/setup.sh installs clang and libclang-rt-14-dev)"; exit 1; }

start=$(date +%s)
cmake -S . -B build-fuzz -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ -DEXOTWIN_FUZZ=ON \
      -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" >/dev/null
cmake --build build-fuzz -j"$JOBS" --target exotwin_fuzz_targets
built=$(date +%s)
echo "test_fuzz: targets built in $(( built - start )) s"

# intercept_tls_get_addr=0: LeakSanitizer's tracer fault at exit of LLVM <= 16 (scripts/test_sanitizers.sh).
export ASAN_OPTIONS="${ASAN_OPTIONS:-halt_on_error=1:detect_leaks=1:abort_on_error=0:intercept_tls_get_addr=0}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}"
findings=build-fuzz/findings
scratch=$(mktemp -d "${TMPDIR:-/tmp}/exotwin_fuzz_XXXXXX")
trap 'rm -rf "$scratch"' EXIT
mkdir -p "$findings"
# The targets run JOBS at a time (each libFuzzer run is one process on one core, for its own fixed
# budget); their reports are printed in TARGETS' order.
run_target() {
  local t=$1
  mkdir -p "$scratch/$t"
  # -timeout: one input longer than 10 s is a hang; -rss_limit_mb: more than 2 GB an out-of-memory.
  if build-fuzz/fuzz/$t -seed="$SEED" -max_total_time="$SECONDS_EACH" -timeout=10 -rss_limit_mb=2048 \
       -print_final_stats=1 -artifact_prefix="$findings/$t-" "$scratch/$t" "fuzz/corpus/$t" \
       >"$scratch/$t.log" 2>&1; then
    echo 0 > "$scratch/$t.rc"
  else
    echo 1 > "$scratch/$t.rc"
  fi
}
running=0
for t in $TARGETS; do
  if [ "$running" -ge "$JOBS" ]; then wait -n; running=$((running - 1)); fi
  run_target "$t" &
  running=$((running + 1))
done
wait
failed=""
for t in $TARGETS; do
  if [ "$(cat "$scratch/$t.rc")" = 0 ]; then
    echo "test_fuzz: $t: $(grep -o 'stat::number_of_executed_units: *[0-9]*' "$scratch/$t.log" | grep -o '[0-9]*$') inputs" \
         "in ${SECONDS_EACH} s, $(grep -o 'cov: [0-9]*' "$scratch/$t.log" | tail -1), no finding"
  else
    echo "test_fuzz: $t: FAILED (its input is in $findings/):"
    grep -E -A30 'ERROR: |==[0-9]+==|terminate called|Uncaught|what\(\)' "$scratch/$t.log" | head -60
    failed="$failed $t"
  fi
done
echo "test_fuzz: took $(( $(date +%s) - start )) s ($(( $(date +%s) - built )) s fuzzing)"
[ -z "$failed" ] || { echo "test_fuzz: findings in:$failed"; exit 1; }
