#!/usr/bin/env bash
# The whole performance table of the README's "Benchmarks" section, from one command:
#
#   scripts/perf_table.sh [OUT_DIR] [DLC_RUNS]
#
# REPORT_ONLY=1 scripts/perf_table.sh [OUT_DIR] re-formats the table from OUT_DIR's raw outputs.
# OUT_DIR (default /tmp/vehsim-perf) receives the raw outputs and perf_table.md; DLC_RUNS (default
# 50) is the number of timed runs per DLC row. Rows: tyre force per provider and the libm
# reference operations (criterion, benches/tyre.rs), the ATIIM patch and per-step estimator
# (criterion, benches/atiim.rs), one ISO 3888-2 DLC per vehicle model x tyre provider
# (`vehsim bench`), the 1000-run sweep and a full discovery. Peak memory: `vehsim bench` reports
# its own VmHWM; every other row runs under `/usr/bin/time -v` (maximum resident set size).
# The floor of a DLC row is counted from the reference operations as docs/performance.md derives.
# The yardstick (`vehsim yardstick`: a deliberately naive single-track model, RK4 at 1 ms over
# 10 s, src/bench/yardstick.rs) is timed before and after the DLC rows; each DLC row's median is
# also given in yardstick medians (the median of the two yardstick timings), a figure that scales
# between machines. INSTR=1 adds the instructions per DLC run (callgrind, needs valgrind; the
# runs-3 minus runs-1 count, halved, as docs/performance.md measures them) for the four rows the
# issues track. Needs bash, awk and GNU time (/usr/bin/time); run from anywhere inside the
# repository.
set -euo pipefail

cd "$(git rev-parse --show-toplevel)"
OUT=${1:-/tmp/vehsim-perf}
RUNS=${2:-50}
TIME=/usr/bin/time
[ -x "$TIME" ] || { echo "perf_table.sh: needs GNU time at $TIME" >&2; exit 2; }
mkdir -p "$OUT"
# criterion bench executable of benches/NAME.rs
bench_exe() {
    cargo bench --bench "$1" --no-run 2>&1 | sed -n "s/.*Executable benches\/$1.rs (\(.*\))/\1/p" | tail -1
}
# GNU time -v fields from a log: wall seconds, CPU seconds, peak RSS MiB
wall_s() { awk -F': ' '/Elapsed \(wall clock\)/ { n = split($2, p, ":"); s = 0; for (i = 1; i <= n; i++) s = s * 60 + p[i]; print s }' "$1"; }
cpu_s() { awk -F': ' '/User time/ { u = $2 } /System time/ { s = $2 } END { printf "%.1f", u + s }' "$1"; }
rss_mib() { awk -F': ' '/Maximum resident set size/ { printf "%.1f", $2 / 1024 }' "$1"; }
# criterion's bencher line "test GROUP/NAME ... bench: N ns/iter (+/- M)" -> N
ns_of() { awk -v n="$2" '$2 == n { gsub(",", "", $5); print $5 }' "$1"; }

# REPORT_ONLY=1: only format the table from the raw outputs already in OUT_DIR.
if [ "${REPORT_ONLY:-0}" != 1 ]; then
rm -rf "${OUT:?}/sweep" "$OUT/synth" "$OUT/discover"

# The simulation rows use the link-time-optimised build (Cargo.toml, profile release-lto).
cargo build --profile release-lto --quiet
VEHSIM=$PWD/target/release-lto/vehsim
load_before=$(cut -d' ' -f1-3 /proc/loadavg)

TYRE_EXE=$(bench_exe tyre)
ATIIM_EXE=$(bench_exe atiim)
$TIME -v "$TYRE_EXE" --bench --warm-up-time 1 --measurement-time 2 --output-format bencher \
    >"$OUT/tyre.txt" 2>"$OUT/tyre.time"
$TIME -v "$ATIIM_EXE" --bench --warm-up-time 1 --measurement-time 3 --output-format bencher \
    >"$OUT/atiim.txt" 2>"$OUT/atiim.time"

"$VEHSIM" yardstick --runs "$((RUNS * 4))" --tsv >"$OUT/yardstick.tsv"
: >"$OUT/dlc.tsv"
for model in bicycle roll4dof; do
    for tyre in linear polynomial pacejka dugoff dugoff_thermal atiim_pacejka; do
        contact=isothermal
        [ "$tyre" = atiim_pacejka ] && contact=atiim
        "$VEHSIM" bench maneuvers/dlc.toml --runs "$RUNS" --model $model --tyre-model $tyre \
            --contact $contact --tsv >>"$OUT/dlc.tsv"
    done
done
"$VEHSIM" yardstick --runs "$((RUNS * 4))" --tsv >>"$OUT/yardstick.tsv"

# Instructions per DLC run: (runs 3 - runs 1) / 2 under callgrind (the process's one-off setup,
# such as the flash table and the course's transition search, cancels).
: >"$OUT/instr.tsv"
if [ "${INSTR:-0}" = 1 ]; then
    for row in "bicycle pacejka isothermal" "bicycle atiim_pacejka atiim" "roll4dof pacejka isothermal" \
        "roll4dof atiim_pacejka atiim"; do
        set -- $row
        for n in 1 3; do
            valgrind --tool=callgrind --callgrind-out-file=/dev/null "$VEHSIM" bench maneuvers/dlc.toml \
                --runs $n --model "$1" --tyre-model "$2" --contact "$3" >/dev/null 2>"$OUT/cg.$n.log"
        done
        c1=$(sed -n 's/.*Collected : \([0-9]*\).*/\1/p' "$OUT/cg.1.log")
        c3=$(sed -n 's/.*Collected : \([0-9]*\).*/\1/p' "$OUT/cg.3.log")
        printf '%s\t%s\t%s\t%s\n' "$1" "$2" "$3" "$(( (c3 - c1) / 2 ))" >>"$OUT/instr.tsv"
    done
fi

$TIME -v "$VEHSIM" run --quiet maneuvers/bench/dlc_sweep_1000.toml --out "$OUT/sweep" 2>"$OUT/sweep.time"
$TIME -v "$VEHSIM" synth --effect tyre_relaxation --out "$OUT/synth" >/dev/null 2>"$OUT/synth.time"
$TIME -v "$VEHSIM" discover --vehicle vehicles/sedan.toml --out "$OUT/discover" "$OUT"/synth/0[1-6]_*.csv \
    >/dev/null 2>"$OUT/discover.time"
load_after=$(cut -d' ' -f1-3 /proc/loadavg)
echo "$load_before" >"$OUT/load_before"
echo "$load_after" >"$OUT/load_after"
fi
load_before=$(cat "$OUT/load_before")
load_after=$(cat "$OUT/load_after")

# Reference costs, ns (the bencher format rounds to whole ns; flops_64 is 64 multiply-adds).
R=reference
atan=$(ns_of "$OUT/tyre.txt" $R/libm_atan)
sin=$(ns_of "$OUT/tyre.txt" $R/libm_sin)
sincos=$(ns_of "$OUT/tyre.txt" $R/libm_sin_cos)
tan=$(ns_of "$OUT/tyre.txt" $R/libm_tan)
pow=$(ns_of "$OUT/tyre.txt" $R/libm_pow)
exp=$(ns_of "$OUT/tyre.txt" $R/libm_exp)
sqrt=$(ns_of "$OUT/tyre.txt" $R/sqrt)
flops64=$(ns_of "$OUT/tyre.txt" $R/flops_64)
# the yardstick's median, ms: the mean of its two timings' medians (before and after the DLC rows)
yard=$(awk -F'\t' '{ s += $8; n++ } END { printf "%.4f", s / n }' "$OUT/yardstick.tsv")

{
    echo "Machine: $(nproc)-core $(uname -m), $(awk '/MemTotal/ { printf "%.0f GiB", $2 / 1048576 }' /proc/meminfo);" \
        "load average $load_before before, $load_after after; $(date +%F)."
    echo "Reference ns: atan $atan, sin $sin, sin_cos $sincos, tan $tan, pow $pow, exp $exp, sqrt $sqrt, 64 multiply-adds $flops64."
    echo
    echo "Yardstick (\`vehsim yardstick\`, naive single-track RK4, 1 ms x 10 s): medians $(awk -F'\t' '{ printf "%s%.3f", (NR > 1 ? ", " : ""), $8 }' "$OUT/yardstick.tsv") ms (before, after the DLC rows); unit $yard ms."
    echo
    echo "| what | command | median (min) | real-time factor | peak memory | floor | ratio | median / yardstick | instructions per run |"
    echo "|---|---|---|---|---|---|---|---|---|"
    for p in linear polynomial pacejka pacejka_ellipse pacejka_with_mz dugoff dugoff_thermal atiim_pacejka; do
        echo "| tyre force, $p | \`cargo bench --bench tyre\` | $(ns_of "$OUT/tyre.txt" combined_slip_forces/$p) ns | | $(rss_mib "$OUT/tyre.time") MiB | | | | |"
    done
    echo "| ATIIM patch 64 x 48, wet / dry | \`cargo bench --bench atiim\` | $(awk -v a="$(ns_of "$OUT/atiim.txt" patch_64x48_wet_7kN)" -v b="$(ns_of "$OUT/atiim.txt" patch_64x48_dry_7kN)" 'BEGIN { printf "%.2f / %.2f ms", a / 1e6, b / 1e6 }') | | $(rss_mib "$OUT/atiim.time") MiB | | | | |"
    echo "| ATIIM estimator, per tyre | \`cargo bench --bench atiim\` | $(awk -v a="$(ns_of "$OUT/atiim.txt" estimator_update_4_tyres)" 'BEGIN { printf "%.0f ns", a / 4 }') | | $(rss_mib "$OUT/atiim.time") MiB | | | | |"
    # DLC rows and their floors (docs/performance.md): per RK4 step, 4 stages x T tyres x (slip-angle
    # atan + the provider's irreducible operations), 4 yaw sin_cos, the steer trigonometry once per
    # step, the estimator per tyre once per step, and the flops.
    awk -F'\t' -v atan="$atan" -v vsin="$sin" -v sc="$sincos" -v tan="$tan" -v pow="$pow" -v vexp="$exp" \
        -v vsqrt="$sqrt" -v f64="$flops64" -v runs="$RUNS" -v yard="$yard" -v instr="$OUT/instr.tsv" '
    BEGIN {
        while ((getline line < instr) > 0) { split(line, f, "\t"); ins[f[1] "/" f[2]] = f[4] }
        flop = f64 / 64
        # provider: transcendental ns per evaluation (static loads: no pow) and flops per evaluation
        tr["linear"] = 0;                     fl["linear"] = 6
        tr["polynomial"] = tan + vsqrt;        fl["polynomial"] = 25
        tr["dugoff"] = tan + vsqrt;            fl["dugoff"] = 25
        tr["dugoff_thermal"] = tan + vsqrt;    fl["dugoff_thermal"] = 35
        tr["pacejka"] = 4 * atan + 2 * vsin + 2 * vsqrt;  fl["pacejka"] = 90
        tr["atiim_pacejka"] = 4 * atan + 2 * vsin + vsqrt; fl["atiim_pacejka"] = 60
    }
    {
        model = $2; tyre = $3; contact = $4; steps = $7; med = $8; min = $9; rtf = $10; mem = $11
        if (model == "bicycle") {
            T = 2; body = 60; n = 10; steer = sc; lp = 0
        } else {
            T = 4; body = 150; n = 18; steer = 2 * sc + tan + 2 * atan; lp = pow
        }
        ptr = tr[tyre] + (tyre == "atiim_pacejka" ? 0 : (tyre == "pacejka" ? 0 : lp))
        stage = T * (atan + ptr + (fl[tyre] + 30) * flop) + sc + body * flop
        # estimator: exp of the interpolated ln rise, exp of the bulk decay, 2 sqrt, the tan of the
        # sliding speed, ~60 flops (table lookups with the polynomial ln)
        est = (contact == "atiim") ? T * (2 * vexp + 2 * vsqrt + tan + 60 * flop) : 0
        step_ns = 4 * stage + steer + est + 13 * n * flop
        floor_ms = steps * step_ns / 1e6
        key = model "/" tyre
        icount = (key in ins) ? sprintf("%.2f M", ins[key] / 1e6) : ""
        printf "| DLC, %s + %s%s | `vehsim bench maneuvers/dlc.toml --runs %d --model %s --tyre-model %s%s` | %.2f ms (%.2f) | %.0f | %.1f MiB | %.2f ms | %.1f | %.3f | %s |\n",
            model, tyre, (contact == "atiim" ? " + ATIIM estimator" : ""), runs, model, tyre,
            (contact == "atiim" ? " --contact atiim" : ""), med, min, rtf, mem / 1024, floor_ms, med / floor_ms,
            med / yard, icount
    }' "$OUT/dlc.tsv"
    awk -F'\t' -v runs="$((RUNS * 4))" '{ printf "| yardstick (%s): naive single track, RK4 1 ms x 10 s | `vehsim yardstick --runs %d` | %.3f ms (%.3f) | %.0f | %.1f MiB | | | 1 | |\n", (NR == 1 ? "before" : "after"), runs, $8, $9, $10, $11 / 1024 }' "$OUT/yardstick.tsv"
    echo "| 1000-run DLC sweep, bicycle + Pacejka, $(nproc) threads | \`vehsim run --quiet maneuvers/bench/dlc_sweep_1000.toml\` | $(wall_s "$OUT/sweep.time") s wall, $(cpu_s "$OUT/sweep.time") s CPU | | $(rss_mib "$OUT/sweep.time") MiB | | | $(awk -v w="$(wall_s "$OUT/sweep.time")" -v y="$yard" 'BEGIN { printf "%.0f", w * 1000 / y }') | |"
    echo "| full discovery (6 runs of 12 s) | \`vehsim synth --effect tyre_relaxation --out b && vehsim discover --vehicle vehicles/sedan.toml --out o b/0[1-6]_*.csv\` | $(wall_s "$OUT/discover.time") s wall, $(cpu_s "$OUT/discover.time") s CPU (synth $(wall_s "$OUT/synth.time") s) | | $(rss_mib "$OUT/discover.time") MiB (synth $(rss_mib "$OUT/synth.time") MiB) | | | | |"
} | tee "$OUT/perf_table.md"
