# Shared by the cluster tests: the small sweep, the documented commands and
# the unsharded reference. Sourced with OFV (the ofv program) and SOURCE_DIR set.
set -euo pipefail

work=$(mktemp -d "${TMPDIR:-/tmp}/ofv-cluster.XXXXXX")
mkdir -p "$work/bin"
ln -s "$OFV" "$work/bin/ofv"  # the documented lines call `ofv`
export PATH="$work/bin:$PATH"

# A small sweep: 2 scenarios x 2 variants x 2 seeds, half a second each.
cat > "$work/grid.yaml" <<'GRID'
name: cluster-test
seeds: 2
set: {duration: 0.5, perception: ground-truth}
variants:
  - {name: ofv, set: {}}
  - {name: static, set: {method: static}}
GRID
mkdir -p "$work/scenarios"
cp "$SOURCE_DIR/sim/scenarios/dvd-one-hand.yaml" "$SOURCE_DIR/sim/scenarios/dvd-static.yaml" "$work/scenarios/"
scenarios=$work/scenarios
grid=$work/grid.yaml
export scenarios grid

# The fenced block after `<!-- tested: NAME -->` in docs/compare.md, word for word.
documented() {
  sed -n "/<!-- tested: $1 -->/,/^\`\`\`\$/p" "$SOURCE_DIR/docs/compare.md" | sed '1,2d;$d'
}

# One unsharded run of the same sweep.
reference() {
  ofv compare --scenarios "$scenarios" --grid "$grid" --jobs 2 --out "$work/reference" >/dev/null
}

same_tables() { python3 "$SOURCE_DIR/test/cluster/same_tables.py" "$work/reference" "$1"; }
