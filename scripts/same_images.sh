#!/usr/bin/env bash
# Fingerprints of what penumbra computes, for checking that a change of structure changes no
# result: every embedded scene's image for the analytic methods, analytic-exact and
# the environment's analytic and ray-traced methods at a fixed seed, and `stress` at a fixed
# seed. One line per output: "<what> <sha256 of the PFM or of the report without its timing>".
#
#   scripts/same_images.sh BINARY > before.txt   # built from the old commit
#   scripts/same_images.sh BINARY > after.txt    # built from the new one
#   diff before.txt after.txt && echo identical
#
# Small images (64x64, one sample per pixel) keep it to a few minutes on two cores; the tree
# cache starts empty so that trees are built as a new user's first run builds them.
set -euo pipefail
bin=${1:?usage: scripts/same_images.sh PATH/TO/penumbra}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export PENUMBRA_CACHE_DIR="$work/cache"
size=64x64
fingerprint() { # name, then the render arguments
    local name=$1
    shift
    "$bin" render "$@" --size "$size" --out "$work/img" >/dev/null 2>&1
    echo "$name $(sha256sum < "$work/img.pfm" | cut -d' ' -f1)"
}
for scene in $("$bin" scenes); do
    case $scene in
    env_*)
        fingerprint "$scene/env-analytic" "$scene" --env-method analytic
        fingerprint "$scene/env-rt" "$scene" --env-method rt --seed 3
        ;;
    *)
        for method in analytic per-triangle unshadowed; do
            fingerprint "$scene/$method" "$scene" --method "$method"
        done
        fingerprint "$scene/analytic-exact" "$scene" --method analytic-exact --spp 2 --seed 5
        ;;
    esac
done
for f in tests/data/blender/*.toml tests/data/blender/*.glb; do
    fingerprint "$f/analytic" "$f" --method analytic
done
"$bin" stress --cases 20000 --seed 11 --json "$work/stress.json" >/dev/null 2>&1
python3 - "$work/stress.json" <<'PY'
import hashlib, json, sys
report = json.load(open(sys.argv[1]))
report.pop("seconds", None)
report.pop("timing", None)  # measured: differs from run to run
text = json.dumps(report, sort_keys=True)
print("stress/seed11", hashlib.sha256(text.encode()).hexdigest())
PY
