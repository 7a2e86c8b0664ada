#!/usr/bin/env bash
# The documented GNU parallel lines (docs/compare.md), with one part killed
# in the middle and the same lines run again: merged tables = one unsharded run.
# Usage: parallel_sweep.sh OFV SOURCE_DIR
OFV=$1 SOURCE_DIR=$2
source "$SOURCE_DIR/test/cluster/common.sh"
trap '[ -n "${KEEP:-}" ] || rm -rf "$work"' EXIT
command -v parallel >/dev/null || { echo "GNU parallel not found: scripts/install-deps.sh --cluster" >&2; exit 1; }

export out=$work/sweep parts=2 cpus=2
block=$(documented parallel)
[ -n "$block" ] || { echo "docs/compare.md: no tested parallel block" >&2; exit 1; }
echo "$block"
run_parts=${block%%ofv compare --merge*}  # the parallel line, without the merge

# First run: part 2 is killed once its first episode is written.
( cd "$work" && setsid bash -c "$run_parts" > "$work/first.log" 2>&1 ) &
first=$!
for _ in $(seq 600); do
  compgen -G "$out/part2/episodes/*.json" >/dev/null && break
  sleep 0.05
done
pkill -KILL -f -- "--shard 2/$parts" || { echo "part 2 was not running" >&2; exit 1; }
if wait "$first"; then echo "the first run was not interrupted" >&2; exit 1; fi
finished=$(ls "$out/part2/episodes/"*.json | wc -l)
[ "$finished" -ge 1 ] && [ "$finished" -lt 4 ] || { echo "part 2 finished $finished of 4 episodes" >&2; exit 1; }

# The same lines again: part 2 resumes, the merge has every episode.
( cd "$work" && eval "$block" ) | tee "$work/second.log"
grep -q "(0 run, 4 resumed)" "$work/second.log"                      # part 1 was complete
grep -q "($((4 - finished)) run, $finished resumed)" "$work/second.log"  # part 2 resumed
reference
same_tables "$out"
