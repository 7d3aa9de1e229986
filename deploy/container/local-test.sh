#!/usr/bin/env bash
# Build the container image and run the main job in it with the documented
# command, on a machine where no registry can be reached (so neither the
# toolchain image nor a Debian image can be pulled): the base image is made
# from Debian's packages with mmdebstrap, and deploy/container/build-prebuilt.sh
# builds the Containerfile's `prebuilt` stage from the host's release binary,
# stripped. Then, with the command of docs/running-at-scale.md, unchanged:
#
#   podman run --rm -v "$PWD:/work" autobal run /opt/autobal/studies/three_balls.toml
#
# once in a folder root owns and once in a folder a normal user owns
# (uid 4242; the results must belong to the folder's owner), and compares
# the results with a run of the same binary on the host, every column but
# the per-run wall time. Builds and replaces the image `autobal` (the
# documented name). Needs root and apt. One command:
#
#   deploy/container/local-test.sh
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
start=$(date +%s)
work=$(mktemp -d)
trap 'cd /; rm -rf "$work"' EXIT
step() { echo "== $* ($(( $(date +%s) - start )) s)"; }

for tool in podman runc mmdebstrap strip; do
  if ! command -v "$tool" > /dev/null; then
    apt-get update > /dev/null
    apt-get install -y podman runc mmdebstrap binutils > /dev/null
    break
  fi
done
# runc instead of crun, which fails on these machines (see the file).
export CONTAINERS_CONF=$repo/deploy/container/runc.conf
base=localhost/debian-bookworm-min:local
if ! podman image exists "$base"; then
  step "making the base image $base with mmdebstrap"
  mmdebstrap --variant=minbase bookworm "$work/rootfs.tar" > /dev/null 2>&1
  podman import "$work/rootfs.tar" "$base" > /dev/null
  rm "$work/rootfs.tar"
fi

step "release build on the host and the prebuilt image"
former=$(podman image inspect --format '{{.Id}}' autobal 2> /dev/null || true)
"$repo/deploy/container/build-prebuilt.sh" -t autobal --build-arg BASE_IMAGE="$base"
step "image built"
# The image this one replaced (now untagged), unless something still uses it.
if [ -n "$former" ] && [ "$former" != "$(podman image inspect --format '{{.Id}}' autobal)" ]; then
  podman rmi "$former" > /dev/null 2>&1 || true
fi
podman run --rm autobal --version
podman run --rm autobal run --help > /dev/null

# Every file under $1 must belong to uid:gid $2.
owned_by() {
  if [ -n "$(find "$1" ! -user "${2%%:*}" -o ! -group "${2##*:}")" ]; then
    echo "files not owned by $2:" >&2
    find "$1" \( ! -user "${2%%:*}" -o ! -group "${2##*:}" \) -exec ls -lnd {} + >&2
    exit 1
  fi
  echo "every file under $1 belongs to $2"
}

step "the documented command in a folder root owns"
mkdir "$work/root-owned"
cd "$work/root-owned"
podman run --rm -v "$PWD:/work" autobal run /opt/autobal/studies/three_balls.toml
ls -ln results/three_balls
test -s results/three_balls/summary.parquet
owned_by results 0:0

step "the documented command in a folder a normal user (uid 4242) owns"
mkdir "$work/user-owned"
chown 4242:4242 "$work/user-owned"
cd "$work/user-owned"
podman run --rm -v "$PWD:/work" autobal run /opt/autobal/studies/three_balls.toml
ls -ln results/three_balls
owned_by results 4242:4242

step "the same study on the host, one process"
target=${CARGO_TARGET_DIR:-target}
case $target in /*) ;; *) target=$repo/$target ;; esac
mkdir "$work/host"
cd "$work/host"
cp "$repo/studies/three_balls.toml" .
"$target/release/study" run three_balls.toml --quiet
here=$repo/deploy/slurm
if [ ! -d "$here/.venv" ]; then
  python3 -m venv "$here/.venv"
  "$here/.venv/bin/pip" install --quiet -r "$here/requirements.txt"
fi
for folder in root-owned user-owned; do
  "$here/.venv/bin/python" "$here/compare_results.py" results/three_balls \
    "$work/$folder/results/three_balls"
done
podman images autobal
echo "container test passed in $(( $(date +%s) - start )) s"
