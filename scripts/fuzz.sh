#!/usr/bin/env bash
# Builds the libFuzzer targets of fuzz/ with Debian's clang (ASan + UBSan) in
# build-fuzz/ and runs each on its seeds (fuzz/corpus/<target>/).
#
#   scripts/fuzz.sh [SECONDS]        every target for SECONDS (default 60)
#   scripts/fuzz.sh -runs=N          every target for N executions
#   scripts/fuzz.sh ... TARGET...    only these targets (e.g. fuzz_oni)
#
# Prints per target the executions, the time and whether anything was found;
# a crash, leak, timeout or out-of-memory input is saved to
# build-fuzz/findings/<target>/ (replay: build-fuzz/bin/<target> FILE) and
# the script exits 1. New inputs the fuzzer finds go to
# build-fuzz/corpus/<target>/ (the seeds in the repository are left as they
# are). OFV_FUZZ_BUILD_DIR picks another build folder, OFV_JOBS the build's
# parallel jobs (default 2); OFV_FUZZ_PARALLEL runs that many targets at once
# (default 1).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD

limit="-max_total_time=60"
targets=()
for arg in "$@"; do
  case "$arg" in
    -runs=*) limit="$arg" ;;
    ''|*[!0-9]*) targets+=("$arg") ;;
    *) limit="-max_total_time=$arg" ;;
  esac
done
all_targets=(fuzz_scene_json fuzz_scenario_yaml fuzz_grid_yaml fuzz_tum_files fuzz_pcd_header fuzz_oni)
[ ${#targets[@]} -gt 0 ] || targets=("${all_targets[@]}")

build=${OFV_FUZZ_BUILD_DIR:-build-fuzz}
case "$build" in /*) ;; *) build="$root/$build" ;; esac
command -v clang++ >/dev/null || { echo "fuzz.sh: clang++ not found (scripts/install-deps.sh installs it)" >&2; exit 2; }
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
build_start=$SECONDS
for t in "${targets[@]}"; do
  [ -d "fuzz/corpus/$t" ] || { echo "fuzz.sh: unknown target $t (expected: ${all_targets[*]})" >&2; exit 2; }
done
mkdir -p "$build"
if ! { cmake -S . -B "$build" -DOFV_FUZZ=ON -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
         -DBUILD_SHARED_LIBS=OFF -DOFV_BUILD_TESTS=OFF -DOFV_BUILD_BENCH=OFF "${launcher[@]}" &&
       cmake --build "$build" -j "${OFV_JOBS:-2}" --target "${targets[@]}"; } >"$build/build.log" 2>&1; then
  tail -n 30 "$build/build.log" >&2
  echo "fuzz.sh: the fuzz build failed (log: $build/build.log)" >&2
  exit 2
fi
echo "fuzz build: $((SECONDS - build_start)) s"

# One target: its own corpus copy (seeds + what earlier runs found), its
# findings folder, its log; a summary line at the end.
run_target() {
  local t=$1
  local corpus="$build/corpus/$t" findings="$build/findings/$t" log="$build/logs/$t.log"
  mkdir -p "$corpus" "$findings" "$(dirname "$log")"
  cp -n "$root/fuzz/corpus/$t"/* "$corpus"/ 2>/dev/null || true
  local start=$SECONDS status=0 before
  before=$(find "$findings" -type f | wc -l)  # findings of earlier runs stay, and do not count
  # -timeout: one input taking 10 s is a hang; -rss_limit_mb: 2 GB is a finding.
  # ASan's leak check runs after each input that allocated more than it freed.
  # Run in the findings folder: files a scenario names are looked up there (none exist).
  (cd "$findings" && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
     "$build/bin/$t" "$limit" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
     -artifact_prefix="$findings/" "$corpus" >"$log" 2>&1) || status=$?
  local runs found
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  found=$(( $(find "$findings" -type f | wc -l) - before ))
  if [ "$status" -eq 0 ] && [ "$found" -eq 0 ]; then
    printf '%-20s %10s executions %5d s  nothing found\n' "$t" "${runs:-?}" $((SECONDS - start))
  else
    printf '%-20s %10s executions %5d s  FOUND (exit %d): %s (log %s)\n' "$t" "${runs:-?}" $((SECONDS - start)) \
      "$status" "$(ls -t "$findings" | head -n "$found" | tr '\n' ' ')" "$log"
    return 1
  fi
}

failed=0
parallel=${OFV_FUZZ_PARALLEL:-1}
pids=()
for t in "${targets[@]}"; do
  run_target "$t" &
  pids+=($!)
  if [ ${#pids[@]} -ge "$parallel" ]; then
    wait "${pids[0]}" || failed=1
    pids=("${pids[@]:1}")
  fi
done
for p in "${pids[@]}"; do wait "$p" || failed=1; done
exit $failed
