#!/usr/bin/env bash
# The documented Slurm job array (docs/compare.md) on a single-node Slurm
# cluster brought up on this machine: merged tables = one unsharded run.
# Usage: slurm_sweep.sh OFV SOURCE_DIR
OFV=$1 SOURCE_DIR=$2
source "$SOURCE_DIR/test/cluster/common.sh"
export OFV_SLURM_DIR=$work/slurm-cluster
chmod 755 "$work"  # munged runs as the munge user
trap '"$SOURCE_DIR/scripts/slurm-local.sh" down; rm -rf "$work"' EXIT
"$SOURCE_DIR/scripts/slurm-local.sh" up
export SLURM_CONF=$OFV_SLURM_DIR/slurm.conf

export out=$work/sweep parts=3 cpus=1
block=$(documented slurm)
[ -n "$block" ] || { echo "docs/compare.md: no tested slurm block" >&2; exit 1; }
echo "$block"
( cd "$work" && eval "$block" )
grep -q "merged 8 of 8 episodes from 3 runs" "$out/slurm/merge.log" || { cat "$out/slurm/merge.log" >&2; exit 1; }
# Each array task ran its part: three parts, each with its own episodes.
for k in 1 2 3; do grep -q "part $k/3\|\"part\":\"$k/3\"" "$out/parts/$k/sweep.json"; done
reference
same_tables "$out"
