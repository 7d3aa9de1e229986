#!/usr/bin/env bash
# Build the container image and run the main job in it on a machine where no
# registry can be reached (so neither the toolchain image nor a Debian image
# can be pulled): the build stage's command runs on the host, the base image
# is made from Debian's packages with mmdebstrap, and podman builds the
# Containerfile's `prebuilt` stage (the runtime stage with that binary).
# Needs root and apt. One command:
#
#   deploy/container/local-test.sh
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
start=$(date +%s)
for tool in podman runc mmdebstrap; do
  command -v "$tool" > /dev/null || apt-get install -y podman runc mmdebstrap > /dev/null
done
work=$(mktemp -d)
# crun fails on these machines (setrlimit, cgroups); runc with no default
# ulimits and the cgroupfs manager works.
cat > "$work/containers.conf" <<'CONF'
[containers]
default_ulimits = []
[engine]
cgroup_manager = "cgroupfs"
CONF
export CONTAINERS_CONF=$work/containers.conf
podman() { command podman --runtime /usr/sbin/runc "$@"; }
base=localhost/debian-bookworm-min:local
if ! podman image exists "$base"; then
  mmdebstrap --variant=minbase bookworm "$work/rootfs.tar" > /dev/null 2>&1
  podman import "$work/rootfs.tar" "$base" > /dev/null
fi

# The build stage's command, on the host (stripped after the build rather
# than by the profile, so that the host's own release build is reused).
(cd "$repo" && cargo build --release --locked --bin study)
target=${CARGO_TARGET_DIR:-$repo/target}
mkdir "$work/context"
cp "$target/release/study" "$work/context/study"
strip "$work/context/study"
cp -r "$repo/studies" "$repo/scenes" "$work/context/"
podman build --target prebuilt --build-arg BASE_IMAGE="$base" \
  --build-arg BINARY=study -f "$repo/Containerfile" -t localhost/autobal:local \
  "$work/context"

# The main job, as the image's non-root user, into a mounted folder.
mkdir "$work/out" && chmod a+rwx "$work/out"
podman run --rm localhost/autobal:local --version
podman run --rm localhost/autobal:local run --help > /dev/null
podman run --rm -v "$work/out:/work" localhost/autobal:local \
  run /opt/autobal/studies/three_balls.toml --quiet | tail -3
podman run --rm --entrypoint id localhost/autobal:local
ls -l "$work/out/results/three_balls"
test -s "$work/out/results/three_balls/summary.parquet"
podman images localhost/autobal:local
echo "container test passed in $(( $(date +%s) - start )) s"
