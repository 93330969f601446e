#!/usr/bin/env bash
# The cluster files on a real Slurm: a one-node cluster (Debian's slurm-wlm + munge) on 127.0.0.1, the
# shipped job files submitted as docs/cluster.md says, the merge compared with the unsharded run.
#
#   tests/slurm/run.sh [RINSCOPE_BINARY]     (default $RINSCOPE, else $CARGO_TARGET_DIR/release/rinscope)
#
# Needs root (or passwordless sudo): slurmd launches the jobs. Installs slurm-wlm and munge with apt-get
# when they are missing and fails if it cannot; RINSCOPE_SKIP_SLURM=1 skips the whole test and says so.
# Everything lives in one temporary folder (config, munge key and socket, state, spool, logs, the jobs'
# files) with its own munge socket and two free ports on 127.0.0.1, so a system Slurm or munge is neither
# used nor disturbed; an EXIT trap cancels the jobs, stops the three daemons (and any process they left),
# and removes the folder, on failure too. Every wait is bounded. The last line is
# "slurm: 1 passed, 0 failed" or "slurm: 0 passed, 1 failed" (exit 1).
#
# Checks:
#   1. assets/cluster/submit-montecarlo.sh 4 --cpus-per-task=<all CPUs> (RUNS=24): the merge's all.json
#      equals `rinscope montecarlo --runs 24 --json` except wall_s and threads; each shard ran on that many
#      threads;
#   2. the same by hand (sbatch --array=0-2 montecarlo.slurm, sbatch --dependency montecarlo-merge.slurm),
#      each shard on 1 thread (the job file's default), the logs in the submission directory;
#   3. a failing shard (RUNS=0, refused by rinscope): the array fails and the merge is cancelled, not left
#      pending forever.
# Tunables: RINSCOPE_SLURM_RUNS (24), RINSCOPE_SLURM_TIMEOUT (seconds for each job set, 600),
# RINSCOPE_SLURM_KEEP=1 keeps the temporary folder (logs, job files) after the daemons stopped.
set -euo pipefail

if [[ ${RINSCOPE_SKIP_SLURM:-} == 1 ]]; then
  echo "slurm: SKIPPED (RINSCOPE_SKIP_SLURM=1): the cluster files were not run"
  exit 0
fi

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
bin=${1:-${RINSCOPE:-${CARGO_TARGET_DIR:-$repo/target}/release/rinscope}}
runs=${RINSCOPE_SLURM_RUNS:-24}
timeout_s=${RINSCOPE_SLURM_TIMEOUT:-600}

say() { echo "slurm: $*"; }
early_fail() {
  echo "slurm: FAILED: $*" >&2
  echo "slurm: 0 passed, 1 failed"
  exit 1
}

[[ -x $bin ]] || early_fail "no rinscope binary at $bin (build with cargo build --release, or pass its path)"
bin=$(cd "$(dirname "$bin")" && pwd)/$(basename "$bin")

# slurmd must run as root to start jobs: re-run under passwordless sudo if needed.
if ((EUID != 0)); then
  if command -v sudo >/dev/null 2>&1 && sudo -n true 2>/dev/null; then
    exec sudo -n env "PATH=$PATH" "RINSCOPE_SLURM_RUNS=$runs" "RINSCOPE_SLURM_TIMEOUT=$timeout_s" bash "$0" "$bin"
  fi
  early_fail "needs root or passwordless sudo to run slurmd (or set RINSCOPE_SKIP_SLURM=1 to skip, visibly)"
fi

# Install the packages if missing; no recommends (the basic plugins are all this test uses).
need=(munged mungekey slurmctld slurmd sbatch squeue scontrol scancel sinfo)
missing() { local c; for c in "${need[@]}"; do command -v "$c" >/dev/null 2>&1 || return 0; done; return 1; }
if missing; then
  say "installing slurm-wlm and munge (apt-get)"
  if ! { timeout 900 apt-get update -qq && DEBIAN_FRONTEND=noninteractive timeout 900 apt-get install -y -qq --no-install-recommends slurm-wlm munge; } >/tmp/rinscope-slurm-apt.log 2>&1; then
    tail -20 /tmp/rinscope-slurm-apt.log >&2
    early_fail "could not install slurm-wlm and munge (log /tmp/rinscope-slurm-apt.log); set RINSCOPE_SKIP_SLURM=1 to skip, visibly"
  fi
  missing && early_fail "slurm-wlm and munge installed but one of ${need[*]} is still not on PATH"
  rm -f /tmp/rinscope-slurm-apt.log
fi
# Comparing JSON needs python3 or jq.
if ! command -v python3 >/dev/null 2>&1 && ! command -v jq >/dev/null 2>&1; then
  { timeout 900 apt-get update -qq && DEBIAN_FRONTEND=noninteractive timeout 900 apt-get install -y -qq --no-install-recommends jq; } >/dev/null 2>&1 ||
    early_fail "neither python3 nor jq, and jq could not be installed"
fi

# A Slurm job environment around this script (CI inside a Slurm job) must not leak into the test cluster.
while IFS='=' read -r name _; do
  case $name in SLURM_* | SBATCH_* | SALLOC_* | SRUN_* | SQUEUE_* | SINFO_* | SCONTROL_*) unset "$name" ;; esac
done < <(env)

started=$(date +%s)
tmp=$(mktemp -d /tmp/rinscope-slurm.XXXXXX)
chmod 755 "$tmp" # munged wants every folder above its socket searchable by all
# Every process started from here on (daemons, sbatch, the jobs, their slurmstepd) carries this marker, so
# the cleanup finds whatever is left of this run, and only of this run.
export RINSCOPE_SLURM_TEST_RUN=$tmp
pids=()
passed=0
daemons_up=0

# Client commands talk to slurmctld: none may hang.
client_timeout=30
sl() { timeout "$client_timeout" "$@"; }

diagnostics() {
  echo "---- squeue" >&2
  sl squeue >&2 2>&1 || true
  echo "---- scontrol show job" >&2
  sl scontrol show job >&2 2>&1 || true
  echo "---- sinfo" >&2
  sl sinfo -N -l >&2 2>&1 || true
  local f
  for f in "$tmp"/log/*.log "$tmp"/work/*.log "$tmp"/work/*/*.log; do
    [[ -f $f ]] || continue
    echo "---- tail ${f#"$tmp"/}" >&2
    tail -25 "$f" >&2 || true
  done
}

cleanup() {
  local status=$?
  set +e
  trap - EXIT INT TERM
  client_timeout=5 # a controller that hangs must not hold the cleanup up
  if ((status != 0 && daemons_up)); then diagnostics; fi
  local i
  if ((daemons_up)); then
    # Cancel whatever is queued or running, give it up to 15 s to end.
    local jobs deadline=$(($(date +%s) + 15))
    mapfile -t jobs < <(sl squeue -h -o %A 2>/dev/null | sort -u)
    ((${#jobs[@]})) && sl scancel "${jobs[@]}" >/dev/null 2>&1
    while (($(date +%s) < deadline)) && [[ -n $(sl squeue -h -o %A 2>/dev/null) ]]; do sleep 1; done
  fi
  # Stop the daemons (slurmd, slurmctld, munged: last started first), then anything else of this run
  # (job steps, their slurmstepd) found by the marker in its environment.
  local pid
  for ((i = ${#pids[@]} - 1; i >= 0; i--)); do kill -TERM "${pids[i]}" 2>/dev/null; done
  for ((i = 0; i < 20; i++)); do
    local alive=0
    for pid in "${pids[@]}"; do kill -0 "$pid" 2>/dev/null && alive=1; done
    ((alive)) || break
    sleep 0.5
  done
  for pid in "${pids[@]}"; do kill -KILL "$pid" 2>/dev/null; wait "$pid" 2>/dev/null; done
  local p env_entries e fd mine
  for p in /proc/[0-9]*; do
    pid=${p#/proc/}
    [[ $pid == "$$" ]] && continue
    mine=0
    if mapfile -d '' env_entries 2>/dev/null <"$p/environ"; then
      for e in "${env_entries[@]}"; do [[ $e == "RINSCOPE_SLURM_TEST_RUN=$tmp" ]] && mine=1 && break; done
    fi
    # slurmstepd drops the environment but keeps slurmd's log open.
    if ((!mine)); then
      for fd in "$p"/fd/*; do [[ $(readlink "$fd" 2>/dev/null) == "$tmp"/* ]] && mine=1 && break; done 2>/dev/null
    fi
    if ((mine)); then
      echo "slurm: killing leftover process $pid ($(tr '\0' ' ' 2>/dev/null <"$p/cmdline"))" >&2
      kill -KILL "$pid" 2>/dev/null
    fi
  done
  cd /
  if [[ ${RINSCOPE_SLURM_KEEP:-} == 1 ]]; then
    echo "slurm: kept $tmp (RINSCOPE_SLURM_KEEP=1)" >&2
  else
    rm -rf "$tmp"
  fi
  local took=$(($(date +%s) - started))
  if ((status == 0 && passed)); then
    say "cluster files ran on a one-node Slurm in ${took} s"
    echo "slurm: 1 passed, 0 failed"
    exit 0
  fi
  echo "slurm: FAILED after ${took} s (diagnostics above)" >&2
  echo "slurm: 0 passed, 1 failed"
  exit 1
}
trap cleanup EXIT
trap 'exit 130' INT
trap 'exit 143' TERM

fail() {
  echo "slurm: FAILED: $*" >&2
  exit 1
}

# Bounded wait: wait_for SECONDS WHAT COMMAND...
wait_for() {
  local limit=$1 what=$2
  shift 2
  local t0
  t0=$(date +%s)
  until "$@"; do
    (($(date +%s) - t0 < limit)) || fail "timed out after ${limit} s waiting for $what"
    sleep 1
  done
}

# Two free TCP ports on loopback for slurmctld and slurmd.
port_free() { ! (exec 3<>"/dev/tcp/127.0.0.1/$1") 2>/dev/null; }
ports=()
for ((p = 20000 + RANDOM % 20000; ${#ports[@]} < 2 && p < 65000; p++)); do
  port_free "$p" && ports+=("$p")
done
((${#ports[@]} == 2)) || fail "no free ports on 127.0.0.1"

mkdir -p "$tmp"/{munge,run,state,spool,log,work}
chmod 700 "$tmp/munge"
chmod 755 "$tmp/run"

# munge: its own key and socket.
mungekey --create --keyfile="$tmp/munge/munge.key" 2>/dev/null ||
  { dd if=/dev/urandom of="$tmp/munge/munge.key" bs=1024 count=1 status=none && chmod 600 "$tmp/munge/munge.key"; }
munged -F --socket="$tmp/run/munge.socket" --key-file="$tmp/munge/munge.key" --pid-file="$tmp/run/munged.pid" \
  --seed-file="$tmp/munge/munged.seed" --log-file="$tmp/log/munged.log" >"$tmp/log/munged.out.log" 2>&1 &
pids+=($!)
munge_ok() { munge -n -S "$tmp/run/munge.socket" 2>/dev/null | unmunge -S "$tmp/run/munge.socket" >/dev/null 2>&1; }
wait_for 20 "munged" munge_ok

node=$(hostname -s 2>/dev/null || hostname)
cpus=$(nproc)
mem_mb=$(($(awk '/^MemTotal:/ {print $2}' /proc/meminfo) / 1024 / 2))
((mem_mb > 1000)) && mem_mb=1000
export SLURM_CONF=$tmp/slurm.conf
cat >"$SLURM_CONF" <<EOF
# One node on loopback, for tests/slurm/run.sh only.
ClusterName=rinscopetest
SlurmctldHost=$node(127.0.0.1)
SlurmctldPort=${ports[0]}
SlurmdPort=${ports[1]}
CommunicationParameters=NoCtldInAddrAny,NoInAddrAny
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$tmp/run/munge.socket
StateSaveLocation=$tmp/state
SlurmdSpoolDir=$tmp/spool
SlurmctldPidFile=$tmp/run/slurmctld.pid
SlurmdPidFile=$tmp/run/slurmd.pid
SlurmctldLogFile=$tmp/log/slurmctld.log
SlurmdLogFile=$tmp/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/backfill
MpiDefault=none
ReturnToService=2
MailProg=/bin/true
NodeName=$node NodeAddr=127.0.0.1 NodeHostname=$node CPUs=$cpus RealMemory=$mem_mb State=UNKNOWN
PartitionName=test Nodes=$node Default=YES MaxTime=INFINITE State=UP
EOF
slurmctld -D >"$tmp/log/slurmctld.out.log" 2>&1 &
pids+=($!)
daemons_up=1
ctld_up() { sl scontrol ping >/dev/null 2>&1; }
wait_for 30 "slurmctld" ctld_up
slurmd -D -N "$node" >"$tmp/log/slurmd.out.log" 2>&1 &
pids+=($!)
node_idle() { [[ $(sl sinfo -h -n "$node" -o %T 2>/dev/null) == idle ]]; }
wait_for 60 "node $node to be idle" node_idle
say "one-node cluster up in $(($(date +%s) - started)) s: $node, $cpus CPUs, slurmctld 127.0.0.1:${ports[0]}, slurmd 127.0.0.1:${ports[1]}"

# The state of a job (JobState=...), UNKNOWN if the controller does not answer (waited for like PENDING;
# a finished job stays known for MinJobAge, 300 s, far longer than one poll).
job_state() {
  local line
  line=$(sl scontrol -o show job "$1" 2>/dev/null) || { echo UNKNOWN; return 0; }
  sed -n 's/.*JobState=\([A-Z_]*\).*/\1/p' <<<"$line" | head -1
}
# Waits until job $1 has ended; echoes its final state.
wait_job_end() {
  local job=$1 t0 state
  t0=$(date +%s)
  while :; do
    state=$(job_state "$job")
    case $state in
      UNKNOWN | PENDING | RUNNING | CONFIGURING | COMPLETING | SUSPENDED | REQUEUED | RESIZING | SIGNALING | STAGE_OUT) ;;
      *)
        echo "$state"
        return 0
        ;;
    esac
    if (($(date +%s) - t0 >= timeout_s)); then
      echo "slurm: job $job still $state after ${timeout_s} s" >&2
      echo TIMEOUT
      return 0
    fi
    sleep 1
  done
}

# The statistics without what measures the machine.
same_statistics() {
  if command -v python3 >/dev/null 2>&1; then
    python3 - "$1" "$2" <<'PY'
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:3])
for v in (a, b):
    v.pop("wall_s", None)
    v.pop("threads", None)
if a != b:
    keys = sorted(k for k in set(a) | set(b) if a.get(k) != b.get(k))
    print("slurm: differ in: " + ", ".join(keys), file=sys.stderr)
    sys.exit(1)
PY
  else
    cmp -s <(jq -S 'del(.wall_s, .threads)' "$1") <(jq -S 'del(.wall_s, .threads)' "$2") ||
      { echo "slurm: $1 and $2 differ beyond wall_s and threads" >&2; return 1; }
  fi
}

# The threads a shard file says its shard ran on (rayon's, which the job file sets from Slurm's CPUs).
shard_threads() {
  if command -v python3 >/dev/null 2>&1; then
    python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["summary"]["threads"])' "$1"
  else
    jq -r .summary.threads "$1"
  fi
}
# Every shard of $1 (a folder) ran on $2 threads.
shards_ran_on() {
  local f n=0
  for f in "$1"/shard-*.json; do
    [[ $(shard_threads "$f") == "$2" ]] || { echo "slurm: $f ran on $(shard_threads "$f") threads, not $2" >&2; return 1; }
    n=$((n + 1))
  done
  ((n > 0))
}

export RINSCOPE=$bin
cd "$tmp/work"
t=$(date +%s)
"$bin" montecarlo --runs "$runs" --json whole.json >whole.log 2>&1 || { cat whole.log >&2; fail "the unsharded run failed"; }
say "unsharded: rinscope montecarlo --runs $runs in $(($(date +%s) - t)) s"

# 1. The wrapper, as docs/cluster.md gives it, with every CPU of the node for each shard.
mkdir wrapper && cd wrapper
t=$(date +%s)
read -r array merge < <(RUNS=$runs timeout 60 "$repo/assets/cluster/submit-montecarlo.sh" 4 --cpus-per-task="$cpus" --time=00:05:00) ||
  fail "submit-montecarlo.sh failed"
[[ $array =~ ^[0-9]+$ && $merge =~ ^[0-9]+$ ]] || fail "submit-montecarlo.sh printed no job ids"
state=$(wait_job_end "$merge")
[[ $state == COMPLETED ]] || fail "wrapper: merge job $merge ended $state"
[[ -f mc/all.json ]] || fail "wrapper: merge completed without mc/all.json"
same_statistics ../whole.json mc/all.json || fail "wrapper: merged statistics differ from the unsharded run"
shards_ran_on mc "$cpus" || fail "wrapper: the shards did not run on the $cpus CPUs given by --cpus-per-task"
say "ok: submit-montecarlo.sh 4 --cpus-per-task=$cpus (jobs $array, $merge): merge equals the unsharded run (wall_s, threads aside), each shard on $cpus threads, in $(($(date +%s) - t)) s"

# 2. The sbatch commands by hand, as docs/cluster.md gives them (3 shards, logs in the submission dir).
cd "$tmp/work" && mkdir by-hand && cd by-hand
t=$(date +%s)
jid=$(sl sbatch --parsable --array=0-2 --export=ALL,RUNS="$runs" "$repo/assets/cluster/montecarlo.slurm")
merge=$(sl sbatch --parsable --dependency=afterok:"$jid" "$repo/assets/cluster/montecarlo-merge.slurm")
state=$(wait_job_end "$merge")
[[ $state == COMPLETED ]] || fail "by hand: merge job $merge ended $state"
same_statistics ../whole.json mc/all.json || fail "by hand: merged statistics differ from the unsharded run"
[[ -f rinscope-mc-${jid}_0.log && -f rinscope-mc-merge-$merge.log ]] || fail "by hand: the job logs are not in the submission directory"
shards_ran_on mc 1 || fail "by hand: the shards did not run on the 1 CPU the job file asks for"
say "ok: sbatch --array=0-2 + --dependency=afterok (jobs $jid, $merge): merge equals the unsharded run, each shard on 1 thread, in $(($(date +%s) - t)) s"

# 3. A shard fails: the merge must be cancelled, not left pending forever.
cd "$tmp/work" && mkdir failing && cd failing
t=$(date +%s)
read -r array merge < <(RUNS=0 timeout 60 "$repo/assets/cluster/submit-montecarlo.sh" 2) || fail "submit-montecarlo.sh failed"
state=$(wait_job_end "$merge")
[[ $state == CANCELLED ]] || fail "failing shard: merge job $merge ended $state, not CANCELLED"
[[ ! -e mc/all.json ]] || fail "failing shard: a merge was written"
grep -qE -- "--runs 0|'0' for '--runs" mc/slurm-"${array}"_0.log || fail "failing shard: the shard's log does not say why it failed"
say "ok: a failing shard (RUNS=0) cancels the merge (DependencyNeverSatisfied + kill-on-invalid-dep) in $(($(date +%s) - t)) s"

# 4. The self-calibration's Monte Carlo as an array (selfcal-montecarlo.slurm) and its merge as a
#    dependent job: the unsharded statistics, wall time aside.
cd "$tmp/work" && mkdir selfcal && cd selfcal
t=$(date +%s)
"$bin" selfcal --monte-carlo 2 --no-recording --navigate-hours 0 --json whole.json >whole.log 2>&1 ||
  { cat whole.log >&2; fail "selfcal: the unsharded run failed"; }
jid=$(sl sbatch --parsable --array=0-1 --export=ALL,RUNS=2 "$repo/assets/cluster/selfcal-montecarlo.slurm")
merge=$(sl sbatch --parsable --dependency=afterok:"$jid" --kill-on-invalid-dep=yes --output=merge.log \
  --wrap "\"$bin\" selfcal --merge sc/shard-0.json sc/shard-1.json --json sc/all.json")
state=$(wait_job_end "$merge")
[[ $state == COMPLETED ]] || { cat merge.log rinscope-selfcal-mc-*.log >&2 || true; fail "selfcal: merge job $merge ended $state"; }
python3 - whole.json sc/all.json <<'PY' || fail "selfcal: merged statistics differ from the unsharded run"
import json, sys
a, b = (json.load(open(p))["monte_carlo"] for p in sys.argv[1:3])
for v in (a, b):
    v.pop("wall_s", None)
sys.exit(0 if a == b else 1)
PY
say "ok: selfcal-montecarlo.slurm --array=0-1 + a dependent merge (jobs $jid, $merge): the unsharded statistics, in $(($(date +%s) - t)) s"

# 5. A parameter sweep as an array (sweep.slurm) and its merge as a dependent job: every run's
#    statistics as in the unsharded sweep.
cd "$tmp/work" && mkdir sweep-job && cd sweep-job
t=$(date +%s)
vary='turntable.axis[1].swing_half_angle_arcsec=0,300,600'
"$bin" sweep --vary "$vary" --seeds 2 --duration-s 30 --json whole.json >whole.log 2>&1 ||
  { cat whole.log >&2; fail "sweep: the unsharded run failed"; }
# (VARY holds commas, which --export=NAME=VALUE would split: it goes through the environment.)
jid=$(VARY="$vary" SEEDS=2 SWEEP_ARGS="--duration-s 30" sl sbatch --parsable --array=0-2 --export=ALL "$repo/assets/cluster/sweep.slurm")
merge=$(sl sbatch --parsable --dependency=afterok:"$jid" --kill-on-invalid-dep=yes --output=merge.log \
  --wrap "\"$bin\" sweep --merge sweep/shard-0.json sweep/shard-1.json sweep/shard-2.json --json sweep/all.json")
state=$(wait_job_end "$merge")
[[ $state == COMPLETED ]] || { cat merge.log rinscope-sweep-*.log >&2 || true; fail "sweep: merge job $merge ended $state"; }
python3 - whole.json sweep/all.json <<'PY' || fail "sweep: merged run statistics differ from the unsharded sweep"
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:3])
keep = ("attitude_error_arcsec", "ins_attitude_error_arcsec", "navigation", "steps", "seed")
pick = lambda r: [(p["index"], p["values"], {k: p["summary"].get(k) for k in keep}) for p in r["points"]]
sys.exit(0 if pick(a) == pick(b) and len(a["points"]) == 6 else 1)
PY
say "ok: sweep.slurm --array=0-2 + a dependent merge (jobs $jid, $merge): every run as in the unsharded sweep, in $(($(date +%s) - t)) s"

passed=1
