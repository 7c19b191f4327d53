#!/usr/bin/env bash
# Damaged session files through the tomorig binary (issue 14, docs/reliability.md): small
# sessions written by `simulate` (in one go) and `run` (live, SWMR), damaged by deterministic
# single-bit flips and truncations, each read by three commands with a 10 s limit:
#   inspect --json           open and summarize (what every command does first)
#   inspect --png --set 1    read the frames of a set
#   preprocess               read every set and write a new session
# Every run must exit 0 or 2: a signal, a timeout or another exit code is counted as a failure
# and its file is kept in the work folder. Counts only, no timings: safe on a loaded machine.
#
#   scripts/fuzz-session-files.sh [TOMORIG] [FLIPS] [TRUNCATIONS]
#   (defaults: build/apps/tomorig 1000 200; about one run per command and damaged file)
set -uo pipefail

tomorig=$(realpath "${1:-build/apps/tomorig}")
flips=${2:-1000}
truncations=${3:-200}
work=$(mktemp -d "${TMPDIR:-/tmp}/tomorig-fuzz-XXXXXX")
echo "work folder: $work"
cd "$work" || exit 1

# Four 32 x 24 cameras: the default rig's structure, files of about 100 KiB, mostly metadata.
"$tomorig" config default | sed 's/width = 512/width = 32/; s/height = 512/height = 24/' > rig.toml
printf '[[preprocess.steps]]\nkind = "subtract_minimum"\n' > chain.toml
"$tomorig" simulate --sets 2 --config rig.toml -o simulate.h5 > /dev/null 2>&1 || { echo "simulate failed"; exit 1; }
"$tomorig" run --sets 2 --pace max --status none --config rig.toml -o run.h5 > /dev/null 2>&1 || { echo "run failed"; exit 1; }

declare -A tally
failures=0

# Runs one command on damaged.h5 and counts how it ended.
check() {
  local label=$1
  shift
  rm -rf png out.h5 out.h5.partial out.h5.lock
  timeout --signal=KILL 10 "$tomorig" "$@" > /dev/null 2> err.txt
  local code=$?
  case $code in
    0) tally[ok]=$((${tally[ok]:-0} + 1)) ;;
    2) tally[refused]=$((${tally[refused]:-0} + 1)) ;;
    137) tally[timeout]=$((${tally[timeout]:-0} + 1)) ;;
    *) if ((code > 128)); then tally[signal]=$((${tally[signal]:-0} + 1)); else tally[other]=$((${tally[other]:-0} + 1)); fi ;;
  esac
  if ((code != 0 && code != 2)); then
    failures=$((failures + 1))
    cp damaged.h5 "failure-$failures.h5"
    echo "FAIL ($code): $label: tomorig $*: $(head -c 300 err.txt)"
  fi
}

read_all() {
  check "$1" inspect --json damaged.h5
  check "$1" inspect damaged.h5 --png png --set 1
  check "$1" preprocess --session damaged.h5 --chain chain.toml -o out.h5
}

# Byte `offset` of damaged.h5 with bit `bit` flipped.
flip() {
  local offset=$1 bit=$2 byte
  byte=$(od -An -tu1 -j "$offset" -N1 damaged.h5 | tr -d ' ')
  printf "$(printf '\\%03o' $((byte ^ (1 << bit))))" | dd of=damaged.h5 bs=1 seek="$offset" conv=notrunc status=none
}

for source in simulate.h5 run.h5; do
  size=$(stat -c %s "$source")
  RANDOM=7  # deterministic offsets
  for ((k = 0; k < flips; k++)); do
    offset=$(((RANDOM * 32768 + RANDOM) % size))
    bit=$((RANDOM % 8))
    cp "$source" damaged.h5
    flip "$offset" "$bit"
    read_all "$source: bit $bit of byte $offset"
  done
  for ((k = 0; k < truncations; k++)); do
    length=$(((RANDOM * 32768 + RANDOM) % size))
    head -c "$length" "$source" > damaged.h5
    read_all "$source: truncated to $length bytes"
  done
done

runs=$(((flips + truncations) * 2 * 3))
echo "sessions: simulate.h5 $(stat -c %s simulate.h5) bytes, run.h5 $(stat -c %s run.h5) bytes"
echo "$((flips * 2)) bit flips and $((truncations * 2)) truncations, 3 commands each: $runs runs"
for key in ok refused signal timeout other; do echo "  $key: ${tally[$key]:-0}"; done
if ((failures > 0)); then
  echo "FAILED: $failures runs ended otherwise than 0 or 2 (files kept in $work)"
  exit 1
fi
rm -rf "$work"
echo "every run exited 0 or 2"
