#!/usr/bin/env bash
# Installs every Debian package facet needs to build, test, benchmark and run.
# Idempotent: packages already installed are skipped, and `apt-get update` runs at most once,
# only when something is missing. This is the project's only install step.
set -euo pipefail

packages=(
  # toolchain
  build-essential cmake ninja-build ccache pkg-config git
  clang clang-format clang-tidy libclang-rt-14-dev
  # algorithms
  libopencv-dev libopencv-contrib-dev libeigen3-dev libnanoflann-dev
  # camera
  libopenimageio-dev openimageio-tools libaravis-dev aravis-tools-cli libusb-1.0-0-dev zlib1g-dev libpng-dev libjpeg-dev libtiff-dev
  libv4l-dev
  # plc, config, service
  libmodbus-dev libyaml-cpp-dev libcli11-dev libspdlog-dev libfmt-dev libsqlite3-dev sqlite3
  libcpp-httplib-dev libssl-dev libsystemd-dev nlohmann-json3-dev
  # results to a fleet: MQTT (libmosquitto) and PostgreSQL (libpq); broker and server for tests
  libmosquitto-dev mosquitto libpq-dev postgresql
  # the tests make a throw-away certificate authority for the broker's TLS listener
  openssl
  # tests and benchmarks
  libgtest-dev libgmock-dev googletest libbenchmark-dev
  python3-pymodbus python3-serial python3-serial-asyncio python3-numpy python3-opencv mbpoll
  python3-jsonschema python3-yaml
  # photographs for bench_registration (examples/data of the OpenCV documentation)
  opencv-doc
  # browser checks of the dashboard and report
  chromium chromium-driver
  # media helpers (image conversions in tests)
  imagemagick
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -q
$SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
