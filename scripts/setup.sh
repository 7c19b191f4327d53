#!/usr/bin/env bash
# tomorig set-up in one command. On a fresh Debian 12 machine, as root (or with sudo):
#   bash scripts/setup.sh run    install what is missing, build (Release), run the default rig
#   bash scripts/setup.sh test   install what is missing, build (Release), run the test suite, then
#                                the library and CLI suites again under ASan + UBSan (second tree)
# Packages come from scripts/apt-packages.txt, the one list of dependencies.
set -euo pipefail

mode="${1:-}"
case "$mode" in
  run|test|build) ;;
  *) echo "usage: bash scripts/setup.sh run|test|build" >&2; exit 2 ;;
esac

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${TOMORIG_BUILD_DIR:-$root/build}"
jobs="$(nproc 2>/dev/null || echo 2)"

install_missing_packages() {
  mapfile -t wanted < <(grep -v -E '^\s*(#|$)' "$root/scripts/apt-packages.txt")
  local missing=()
  for pkg in "${wanted[@]}"; do
    if ! dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed"; then
      missing+=("$pkg")
    fi
  done
  if ((${#missing[@]} == 0)); then
    echo "setup: all ${#wanted[@]} packages already installed"
    return
  fi
  echo "setup: installing ${#missing[@]} missing packages: ${missing[*]}"
  local sudo=""
  if [[ $(id -u) -ne 0 ]]; then
    if command -v sudo >/dev/null; then sudo="sudo"; else
      echo "setup: need root (or sudo) to install: ${missing[*]}" >&2; exit 1
    fi
  fi
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -qq
  $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
}

build() {
  echo "setup: configuring and building in $build_dir (Release)"
  cmake -S "$root" -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build "$build_dir" -j "$jobs"
}

install_missing_packages
build

case "$mode" in
  run)
    shift
    exec "$build_dir/apps/tomorig" run "$@"
    ;;
  test)
    (cd "$build_dir" && ctest --output-on-failure -j "$jobs" --timeout 600)
    # The same library and CLI suites built with ASan + UBSan (docs/reliability.md, "Sanitizers").
    bash "$root/scripts/test-sanitized.sh"
    ;;
  build) ;;
esac
