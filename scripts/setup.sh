#!/usr/bin/env bash
# Installs what probecast needs on Debian 12 (bookworm), idempotently.
# Fast when nothing is missing: one dpkg query, no network.
set -euo pipefail

PACKAGES=(
  build-essential cmake ninja-build pkg-config ccache
  libzstd-dev libgtest-dev libbenchmark-dev libcli11-dev libspdlog-dev libfmt-dev
  nlohmann-json3-dev libstb-dev libopenexr-dev libglm-dev libtinygltf-dev
  libvulkan-dev vulkan-tools glslang-tools spirv-tools vulkan-validationlayers
  libgrpc++-dev libprotobuf-dev protobuf-compiler protobuf-compiler-grpc
  nats-server libnats-dev
  libglfw3-dev xvfb xauth xdotool libmeshoptimizer-dev
  clang-14 libclang-rt-14-dev openssl libssl-dev strace
  python3-dev python3-numpy python3-pytest python3-matplotlib pybind11-dev python3-venv
  emscripten node-acorn nodejs chromium ffmpeg
)
# npm comes with nodejs where nodejs is not Debian's (NodeSource's): Debian's npm only without one.
command -v npm >/dev/null 2>&1 || PACKAGES+=(npm)
# From bookworm-backports (bookworm has none): scikit-build-core, for `pip install ./python`.
BACKPORTS_PACKAGES=(python3-scikit-build-core)
# Mesa >= 24 from bookworm-backports: lavapipe with ray tracing (see docs/PLATFORM.md).
MESA_MIN=24

sudo_if_needed() {
  if [ "$(id -u)" -eq 0 ]; then "$@"; else sudo "$@"; fi
}

missing_packages() {  # PACKAGE...
  local p
  for p in "$@"; do
    if ! dpkg-query -W -f='${Status}\n' "$p" 2>/dev/null | grep -q '^install ok installed'; then
      echo "$p"
    fi
  done
}

mesa_ok() {
  local v
  v=$(dpkg-query -W -f='${Version}' mesa-vulkan-drivers 2>/dev/null || true)
  [ -n "$v" ] || return 1
  local major=${v%%.*}
  major=${major#*:}
  [ "$major" -ge "$MESA_MIN" ] 2>/dev/null
}

add_backports_source() {
  if grep -rqs 'bookworm-backports' /etc/apt/sources.list /etc/apt/sources.list.d/; then
    return 0
  fi
  # Same archive and key as the machine's Debian source.
  local uri="" key="/usr/share/keyrings/debian-archive-keyring.gpg"
  if [ -f /etc/apt/sources.list.d/debian.sources ]; then
    uri=$(awk '/^URIs:/ && $2 !~ /security/ {print $2; exit}' /etc/apt/sources.list.d/debian.sources)
    local k
    k=$(awk '/^Signed-By:/ {print $2; exit}' /etc/apt/sources.list.d/debian.sources)
    [ -n "$k" ] && key="$k"
  fi
  if [ -z "$uri" ] && [ -f /etc/apt/sources.list ]; then
    uri=$(awk '$1 == "deb" && $0 ~ /bookworm / {for (i = 2; i <= NF; i++) if ($i ~ /^(https?|file):/) {print $i; exit}}' /etc/apt/sources.list)
  fi
  [ -n "$uri" ] || uri="http://deb.debian.org/debian"
  echo "setup: adding bookworm-backports from $uri"
  sudo_if_needed tee /etc/apt/sources.list.d/probecast-backports.sources >/dev/null <<SRC
Types: deb
URIs: $uri
Suites: bookworm-backports
Components: main
Signed-By: $key
SRC
}

main() {
  local missing missing_bpo
  missing=$(missing_packages "${PACKAGES[@]}")
  missing_bpo=$(missing_packages "${BACKPORTS_PACKAGES[@]}")
  if [ -z "$missing" ] && [ -z "$missing_bpo" ] && mesa_ok; then
    return 0
  fi
  export DEBIAN_FRONTEND=noninteractive
  add_backports_source
  local mesa=""
  mesa_ok || mesa="mesa-vulkan-drivers (bookworm-backports)"
  echo "setup: installing:" $missing $mesa ${missing_bpo:+$missing_bpo (bookworm-backports)}
  sudo_if_needed apt-get update -q
  if [ -n "$missing" ]; then
    # shellcheck disable=SC2086
    sudo_if_needed apt-get install -y -q --no-install-recommends $missing
  fi
  if [ -n "$missing_bpo" ]; then
    # shellcheck disable=SC2086
    sudo_if_needed apt-get install -y -q --no-install-recommends -t bookworm-backports $missing_bpo
  fi
  if ! mesa_ok; then
    sudo_if_needed apt-get install -y -q -t bookworm-backports mesa-vulkan-drivers
  fi
}

main "$@"
