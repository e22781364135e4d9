#!/usr/bin/env bash
# The speed guard's test of itself (docs/speed.md): a build whose set differences repeat
# their work (feature `speed-guard-selftest`: SetDifference::subtract and the hole's clip,
# hole_difference::part_inside_convex) must fail `penumbra bench --suite speed` against the
# committed baseline, naming a slowed scene.
# Run after the guard itself: it rebuilds target/release/penumbra with the feature and then
# without it again.
set -uo pipefail
cd "$(dirname "$0")/.."
scenes=cube,chair,fig4
cargo build -q --release --no-default-features --features speed-guard-selftest || exit 2
log=out/bench/speed-selftest/guard.log
mkdir -p "$(dirname "$log")"
target/release/penumbra bench --suite speed --only "$scenes" \
    --baseline tests/data/speed_baseline.json --out-dir out/bench/speed-selftest >"$log" 2>&1
status=$?
cargo build -q --release --no-default-features || exit 2
cat "$log"
if [ "$status" = 0 ]; then
    echo "speed guard self-test FAILED: the slowed build passed the guard" >&2
    exit 1
fi
if ! grep -q "the speed guard failed" "$log"; then
    echo "speed guard self-test FAILED: the slowed build failed for another reason" >&2
    exit 1
fi
echo "speed guard self-test: the slowed set difference was caught"
