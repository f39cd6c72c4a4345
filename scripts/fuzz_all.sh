#!/usr/bin/env bash
# Runs every cargo-fuzz target of fuzz/ in turn for SECONDS each (default 600), one process, with the
# bounds docs/hardening.md states: 2 GiB of memory, 10 s per input. Needs nightly and cargo-fuzz.
# The log of each run goes to fuzz/logs/TARGET.log; crashes to fuzz/artifacts/TARGET/.
set -euo pipefail
cd "$(dirname "$0")/../fuzz"
seconds="${1:-600}"
mkdir -p logs
for target in scene vol vdb weather_png table_file sprite_model metar; do
    mkdir -p "corpus/$target"
    echo "fuzzing $target for $seconds s"
    cargo +nightly fuzz run "$target" "corpus/$target" \
        "../crates/cloudscape/tests/fuzz-regressions/$target/accept" \
        "../crates/cloudscape/tests/fuzz-regressions/$target/reject" \
        -- -max_total_time="$seconds" -rss_limit_mb=2048 -malloc_limit_mb=2048 -timeout=10 \
        >"logs/$target.log" 2>&1 || echo "$target: FAILED (see fuzz/logs/$target.log)"
    tail -n 2 "logs/$target.log"
done
