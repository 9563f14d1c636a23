#!/usr/bin/env bash
# Compares heliodon with Radiance on the bundled scenes through export-radiance.
# Needs Radiance on PATH with its lib on RAYPATH (e.g. `pip install pyradiance`,
# then PATH=$SITE/pyradiance/bin:$PATH RAYPATH=.:$SITE/pyradiance/lib).
# Usage: tools/check_bundled_radiance.sh [OUT_DIR]   (runs each case's run.sh: slow, minutes per case)
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-target/bundled-radiance}"
cargo build --release --quiet
heliodon=target/release/heliodon
for case in "test_room 2026-03-21 10:00 clear" "office 2026-06-21 15:00 intermediate" "living_room 2026-12-21 12:00 overcast"; do
    set -- $case
    dir="$out/$1-$4"
    mkdir -p "$dir"
    "$heliodon" export-radiance "assets/scenes/$1/scene.toml" --date "$2" --time "$3" --sky "$4" --out "$dir"
    "$heliodon" sensors "assets/scenes/$1/scene.toml" --date "$2" --time "$3" --sky "$4" --format csv > "$dir/heliodon.csv"
    sh "$dir/run.sh" > /dev/null
    python3 - "$dir" <<'PY'
import csv, statistics, sys
d = sys.argv[1]
ref = {r["name"]: float(r["illuminance_lux"]) for r in csv.DictReader(open(f"{d}/radiance.csv"))}
got = {r["name"]: float(r["illuminance_lux"]) for r in csv.DictReader(open(f"{d}/heliodon.csv"))}
errors = sorted(abs(got[n] / r - 1) if r >= 50 else abs(got[n] - r) / 250 for n, r in ref.items())
print(f"{d}: n {len(errors)} median {100 * statistics.median(errors):.2f}% "
      f"p90 {100 * errors[int(0.9 * len(errors))]:.2f}% max {100 * errors[-1]:.2f}%")
PY
done
