#!/usr/bin/env bash
# Installs or upgrades facet on a line computer: builds, installs facetd and facet to
# /usr/local/bin, creates the `facet` system user, installs the systemd unit and an example
# station config (never overwriting an existing one), and restarts facetd if it was running.
# Idempotent: run it again after `git pull` to upgrade. Needs root. Not run by the tests.
#
#   sudo deploy/install.sh              # build in build/release, install, (re)start
#   sudo deploy/install.sh --no-build   # install what build/release already holds
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
build=${FACET_BUILD_DIR:-$root/build/release}
prefix=/usr/local
config_dir=/etc/facet
state_dir=/var/lib/facet
build_first=1
[[ ${1:-} == --no-build ]] && build_first=0

if [[ $(id -u) -ne 0 ]]; then
  echo "install.sh: run as root (it writes $prefix/bin, $config_dir and /etc/systemd/system)" >&2
  exit 1
fi

# 1. Build (as the invoking user's tree; Release, warnings as errors, the two daemon binaries).
if [[ $build_first -eq 1 ]]; then
  bash "$root/deploy/install-deps.sh"
  cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release
  cmake --build "$build" -j"$(nproc)" --target facetd facet
fi
for binary in service/daemon/facetd service/facet camera/libfacet_image_codecs.so \
    camera/libfacet_aravis_camera.so; do
  [[ -x $build/$binary ]] || { echo "install.sh: $build/$binary is missing; build first" >&2; exit 1; }
done

# 2. The user the daemon runs as: no login, no home; video/plugdev for USB cameras.
if ! id facet >/dev/null 2>&1; then
  useradd --system --no-create-home --home-dir "$state_dir" --shell /usr/sbin/nologin facet
fi
for group in video plugdev; do
  getent group "$group" >/dev/null || groupadd --system "$group"
  id -nG facet | grep -qw "$group" || usermod -aG "$group" facet
done

# 3. Binaries: install(1) replaces atomically, so a running facetd keeps its old inode. The
# modules first (image codecs, GigE Vision camera): the binaries load them on first use from
# $prefix/lib/facet.
install -D -m 0644 "$build/camera/libfacet_image_codecs.so" "$prefix/lib/facet/libfacet_image_codecs.so"
install -D -m 0644 "$build/camera/libfacet_aravis_camera.so" "$prefix/lib/facet/libfacet_aravis_camera.so"
install -D -m 0755 "$build/service/daemon/facetd" "$prefix/bin/facetd"
install -D -m 0755 "$build/service/facet" "$prefix/bin/facet"
install -D -m 0644 "$root/deploy/README.md" "$prefix/share/doc/facet/README.md"

# 4. Config and recipes: installed once, then owned by the line (never overwritten).
install -d -m 0755 "$config_dir"
if [[ ! -e $config_dir/station.yaml ]]; then
  cp -r "$root/recipes/." "$config_dir/"
  # The example writes to /tmp; a service keeps its results in its state directory.
  sed -i -e "s#database: /tmp/facet-demo-results.db#database: $state_dir/results.db#" \
         -e "s#folder: /tmp/facet-demo-archive#folder: $state_dir/archive#" "$config_dir/station.yaml"
  echo "install.sh: example station installed in $config_dir; edit camera, PLC and http.token"
fi
install -d -m 0750 -o facet -g facet "$state_dir"

# 5. The unit; restart only if it was running (an upgrade), never start a fresh install blindly.
install -D -m 0644 "$root/deploy/facetd.service" /etc/systemd/system/facetd.service
systemctl daemon-reload
if systemctl is-active --quiet facetd; then
  systemctl restart facetd
  echo "install.sh: facetd upgraded and restarted"
else
  echo "install.sh: installed; start with: systemctl enable --now facetd"
fi
