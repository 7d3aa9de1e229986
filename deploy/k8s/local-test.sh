#!/usr/bin/env bash
# Run the documented Kubernetes commands as written, on a machine with no
# cluster: the command block of docs/running-at-scale.md's "Kubernetes
# Indexed Job" section is taken from the doc at test time and run with bash,
# unchanged, in a copy of deploy/k8s, with deploy/k8s/kubectl-stand-in.py
# first on PATH as `kubectl`. The stand-in plays the cluster with podman:
# the claim is a host folder (fsGroup applied as the kubelet does), each Job
# is played by a background controller that runs the manifests' pods
# (image, command, args, runAsUser, fsGroup, mounts, completions,
# parallelism, JOB_COMPLETION_INDEX, backoffLimitPerIndex, maxFailedIndexes,
# backoffLimit: all read from the manifests; resource requests ignored).
# No API server or Job controller of Kubernetes runs: the stand-in follows
# their documented semantics. The image is the local localhost/autobal (the
# manifests' registry.example.org/autobal:latest maps to it); when absent it
# is built with deploy/container/build-prebuilt.sh (cargo). Needs root and
# podman (installed with runc from apt when missing) and PyYAML
# (python3-yaml, likewise). One command:
#
#   deploy/k8s/local-test.sh
#   deploy/k8s/local-test.sh --fail-shard
#
# Without options the block must exit 0 and the merged results on the
# volume must equal a one-process run of the same study in the same image,
# every column but the per-run wall time, and belong to the pods' uid.
# --fail-shard makes shard 2's folder on the volume hold another study
# before the block runs, so its pods fail (`--resume` refuses it, exit 2);
# then wait-job.sh must report the Job failed naming index 1 within seconds
# of the failure, the merge Job must never be applied, and no shard pod may
# be left running. The shipped study's other shards end before that, so the
# block runs a second time with a study 200 times as large (a copy on the
# volume; only its path changed in the args): the other 7 shard pods must
# then be stopped by the Job's failure, study saving its runs (exit 130).
# If all that held the script exits 1 (as deploy/slurm/local-test.sh
# --fail-shard does), otherwise 3. K8S_TEST_TIMEOUT (default 1800 s) bounds
# each run of the block. Containers it starts are named
# autobal-k8s-test-PID-…; they and its temporary folder are removed on exit.
set -euo pipefail
usage() { sed -n '2,36p' "$0" >&2; exit 2; }
fail_shard=
case $# in
  0) ;;
  1) if [ "$1" = --fail-shard ]; then fail_shard=2; else usage; fi ;;
  *) usage ;;
esac
repo=$(cd "$(dirname "$0")/../.." && pwd)
here=$repo/deploy/k8s
start=$(date +%s)
work=$(mktemp -d)
prefix=autobal-k8s-test-$$
intended=
step() { echo "== $* ($(( $(date +%s) - start )) s)"; }

# shellcheck disable=SC2317 # run by the EXIT trap
cleanup() {
  local status=$? pidfile pid names
  set +e
  # With --fail-shard, exit 1 means "as intended": any other end is 3.
  if [ -n "$fail_shard" ] && [ "$status" -eq 1 ] && [ -z "$intended" ]; then
    status=3
  fi
  # The stand-in's controllers (started detached) stop their pods on SIGTERM.
  for pidfile in "$work"/*/cluster/jobs/*/controller.pid; do
    [ -f "$pidfile" ] || continue
    pid=$(cat "$pidfile")
    if grep -qs _controller "/proc/$pid/cmdline"; then
      kill "$pid" 2> /dev/null
      while kill -0 "$pid" 2> /dev/null; do sleep 0.2; done
    fi
  done
  names=$(podman ps -a --filter "name=^$prefix-" --format '{{.Names}}' 2> /dev/null)
  if [ -n "$names" ]; then
    # shellcheck disable=SC2086 # one name a word
    podman rm -f -t 0 $names > /dev/null 2>&1
    # shellcheck disable=SC2086 # the names on one line
    echo "removed containers:" $names
  fi
  cd /
  rm -rf "$work"
  exit "$status"
}
trap cleanup EXIT

for tool in podman runc; do
  if ! command -v "$tool" > /dev/null; then
    apt-get update > /dev/null
    apt-get install -y podman runc > /dev/null
    break
  fi
done
if ! python3 -c 'import yaml' 2> /dev/null; then
  apt-get update > /dev/null
  apt-get install -y python3-yaml > /dev/null
fi
# runc instead of crun, which fails on these machines (see the file).
export CONTAINERS_CONF=$repo/deploy/container/runc.conf
image=localhost/autobal
if ! podman image exists "$image"; then
  step "no image $image: building it with deploy/container/build-prebuilt.sh"
  base=()
  # deploy/container/local-test.sh makes this base image where no registry
  # can be reached.
  if podman image exists localhost/debian-bookworm-min:local; then
    base=(--build-arg BASE_IMAGE=localhost/debian-bookworm-min:local)
  fi
  "$repo/deploy/container/build-prebuilt.sh" -t autobal "${base[@]}"
fi
podman run --rm "$image" --version

# The names the check needs, from the manifests.
read -r claim shards merge completions per_index < <(python3 - "$here" <<'PY'
import sys, yaml
d = sys.argv[1]
load = lambda f: yaml.safe_load(open(f"{d}/{f}"))
pvc, shards, merge = load("results-pvc.yaml"), load("shards-job.yaml"), load("merge-job.yaml")
print(pvc["metadata"]["name"], shards["metadata"]["name"], merge["metadata"]["name"],
      shards["spec"]["completions"], shards["spec"]["backoffLimitPerIndex"])
PY
)

step "the command block of the doc's \"Kubernetes Indexed Job\" section"
awk '
  /^## / { section = ($0 == "## Kubernetes Indexed Job") }
  section && /^```sh$/ { inside = 1; blocks++; next }
  inside && /^```$/ { inside = 0; next }
  inside { print }
  END { if (blocks != 1) { print "expected one sh block, found " blocks > "/dev/stderr"; exit 1 } }
' "$repo/docs/running-at-scale.md" > "$work/block.sh"
sed 's/^/  /' "$work/block.sh"
mkdir -p "$work/bin"
ln -s "$here/kubectl-stand-in.py" "$work/bin/kubectl"
export KUBECTL_STANDIN_IMAGES=registry.example.org/autobal:latest=$image
results=results/balls_vs_rollers

# run_block PART: the block in $work/PART/run (a copy of deploy/k8s), the
# stand-in's cluster in $work/PART/cluster; sets status, block_end, block_s.
run_block() {
  export KUBECTL_STANDIN_STATE=$work/$1/cluster KUBECTL_STANDIN_PREFIX=$prefix-$1
  step "running the block (bash, in a copy of deploy/k8s, the stand-in kubectl first on PATH)"
  local block_start=$EPOCHREALTIME
  status=0
  (cd "$work/$1/run" && PATH=$work/bin:$PATH timeout "${K8S_TEST_TIMEOUT:-1800}" bash "$work/block.sh") \
    2>&1 | tee "$work/$1/block.log" || status=${PIPESTATUS[0]}
  block_end=$EPOCHREALTIME
  block_s=$(awk -v a="$block_start" -v b="$block_end" 'BEGIN { printf "%.1f", b - a }')
  step "the block ended with exit $status after $block_s s"
  PATH=$work/bin:$PATH kubectl get pods -l job-name="$shards" || true
  PATH=$work/bin:$PATH kubectl get pods -l job-name="$merge" 2> /dev/null || true
  echo "(*: stopped by the Job controller)"
  echo "last lines of the pods' logs:"
  PATH=$work/bin:$PATH kubectl logs -l job-name="$shards" --prefix \
    | grep -E 'finished:|wrote|rror|refus|nterrupt|stopp|saved' | tail -n 16 || true
  PATH=$work/bin:$PATH kubectl logs -l job-name="$merge" --prefix 2> /dev/null | tail -n 3 || true
}
# new_part PART: a fresh copy of deploy/k8s and a fresh cluster (volume).
new_part() {
  mkdir -p "$work/$1/run/deploy" "$work/$1/cluster/volumes"
  cp -r "$here" "$work/$1/run/deploy/k8s"
  volume=$work/$1/cluster/volumes/$claim
}

if [ -z "$fail_shard" ]; then
  new_part ok
  step "the same study in one process, in the same image"
  mkdir "$work/whole"
  podman run --rm --name "$prefix-whole" -v "$work/whole:/work" "$image" \
    run /opt/autobal/studies/balls_vs_rollers.toml --quiet > "$work/whole.log"
  run_block ok
  if [ "$status" -ne 0 ]; then
    echo "FAILED: the documented block exited $status" >&2
    exit 1
  fi
  test -s "$volume/$results/runs.parquet"
  test -s "$volume/$results/summary.parquet"
  # runAsUser: every file the pods wrote belongs to the pods' uid.
  uid=$(python3 -c 'import sys, yaml; print(yaml.safe_load(open(sys.argv[1]))["spec"]["template"]["spec"]["securityContext"]["runAsUser"])' "$here/shards-job.yaml")
  if [ -n "$(find "$volume/results" ! -user "$uid")" ]; then
    echo "files on the volume not owned by uid $uid:" >&2
    find "$volume/results" ! -user "$uid" -exec ls -lnd {} + >&2
    exit 1
  fi
  echo "every file under the volume's results/ belongs to uid $uid"
  ls -ln "$volume/$results"
  venv=$repo/deploy/slurm
  if [ ! -d "$venv/.venv" ]; then
    python3 -m venv "$venv/.venv"
    "$venv/.venv/bin/pip" install --quiet -r "$venv/requirements.txt"
  fi
  "$venv/.venv/bin/python" "$venv/compare_results.py" "$work/whole/$results" "$volume/$results"
  echo "local Kubernetes test passed in $(( $(date +%s) - start )) s (the documented block $block_s s: $completions shards, the merge and the waits)"
  exit 0
fi

# --fail-shard. check_failed PART STUDY: the block ended, wait-job.sh named
# the failed index, the merge Job was never applied, index fail_shard - 1
# failed 1 + backoffLimitPerIndex times with exit 2, no shard pod is left
# running. Sets facts (KEY=VALUE lines) and appends to problems.
problems=()
index=$((fail_shard - 1))
fact() { sed -n "s/^$1=//p" <<< "$facts"; }
check_failed() {
  local state=$work/$1/cluster live
  facts=$(python3 - "$state/jobs/$shards/job.json" "$index" <<'PY'
import json, sys
job = json.load(open(sys.argv[1]))
index = int(sys.argv[2])
conds = {c["type"]: c for c in job["status"]["conditions"]}
pods = job["pods"]
failed_pods = [p for p in pods if p["index"] == index and p["phase"] == "Failed"]
stopped = [p for p in pods if p.get("stoppedByController")]
print("conditions=" + ",".join(conds))
print("failed_indexes=" + job["status"].get("failedIndexes", ""))
print(f"index_exit2={len([p for p in failed_pods if p.get('exitCode') == 2])}")
print(f"stopped={len(stopped)}")
print("stopped_exit=" + ",".join(sorted({str(p['exitCode']) for p in stopped})))
print(f"succeeded_pods={len([p for p in pods if p['phase'] == 'Succeeded'])}")
print(f"running={len([p for p in pods if p['phase'] == 'Running'])}")
print(f"first_failure={min((p['ended'] for p in failed_pods), default=0):.3f}")
print(f"failure_target={conds.get('FailureTarget', {}).get('at', 0):.3f}")
print(f"failed_at={conds.get('Failed', {}).get('at', 0):.3f}")
PY
  )
  # shellcheck disable=SC2001 # a prefix on every line
  sed 's/^/  /' <<< "$facts"
  [ "$status" -ne 124 ] || problems+=("$1: the block did not end within ${K8S_TEST_TIMEOUT:-1800} s")
  [ "$status" -eq 124 ] || [ "$status" -eq 1 ] \
    || problems+=("$1: the block exited $status, not 1 (wait-job.sh's answer for a failed Job)")
  grep -q "job/$shards failed (failed indexes: $index)" "$work/$1/block.log" \
    || problems+=("$1: wait-job.sh did not report job/$shards failed with index $index")
  if grep -q "apply -f .*merge-job.yaml" "$state/calls.log" || [ -d "$state/jobs/$merge" ]; then
    problems+=("$1: the merge Job was applied")
  fi
  [ "$(fact failed_indexes)" = "$index" ] || problems+=("$1: failedIndexes is '$(fact failed_indexes)', not $index")
  [[ ,$(fact conditions), == *,Failed,* ]] || problems+=("$1: job/$shards is not Failed")
  [ "$(fact index_exit2)" = $((per_index + 1)) ] \
    || problems+=("$1: index $index: $(fact index_exit2) pods exited 2, not 1 + backoffLimitPerIndex = $((per_index + 1))")
  live=$(podman ps --filter "name=^$prefix-$1-$shards-" --format '{{.Names}}')
  if [ -n "$live" ] || [ "$(fact running)" != 0 ]; then
    problems+=("$1: shard pods still running: $live")
  fi
  after_target=$(awk -v a="$(fact failure_target)" -v b="$block_end" 'BEGIN { printf "%.1f", b - a }')
  after_first=$(awk -v a="$(fact first_failure)" -v b="$block_end" 'BEGIN { printf "%.1f", b - a }')
  stop_s=$(awk -v a="$(fact failure_target)" -v b="$(fact failed_at)" 'BEGIN { printf "%.1f", b - a }')
}

new_part fail
# The claim already holds a folder for shard 2 with another study in it:
# `--resume` refuses it (exit 2), on every retry.
mkdir -p "$volume/$results/shard-$fail_shard-of-$completions"
echo '# another study' > "$volume/$results/shard-$fail_shard-of-$completions/study.toml"
run_block fail
check_failed fail
report1="the documented manifests: index $index (shard $fail_shard) failed $((per_index + 1)) times (exit 2; retried as a new pod $per_index times, after the 10 s and 20 s back-off), the Job failed with failedIndexes $index, wait-job.sh said so and the merge Job was never applied; the other $(fact succeeded_pods) shards had already succeeded ($(fact stopped) pods to stop); the block ended $after_target s after the Job's failure was decided (the last retry failed), $after_first s after the first failure, $block_s s after it started (exit $status)"

# The shipped study's shards end in seconds, before the failed index has
# used up its retries, so the run above stops no pod. Again with a study
# 200 times as large (samples 100 -> 20000, a copy on the volume; the
# manifest's args with only the study's path changed), so that the other
# shards are still running when the Job fails and must be stopped: study
# saves what it has on SIGTERM and exits 130.
step "again, with shards still running when the Job fails (a larger study)"
new_part running
mkdir -p "$volume"
sed 's/^samples = .*/samples = 20000/' "$repo/studies/balls_vs_rollers.toml" > "$volume/balls_vs_rollers.toml"
python3 - "$here/shards-job.yaml" "$work/running/run/deploy/k8s/shards-job.yaml" <<'PY'
import sys, yaml
text = open(sys.argv[1]).read()
job = yaml.safe_load(text)
container = job["spec"]["template"]["spec"]["containers"][0]
old = "/opt/autobal/studies/balls_vs_rollers.toml"
assert old in container["args"][0], container["args"]
container["args"][0] = container["args"][0].replace(old, "balls_vs_rollers.toml")
yaml.safe_dump(job, open(sys.argv[2], "w"), sort_keys=False)
print("args:", container["args"][0])
PY
mkdir -p "$volume/$results/shard-$fail_shard-of-$completions"
echo '# another study' > "$volume/$results/shard-$fail_shard-of-$completions/study.toml"
run_block running
check_failed running
if [ "$(fact stopped)" != $((completions - 1)) ] || [ "$(fact stopped_exit)" != 130 ]; then
  problems+=("running: $(fact stopped) pods stopped (exit codes $(fact stopped_exit)), not the other $((completions - 1)) with exit 130")
fi
report2="With a larger study: the same, and the other $(fact stopped) shard pods were stopped (SIGTERM; study saved its runs and exited 130) in $stop_s s between FailureTarget and Failed; the block ended $after_target s after the failure was decided, $block_s s after it started (exit $status)"

if [ ${#problems[@]} -gt 0 ]; then
  printf -- '--fail-shard: NOT as intended: %s\n' "${problems[@]}" >&2
  exit 3
fi
echo "--fail-shard: as intended. With $report1. $report2. Exit 1 ($(( $(date +%s) - start )) s in all)" >&2
intended=yes
exit 1
