#!/usr/bin/env bash
# Episodes per minute of one sweep run four ways on this machine: `ofv
# compare` with --jobs 1 and --jobs 2, and as a Slurm job array of 1 and of
# N tasks (one CPU each) on a single-node cluster brought up here
# (scripts/slurm-local.sh; needs root, slurm-wlm and munge). Each way runs
# the same sweep from scratch: 4 scenarios x 2 variants x SEEDS seeds (each
# scenario's own length, 4 to 5 s) with full perception, as `ofv simulate` runs.
#
#   scripts/sweep-throughput.sh [SEEDS [N]]     (defaults: 2 seeds, N = nproc)
set -euo pipefail
cd "$(dirname "$0")/.."
seeds=${1:-2}
tasks=${2:-$(nproc)}
ofv=$PWD/build/bin/ofv
work=$(mktemp -d /tmp/ofv-throughput.XXXXXX)
chmod 755 "$work"
export OFV_SLURM_DIR=$work/cluster
trap 'scripts/slurm-local.sh down >/dev/null 2>&1 || true; rm -rf "$work"' EXIT
cat > "$work/grid.yaml" <<GRID
name: throughput
seeds: $seeds
variants:
  - {name: ofv, set: {}}
  - {name: static, set: {method: static}}
GRID
scenarios=(dvd-static dvd-one-hand cloth-occluder sweep)
episodes=$(( ${#scenarios[@]} * 2 * seeds ))
rate() { awk -v n="$episodes" -v s="$1" 'BEGIN { printf "%.1f", 60 * n / s }'; }
elapsed() { awk -v a="$1" -v b="$(date +%s.%N)" 'BEGIN { print b - a }'; }
report() { printf '%-28s %4d episodes in %6.1f s: %s episodes/min\n' "$1" "$episodes" "$2" "$(rate "$2")"; }

for jobs in 1 2; do
  start=$(date +%s.%N)
  "$ofv" compare --scenarios "${scenarios[@]}" --grid "$work/grid.yaml" --jobs "$jobs" --out "$work/jobs$jobs" >/dev/null
  report "ofv compare --jobs $jobs" "$(elapsed "$start")"
done

scripts/slurm-local.sh up >/dev/null
export SLURM_CONF=$OFV_SLURM_DIR/slurm.conf
sbatch --wait --wrap true -o /dev/null >/dev/null  # the first job of a new cluster waits for its first scheduling pass
for n in 1 "$tasks"; do
  out=$work/slurm$n
  "$ofv" compare --scenarios "${scenarios[@]}" --grid "$work/grid.yaml" --jobs 1 --out "$out" --slurm-script "$n" >/dev/null
  start=$(date +%s.%N)
  "$out/slurm/submit.sh" --wait >/dev/null
  report "Slurm array of $n task(s)" "$(elapsed "$start")"
done
echo "($(lscpu | sed -n 's/^Model name: *//p'), $(nproc) CPUs; $(grep -q avx512f /proc/cpuinfo && echo AVX-512 || echo no AVX-512))"
