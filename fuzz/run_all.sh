#!/usr/bin/env bash
# Run every fuzz target for a bounded time, one after another (single process each), then merge
# what gave new coverage into the committed corpus. Usage: fuzz/run_all.sh [SECONDS_PER_TARGET]
# (default 120). Logs: fuzz/logs/<target>.log; crashes: fuzz/artifacts/<target>/.
# Needs a nightly toolchain and cargo-fuzz (docs/fuzzing.md).
set -uo pipefail
cd "$(dirname "$0")"
secs=${1:-120}
mkdir -p logs work
printf 'target\tseconds\texecutions\tcrashes\n' > logs/summary.tsv
for t in $(cargo +nightly fuzz list); do
    mkdir -p "work/$t" "corpus/$t"
    # New inputs go to work/<target> (not committed); the committed corpus is read as seeds.
    cargo +nightly fuzz run "$t" "work/$t" "corpus/$t" -- \
        -max_total_time="$secs" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
        >"logs/$t.log" 2>&1
    execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "logs/$t.log" | grep -o '[0-9]*$' | tail -1)
    crashes=$(find "artifacts/$t" -type f 2>/dev/null | wc -l)
    printf '%s\t%s\t%s\t%s\n' "$t" "$secs" "${execs:-?}" "$crashes" >> logs/summary.tsv
    # Add to the committed corpus only the inputs that reach new edges (hit counts ignored).
    cargo +nightly fuzz run "$t" "corpus/$t" "work/$t" -- -merge=1 -use_counters=0 >>"logs/$t.log" 2>&1
done
column -t logs/summary.tsv
