#!/usr/bin/env bash
# Try the Slurm scripts for real on this machine: install a single-node
# Slurm from the package registry (slurmctld and slurmd on localhost, munge),
# submit a small study as 4 shards plus the merge through submit.sh, wait,
# and check that the merged result equals a single-process run. Needs root
# and apt; stops the daemons it started. One command:
#
#   deploy/slurm/local-test.sh
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
here=$repo/deploy/slurm
start=$(date +%s)
if ! command -v slurmctld > /dev/null; then
  apt-get install -y slurm-wlm munge > /dev/null
fi
mkdir -p /etc/slurm /var/spool/slurmctld /var/spool/slurmd /run/munge
host=$(hostname -s)
mem=$(awk '/MemTotal/ { print int($2 / 1024 * 0.8) }' /proc/meminfo)
cat > /etc/slurm/slurm.conf <<CONF
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
chown munge:munge /run/munge /var/log/munge /var/lib/munge
[ -f /etc/munge/munge.key ] || (mungekey --create > /dev/null 2>&1 || /usr/sbin/create-munge-key -f > /dev/null)
pgrep -x munged > /dev/null || runuser -u munge -- munged
pgrep -x slurmctld > /dev/null || slurmctld
pgrep -x slurmd > /dev/null || slurmd
stop() { pkill -x slurmd || true; pkill -x slurmctld || true; }
trap stop EXIT
for _ in $(seq 30); do
  sinfo -h -o %T 2> /dev/null | grep -q idle && break
  sleep 1
done
sinfo

(cd "$repo" && cargo build --quiet)
export STUDY_BIN=$repo/target/debug/study
work=$(mktemp -d)
sed 's/^samples = .*/samples = 20/' "$repo/studies/three_balls.toml" > "$work/small.toml"
cd "$work"
"$STUDY_BIN" run small.toml --quiet --threads 1
mv results/small whole
ids=$("$here/submit.sh" small.toml 4 1)
echo "$ids"
merge_id=${ids##* }
while squeue -h -j "$merge_id" 2> /dev/null | grep -q .; do sleep 2; done
cat slurm-*.out
if [ ! -f results/small/runs.parquet ]; then
  echo "the merge job wrote no results/small/runs.parquet" >&2
  exit 1
fi
if [ ! -d "$here/.venv" ]; then
  python3 -m venv "$here/.venv"
  "$here/.venv/bin/pip" install --quiet -r "$here/requirements.txt"
fi
"$here/.venv/bin/python" "$here/compare_results.py" whole results/small
echo "local Slurm test passed in $(( $(date +%s) - start )) s"
