#!/usr/bin/env bash
# The one list of salient's system dependencies (Debian 12). Idempotent: installs only what is
# missing; works as root and uses sudo otherwise.
#   deploy/install-deps.sh          build + test dependencies
#   deploy/install-deps.sh --peers  also the peer tools the benchmarks compare against
set -euo pipefail

build_packages=(
  build-essential cmake ninja-build ccache pkg-config git
  libboost-dev libboost-system-dev libboost-program-options-dev
  nlohmann-json3-dev libcgal-dev libeigen3-dev libspectra-dev libpolyclipping-dev
  libsqlite3-dev libtbb-dev libglpk-dev doctest-dev libspdlog-dev libcli11-dev
  libtomlplusplus-dev zlib1g-dev libpng-dev
  # the spectral saliency's eigensolver: LAPACK's dsyevd through LAPACKE, on OpenBLAS
  liblapacke-dev libopenblas-dev
  # fuzz targets (libFuzzer) and the sanitizer build
  clang libclang-rt-14-dev
  # end-to-end tests speak to the daemon as users do (pgrep/pkill: procps; mount, for the full-disk
  # test on a tmpfs: util-linux)
  curl python3 procps util-linux
  # the plan-format test validates every plan writer's output against docs/plan.schema.json
  python3-jsonschema
  # the judge of our x3g files and of the Replicator profile's moves (GPX; also installs s3gdump)
  gpx
  # `make format-check`, which CI runs: the one formatter version the tree is written with
  clang-format
  # the web page's libraries, served by salientd from /usr/share/javascript (WebGL, charts), and
  # the browser tests: headless Chromium driven by Selenium
  libjs-three libjs-chart.js chromium chromium-driver python3-selenium
  # OctoPrint clients' push socket (/sockjs/websocket) replayed in the client tests
  python3-websocket
  # Zeroconf: salientd announces _octoprint._tcp through Avahi when configured; the test browses
  avahi-daemon avahi-utils libavahi-client-dev
  # the PostgreSQL store backend (salientd --database postgresql://…): libpq to build; the
  # server (15 in Debian 12) for the store tests, which start a temporary cluster on loopback
  libpq-dev postgresql
  # the farm test with nodes whose clocks disagree (libfaketime shifts one node's clock)
  faketime
  # salientd tells systemd it is ready (sd_notify, Type=notify); `make deb` checks the package
  # with lintian and the deploy tests build it with dpkg-deb/dpkg-shlibdeps (dpkg-dev) and read
  # the udev rule with udevadm (udev)
  libsystemd-dev lintian dpkg-dev udev
  # the reverse-proxy test runs deploy/nginx/salient.conf in a real nginx, over TLS with a
  # self-signed certificate made by openssl
  nginx openssl
)
peer_packages=(prusa-slicer cura-engine cura printrun wrk hyperfine)

packages=("${build_packages[@]}")
if [[ "${1:-}" == "--peers" ]]; then packages+=("${peer_packages[@]}"); fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "ok installed"; then
    missing+=("$p")
  fi
done
if ((${#missing[@]} == 0)); then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

as_root=()
if [[ $(id -u) -ne 0 ]]; then as_root=(sudo); fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
"${as_root[@]}" apt-get update -qq
"${as_root[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "install-deps: done"
