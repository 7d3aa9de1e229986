#!/usr/bin/env bash
# Build the Containerfile's `prebuilt` image (the runtime stage with a binary
# built on this machine), for machines that cannot pull the toolchain image:
# runs the build stage's command on the host, strips a copy of the binary
# into a small temporary build context with the shipped studies, scenes and
# the entrypoint (the repository's own context leaves target/ out), and
# builds from it. Options go to `podman build`, e.g.
#
#   deploy/container/build-prebuilt.sh -t autobal
#   deploy/container/build-prebuilt.sh -t autobal --build-arg BASE_IMAGE=localhost/debian-bookworm-min:local
#
# Needs cargo, strip (binutils) and podman (or PODMAN=docker).
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
stage=$(mktemp -d)
trap 'rm -rf "$stage"' EXIT

(cd "$repo" && cargo build --release --locked --bin study)
target=${CARGO_TARGET_DIR:-target}
case $target in /*) ;; *) target=$repo/$target ;; esac
# Stripped: the release profile keeps line tables, 300+ MB; stripped, 30 MB.
strip -o "$stage/study" "$target/release/study"
chmod 755 "$stage/study"
cp -r "$repo/studies" "$repo/scenes" "$stage/"
mkdir -p "$stage/deploy/container"
cp "$repo/deploy/container/entrypoint.sh" "$stage/deploy/container/"
echo "build context: $(du -sh "$stage" | cut -f1) (stripped binary $(du -h "$stage/study" | cut -f1))"
"${PODMAN:-podman}" build --target prebuilt -f "$repo/Containerfile" "$@" "$stage"
