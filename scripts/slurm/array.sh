# shellcheck shell=bash
# Sourced by render.sh and frames.sh: submit one Slurm array job, wait for it by polling
# (sbatch --wait polls at growing intervals and can notice the end 32 s late), and
# resubmit the tasks that failed, once.
#
# The caller sets KIND (a word for one task: "tile", "frame"), LOGDIR, and defines
# `output_of I`, which prints the file task I must leave behind. A task has failed when
# Slurm says it did not complete or its output is missing.
#
# sbatch options come from the environment:
#   CPUS_PER_TASK   CPUs (and kd2exr threads) per task, default 1
#   PARTITION       partition (default: the cluster's default partition)
#   TIME_LIMIT      time limit per task, in sbatch's --time format
#   SBATCH_ARGS     any further sbatch options, split at spaces
#   POLL_SECONDS    how often to ask Slurm about the job, default 0.5

sbatch_flags=(--cpus-per-task="${CPUS_PER_TASK:-1}")
[ -n "${PARTITION:-}" ] && sbatch_flags+=(--partition="$PARTITION")
[ -n "${TIME_LIMIT:-}" ] && sbatch_flags+=(--time="$TIME_LIMIT")
# shellcheck disable=SC2206 # SBATCH_ARGS is a list of options, split on purpose
[ -n "${SBATCH_ARGS:-}" ] && sbatch_flags+=(${SBATCH_ARGS})

current_job=
# Interrupting the driver cancels the job instead of leaving tasks running.
trap '[ -n "$current_job" ] && scancel "$current_job" 2>/dev/null; exit 130' INT TERM

# submit ARRAY LOG SCRIPT ARGS…: prints the job id.
submit() {
    local array=$1 log=$2
    shift 2
    sbatch --parsable --array="$array" -o "$log" "${sbatch_flags[@]}" "$@" | cut -d';' -f1
}

# task_states JOB: one "TASK STATE" line per array task Slurm still remembers.
task_states() {
    scontrol -o show job "$1" 2>/dev/null |
        sed -n 's/.*ArrayTaskId=\([0-9]*\) .*JobState=\([A-Z_]*\).*/\1 \2/p'
}

# wait_job JOB COUNT: returns when no task of JOB is pending or running.
wait_job() {
    local job=$1 count=$2 out finished last=-1
    while true; do
        # A job Slurm has forgotten (MinJobAge passed) ended long ago.
        out=$(scontrol -o show job "$job" 2>/dev/null) || return 0
        finished=$(grep -c 'JobState=COMPLETED' <<<"$out" || true)
        if [ "$finished" != "$last" ]; then
            echo "slurm: job $job: $finished of $count ${KIND}s done" >&2
            last=$finished
        fi
        if ! grep -o 'JobState=[A-Z_]*' <<<"$out" |
            grep -qvE '=(COMPLETED|FAILED|CANCELLED|TIMEOUT|NODE_FAIL|OUT_OF_MEMORY|BOOT_FAIL|DEADLINE|PREEMPTED)$'; then
            return 0
        fi
        sleep "${POLL_SECONDS:-0.5}"
    done
}

# failed_tasks JOB I…: prints those of the tasks I… that did not leave their output.
failed_tasks() {
    local job=$1 states i state
    shift
    states=$(task_states "$job")
    for i in "$@"; do
        state=$(sed -n "s/^$i //p" <<<"$states")
        if [ ! -s "$(output_of "$i")" ] || { [ -n "$state" ] && [ "$state" != COMPLETED ]; }; then
            echo "$i"
        fi
    done
}

# run_array COUNT SCRIPT ARGS…: tasks 0…COUNT-1, failed ones resubmitted once; returns 1
# naming each task that failed twice and its log.
run_array() {
    local count=$1 all failed again i
    shift
    mapfile -t all < <(seq 0 $((count - 1)))
    mkdir -p "$LOGDIR"
    current_job=$(submit "0-$((count - 1))" "$LOGDIR/$KIND-%a.log" "$@")
    echo "slurm: submitted job $current_job: $count ${KIND}s (logs in $LOGDIR)" >&2
    wait_job "$current_job" "$count"
    mapfile -t failed < <(failed_tasks "$current_job" "${all[@]}")
    [ ${#failed[@]} -eq 0 ] && return 0
    echo "slurm: ${KIND}s ${failed[*]} failed; resubmitting them once" >&2
    current_job=$(submit "$(
        IFS=,
        echo "${failed[*]}"
    )" "$LOGDIR/$KIND-%a.retry.log" "$@")
    wait_job "$current_job" "${#failed[@]}"
    mapfile -t again < <(failed_tasks "$current_job" "${failed[@]}")
    [ ${#again[@]} -eq 0 ] && return 0
    for i in "${again[@]}"; do
        echo "slurm: $KIND $i failed twice; see $LOGDIR/$KIND-$i.retry.log (first try: $LOGDIR/$KIND-$i.log)" >&2
    done
    return 1
}
