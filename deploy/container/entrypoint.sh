#!/bin/sh
# The image's entrypoint: run `study` as the owner of the working folder, so
# that `podman run --rm -v "$PWD:/work" autobal run …` writes results that
# belong to whoever owns the mounted folder, whoever starts the container:
#
# - rootless podman (a normal user): the user's folder is owned by uid 0 in
#   the container's user namespace, which is the user on the host, so study
#   runs as that (namespaced) root and the files are the user's;
# - rootful podman or docker on a folder a normal user owns (sudo, or docker
#   as a member of the docker group): study drops to that folder's uid:gid;
# - rootful podman or docker as root on root's folder: study runs as root,
#   the caller's own rights.
#
# A container started as a non-root uid (`--user`, Kubernetes' runAsUser)
# runs study directly: nothing in the image needs a particular uid (HOME is
# /tmp; /work, the image's own working folder, is writable by every uid).
set -eu
if [ "$(id -u)" = 0 ]; then
  owner=$(stat -c %u .)
  group=$(stat -c %g .)
  if [ "$owner" != 0 ]; then
    exec setpriv --reuid="$owner" --regid="$group" --clear-groups -- study "$@"
  fi
fi
exec study "$@"
