#!/usr/bin/env bash
# Try the Slurm scripts for real on this machine: install a single-node
# Slurm from the package registry (slurmctld and slurmd on localhost, munge),
# submit a small study as 4 shards plus the merge through submit.sh, wait,
# and check that the merged result equals a single-process run. Needs root
# and apt. One command:
#
#   deploy/slurm/local-test.sh
#   deploy/slurm/local-test.sh --fail-shard
#
# The wait ends as soon as the merge job completes or any job fails or is
# cancelled (exit 1, naming the jobs and their states, after their logs).
# --fail-shard proves that path: shard 2's folder is made to hold another
# study, so its task fails (`--resume` refuses the folder, exit 2); Slurm
# must then cancel the merge job (submit.sh's --kill-on-invalid-dep=yes)
# and the script exits 1 within seconds. It exits 3 instead if the merge
# job was left pending or anything else went otherwise.
#
# Daemons it starts (munged, slurmctld, slurmd, also any an install of the
# packages started) it stops on exit, by their pids; daemons that were
# already running are used and left alone. It writes /etc/slurm/slurm.conf
# only when it starts both Slurm daemons, and puts the former file back (or
# none) on exit. Its temporary folder is removed on every exit.
set -euo pipefail
usage() { sed -n '2,23p' "$0" >&2; exit 2; }
fail_shard=
case $# in
  0) ;;
  1) if [ "$1" = --fail-shard ]; then fail_shard=2; else usage; fi ;;
  *) usage ;;
esac
repo=$(cd "$(dirname "$0")/../.." && pwd)
here=$repo/deploy/slurm
start=$(date +%s)
work=$(mktemp -d)
pids=()       # daemons this script started ...
names=()      # ... and their names, in start order
jobs=         # the job ids it submitted, comma-separated
conf=/etc/slurm/slurm.conf
conf_saved=   # set when it wrote slurm.conf: "absent" or a copy of the former
step() { echo "== $* ($(( $(date +%s) - start )) s)"; }

cleanup() {
  local status=$? i
  set +e
  if [ -n "$jobs" ]; then
    # Cancel what is left of its jobs and let them end, so that no job step
    # outlives slurmd.
    scancel "${array_id}" "${merge_id}" 2> /dev/null
    for _ in $(seq 30); do
      squeue -h -j "$jobs" 2> /dev/null | grep -q . || break
      sleep 1
    done
  fi
  for (( i = ${#pids[@]} - 1; i >= 0; i-- )); do
    if kill "${pids[i]}" 2> /dev/null; then
      # Its own children are reaped with wait; the others polled.
      wait "${pids[i]}" 2> /dev/null
      while kill -0 "${pids[i]}" 2> /dev/null; do sleep 0.2; done
      echo "stopped ${names[i]} (pid ${pids[i]}), which this script started"
    fi
  done
  case $conf_saved in
    "") ;;
    absent) rm -f "$conf" ;;
    *) mv "$conf_saved" "$conf" ;;
  esac
  cd /
  rm -rf "$work"
  exit "$status"
}
trap cleanup EXIT

daemons="munged slurmctld slurmd"
daemon_pids() { for d in $daemons; do pgrep -x "$d" || true; done; }
running_before=$(daemon_pids | tr '\n' ' ')
if ! command -v slurmctld > /dev/null || ! command -v munged > /dev/null; then
  step "installing slurm-wlm and munge"
  apt-get update > /dev/null
  apt-get install -y slurm-wlm munge > /dev/null
  # Daemons the packages' scripts started are this script's to stop.
  for pid in $(daemon_pids); do
    case " $running_before " in
      *" $pid "*) ;;
      *) pids+=("$pid"); names+=("$(ps -o comm= -p "$pid")") ;;
    esac
  done
fi
# Starts a daemon in the foreground, in the background of this script.
start_daemon() {
  local name=$1
  shift
  "$@" > "$work/$name.log" 2>&1 &
  pids+=("$!")
  names+=("$name")
}

mkdir -p /etc/slurm /var/spool/slurmctld /var/spool/slurmd /run/munge
chown munge:munge /run/munge /var/log/munge /var/lib/munge
[ -f /etc/munge/munge.key ] || (mungekey --create > /dev/null 2>&1 || /usr/sbin/create-munge-key -f > /dev/null)
if ! pgrep -x munged > /dev/null; then
  start_daemon munged setpriv --reuid=munge --regid=munge --init-groups -- munged --foreground
  for _ in $(seq 20); do
    munge -n 2> /dev/null | unmunge > /dev/null 2>&1 && break
    sleep 0.5
  done
fi
if ! pgrep -x slurmctld > /dev/null && ! pgrep -x slurmd > /dev/null; then
  if [ -f "$conf" ]; then
    cp -p "$conf" "$work/slurm.conf.saved"
    conf_saved=$work/slurm.conf.saved
  else
    conf_saved=absent
  fi
  host=$(hostname -s)
  mem=$(awk '/MemTotal/ { print int($2 / 1024 * 0.8) }' /proc/meminfo)
  cat > "$conf" <<CONF
ClusterName=local
SlurmctldHost=$host
SlurmUser=root
AuthType=auth/munge
StateSaveLocation=/var/spool/slurmctld
SlurmdSpoolDir=/var/spool/slurmd
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
NodeName=$host CPUs=$(nproc) RealMemory=$mem State=UNKNOWN
PartitionName=main Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
fi
pgrep -x slurmctld > /dev/null || start_daemon slurmctld slurmctld -D
pgrep -x slurmd > /dev/null || start_daemon slurmd slurmd -D
for _ in $(seq 30); do
  sinfo -h -o %T 2> /dev/null | grep -q idle && break
  sleep 1
done
sinfo || true
if ! sinfo -h -o %T 2> /dev/null | grep -q idle; then
  echo "no idle Slurm node after 30 s" >&2
  tail -n 20 "$work"/*.log >&2 || true
  exit 1
fi

step "debug build of study (cargo build)"
build_start=$(date +%s)
(cd "$repo" && cargo build --quiet --bin study)
build_s=$(( $(date +%s) - build_start ))
target=${CARGO_TARGET_DIR:-target}
case $target in /*) ;; *) target=$repo/$target ;; esac
export STUDY_BIN=$target/debug/study
sed 's/^samples = .*/samples = 20/' "$repo/studies/three_balls.toml" > "$work/small.toml"
cd "$work"
if [ -z "$fail_shard" ]; then
  step "the study in one process"
  "$STUDY_BIN" run small.toml --quiet --threads 1
  mv results/small whole
else
  # Shard 2's folder holds another study: `--resume` refuses it (exit 2).
  mkdir -p results/small/shard-$fail_shard-of-4
  echo '# another study' > results/small/shard-$fail_shard-of-4/study.toml
fi

step "4 shards and the merge through submit.sh"
submitted=$(date +%s)
ids=$("$here/submit.sh" small.toml 4 1)
echo "$ids"
array_id=$(awk '{ print $3 }' <<< "$ids")
merge_id=${ids##* }
jobs=$array_id,$merge_id

# Wait until the merge job completes, or until any job fails or is
# cancelled. A failed shard makes Slurm cancel the merge job at once; should
# the merge stay pending anyway, the wait gives up 30 s after the failure.
ended='^(FAILED|CANCELLED|TIMEOUT|NODE_FAIL|OUT_OF_MEMORY|BOOT_FAIL|DEADLINE|PREEMPTED|REVOKED|SPECIAL_EXIT)$'
timeout=${SLURM_TEST_TIMEOUT:-600}
outcome=
failed_at=
while [ -z "$outcome" ]; do
  merge_state=$(squeue -h -t all -j "$merge_id" -o %T 2> /dev/null || true)
  bad_shards=$(squeue -h -t all -j "$array_id" -o '%i %T' 2> /dev/null \
    | awk -v re="$ended" '$2 ~ re { printf "%s%s %s", sep, $1, $2; sep = ", " }' || true)
  now=$(date +%s)
  if [ "$merge_state" = COMPLETED ]; then
    outcome=completed
  elif [[ $merge_state =~ $ended ]]; then
    outcome=failed
  elif [ -z "$merge_state" ]; then
    outcome=lost
  elif [ -n "$bad_shards" ]; then
    failed_at=${failed_at:-$now}
    if (( now - failed_at >= 30 )); then outcome=pending; fi
  fi
  if [ -z "$outcome" ] && (( now - submitted >= timeout )); then outcome=timeout; fi
  [ -n "$outcome" ] || sleep 1
done
waited=$(( $(date +%s) - submitted ))
cat slurm-*.out 2> /dev/null || true
echo "jobs:"
squeue -h -t all -j "$jobs" -o '  %i %j %T %r' 2> /dev/null || true

if [ "$outcome" != completed ]; then
  merge_reason=$(squeue -h -t all -j "$merge_id" -o %r 2> /dev/null || true)
  case $outcome in
    failed) why="merge job $merge_id ${merge_state} (${merge_reason})" ;;
    pending) why="merge job $merge_id still ${merge_state} (${merge_reason}) 30 s after the failure: Slurm did not cancel it" ;;
    lost) why="merge job $merge_id is no longer known to Slurm" ;;
    timeout) why="merge job $merge_id still ${merge_state} after ${timeout} s (SLURM_TEST_TIMEOUT)" ;;
  esac
  echo "FAILED after ${waited} s of waiting: failed shards: ${bad_shards:-none}; ${why}." >&2
  if [ -n "$fail_shard" ]; then
    if [ "$outcome" = failed ] && [ "$merge_state" = CANCELLED ] \
      && [[ $bad_shards == *"_$fail_shard FAILED"* ]]; then
      echo "--fail-shard: as intended, shard $fail_shard failed, Slurm cancelled the merge job and the wait ended ${waited} s after submission; exit 1 ($(( $(date +%s) - start )) s in all)" >&2
      exit 1
    fi
    echo "--fail-shard: NOT as intended (expected shard $fail_shard FAILED and the merge job CANCELLED)" >&2
    exit 3
  fi
  exit 1
fi
if [ -n "$fail_shard" ]; then
  echo "--fail-shard: NOT as intended: the merge job completed although shard $fail_shard should have failed" >&2
  exit 3
fi
if [ ! -f results/small/runs.parquet ]; then
  echo "the merge job wrote no results/small/runs.parquet" >&2
  exit 1
fi
if [ ! -d "$here/.venv" ]; then
  python3 -m venv "$here/.venv"
  "$here/.venv/bin/pip" install --quiet -r "$here/requirements.txt"
fi
"$here/.venv/bin/python" "$here/compare_results.py" whole results/small
echo "local Slurm test passed in $(( $(date +%s) - start )) s (of which the cargo build ${build_s} s; the Slurm jobs ${waited} s from submission to the merge's end)"
