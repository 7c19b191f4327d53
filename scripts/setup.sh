#!/usr/bin/env bash
# tomorig set-up in one command. On a fresh Debian 12 machine, as root (or with sudo):
#   bash scripts/setup.sh run    install what is missing, build (Release), run the default rig
#   bash scripts/setup.sh test   install what is missing, build (Release), run the test suite, then
#                                the untrusted-input library suites again under ASan + UBSan
#                                (second tree, scripts/test-sanitized.sh)
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

# The dashboard's browser test (tests/browser/) runs Playwright from npm against Debian's
# Chromium: `npm ci` installs exactly the versions in its package-lock.json, again only when
# the lock file changed since.
install_browser_test_packages() {
  local dir="$root/tests/browser"
  if ! command -v npm >/dev/null; then
    echo "setup: npm not found: install Node.js 20 with npm for the dashboard's browser test" >&2; exit 1
  fi
  if [[ ! -d "$dir/node_modules/playwright-core" || "$dir/package-lock.json" -nt "$dir/node_modules/.package-lock.json" ]]; then
    echo "setup: installing the browser test's npm packages (tests/browser/package-lock.json)"
    (cd "$dir" && npm ci --no-audit --no-fund --loglevel=error)
  fi
}

build() {
  echo "setup: configuring and building in $build_dir (Release)"
  cmake -S "$root" -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build "$build_dir" -j "$jobs"
}

install_missing_packages
if [[ $mode == test ]]; then install_browser_test_packages; fi
build

case "$mode" in
  run)
    shift
    exec "$build_dir/apps/tomorig" run "$@"
    ;;
  test)
    # Both halves run even when the first fails (one CI run shows every failure); either failing
    # fails the command. The sanitizer half builds its own tree (build-sanitize): what it covers
    # and how long it takes is in docs/reliability.md, "Sanitizers".
    status=0
    (cd "$build_dir" && ctest --output-on-failure -j "$jobs" --timeout 600) || status=$?
    bash "$root/scripts/test-sanitized.sh" || status=$?
    if ((status != 0)); then echo "setup: tests failed (exit $status)" >&2; fi
    exit "$status"
    ;;
  build) ;;
esac
