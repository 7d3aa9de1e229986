#!/usr/bin/env bash
# Wait until a Kubernetes Job is complete or has failed, whichever comes
# first (`kubectl wait --for=condition=complete` alone waits out its whole
# timeout when the Job fails):
#
#   deploy/k8s/wait-job.sh JOB [TIMEOUT]     (TIMEOUT as kubectl's, default 24h)
#
# Exits 0 when the Job is complete; 1 when it failed (printing its failed
# indexes and where the logs are); 2 on a timeout or when kubectl cannot
# wait (no such Job, no cluster). Extra kubectl options, e.g. a namespace,
# through KUBECTL_ARGS="-n batch".
set -euo pipefail
if [ $# -lt 1 ] || [ $# -gt 2 ]; then
  sed -n '2,11p' "$0" >&2
  exit 2
fi
job=$1
timeout=${2:-24h}
read -r -a extra <<< "${KUBECTL_ARGS:-}"
kubectl "${extra[@]}" wait --for=condition=complete --timeout="$timeout" "job/$job" > /dev/null &
complete=$!
kubectl "${extra[@]}" wait --for=condition=failed --timeout="$timeout" "job/$job" > /dev/null &
failed=$!
trap 'kill "$complete" "$failed" 2> /dev/null || true' EXIT
# The first of the two to end decides (bash 5.1: wait -n -p).
status=0
wait -n -p first "$complete" "$failed" || status=$?
if [ "$status" -eq 0 ] && [ "$first" = "$complete" ]; then
  echo "job/$job is complete"
  exit 0
fi
if [ "$status" -eq 0 ] && [ "$first" = "$failed" ]; then
  indexes=$(kubectl "${extra[@]}" get "job/$job" -o jsonpath='{.status.failedIndexes}' 2> /dev/null || true)
  echo "job/$job failed${indexes:+ (failed indexes: $indexes)}; logs: kubectl logs -l job-name=$job --prefix" >&2
  exit 1
fi
echo "job/$job: neither complete nor failed (kubectl wait exited $status: a timeout after $timeout, or no such job)" >&2
exit 2
