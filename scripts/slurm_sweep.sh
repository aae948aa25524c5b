#!/usr/bin/env bash
# Run a vehsim sweep as a Slurm job array and merge it: the README's Slurm recipe with its
# failures named.
#
#   scripts/slurm_sweep.sh SPEC N OUT [SBATCH_OPTION...]
#
# submits `sbatch --wait --array=1-N` whose task K runs `vehsim run SPEC --quiet --out OUT
# --shard K/N` (one shard per task, in the submitting folder), then `vehsim merge` of the N shard
# folders into OUT/<name>/, the same bytes as `vehsim run SPEC --out OUT`. OUT must be on a file
# system every node sees, and start without shards of SPEC (an old shard would be merged
# otherwise: the script refuses a non-empty OUT/<name>.shard-*-of-N). Each task's output goes to
# OUT/slurm/<job>_<task>.out. Extra arguments go to sbatch (--partition, --time, --cpus-per-task;
# with --cpus-per-task C add VEHSIM_JOBS=C to run each shard on C threads, default 1).
#
# `vehsim` is taken from PATH (or $VEHSIM_BIN) where the tasks run; sbatch exports this
# environment to them. When a task fails, nothing is merged: the script names every failed task,
# its shard, its exit code and the last lines of its output, and exits 1. Needs sbatch, scontrol.
set -euo pipefail

die() {
    echo "slurm_sweep.sh: $*" >&2
    exit 1
}

[ $# -ge 3 ] || die "usage: $0 SPEC N OUT [SBATCH_OPTION...]"
spec=$1 n=$2 out=$3
shift 3
[[ "$n" =~ ^[1-9][0-9]*$ ]] || die "N: '$n' is not a shard count; expected a whole number >= 1"
[ -f "$spec" ] || die "$spec: spec file not found"
vehsim=${VEHSIM_BIN:-$(command -v vehsim || true)}
[ -n "$vehsim" ] || die "vehsim is not on PATH (set VEHSIM_BIN to the binary)"
export VEHSIM_BIN=$vehsim VEHSIM_JOBS=${VEHSIM_JOBS:-1}
# Bad input is refused here, before anything is queued.
"$vehsim" validate --quiet "$spec" >/dev/null || die "$spec: not a valid spec (see above); nothing submitted"
mkdir -p "$out/slurm"
shopt -s nullglob
old=("$out"/*.shard-*-of-"$n")
[ ${#old[@]} -eq 0 ] || die "$out already holds shard folders (${old[*]}); remove them or use another OUT"

# The recipe: one array task per shard, sbatch waiting for all of them.
set +e
job=$(sbatch --parsable --wait --array="1-$n" --job-name=vehsim-sweep --output="$out/slurm/%A_%a.out" "$@" \
    --wrap "\"\$VEHSIM_BIN\" run \"$spec\" --quiet --jobs \"\$VEHSIM_JOBS\" --out \"$out\" --shard \${SLURM_ARRAY_TASK_ID}/$n")
status=$?
set -e
job=${job%%;*}
if [ "$status" -ne 0 ]; then
    [[ "$job" =~ ^[0-9]+$ ]] || die "sbatch failed (exit $status) before the job was queued; nothing merged"
    echo "slurm_sweep.sh: job array $job did not complete (sbatch exit $status); nothing merged. Failed tasks:" >&2
    # scontrol keeps finished jobs for MinJobAge (300 s by default): one record per array task
    records=$(scontrol -o show job "$job" 2>/dev/null || true)
    [ -n "$records" ] || echo "  (Slurm no longer lists job $job; the tasks' output is in $out/slurm/)" >&2
    printf '%s\n' "$records" | while read -r line; do
        [ -n "$line" ] || continue
        task=$(grep -o 'ArrayTaskId=[^ ]*' <<<"$line" | cut -d= -f2)
        state=$(grep -o 'JobState=[^ ]*' <<<"$line" | cut -d= -f2)
        code=$(grep -o ' ExitCode=[^ ]*' <<<"$line" | cut -d= -f2)
        [ "$state" = COMPLETED ] && continue
        echo "  task $task (shard $task/$n): $state, exit code $code; last lines of $out/slurm/${job}_$task.out:" >&2
        log="$out/slurm/${job}_$task.out"
        if [ -f "$log" ]; then tail -n 5 "$log" | sed 's/^/    /' >&2; else echo "    (no output file)" >&2; fi
    done
    exit 1
fi
shards=("$out"/*.shard-*-of-"$n")
"$vehsim" merge "${shards[@]}"
