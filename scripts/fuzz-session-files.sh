#!/usr/bin/env bash
# Damaged session files through the tomorig binary (issue 14, docs/reliability.md): a small
# session written by `simulate` and a live recording killed mid-run (its "<name>.partial", HDF5
# SWMR), damaged by deterministic single-bit flips and truncations, each read by the commands
# below with a 10 s limit:
#   inspect --json                       open and summarize (what every command does first)
#   inspect --png --set 1                read the frames of a set
#   preprocess                           read every set and write a new session
#   replay (into a tomorig record)       read and stream every set
#   reconstruct --grid 32,24,16          a small reconstruction of set 0
#   process --grid 32,24,16 --sets 1     reconstruction and correlation into a results file
# Every run must exit 0 or 2: a signal, a timeout or another exit code is counted as a failure
# and its file is kept in the work folder. Counts only, no timings: safe on a loaded machine.
#
#   scripts/fuzz-session-files.sh [TOMORIG] [FLIPS] [TRUNCATIONS] [all|rotate]
#   defaults: build/apps/tomorig 1000 200 all (FLIPS and TRUNCATIONS per file). `rotate` runs
#   one command per damaged file, in turn (the ctest FuzzSessionFilesCli runs 20 + 8 that way).
set -uo pipefail

tomorig=$(realpath "${1:-build/apps/tomorig}")
flips=${2:-1000}
truncations=${3:-200}
mode=${4:-all}
work=$(mktemp -d "${TMPDIR:-/tmp}/tomorig-fuzz-XXXXXX")
echo "work folder: $work"
cd "$work" || exit 1

# Four 32 x 24 cameras: the default rig's structure, files of about 100-200 KiB, mostly metadata.
# Pixels 16 times the default's pitch keep the default's field of view, so the images hold the
# default's particles (at its pitch a 32 x 24 corner sees none) and an undamaged file
# reconstructs and correlates: reconstruct and process then read past the checks.
"$tomorig" config default |
  sed -E 's/width = 512/width = 32/; s/height = 512/height = 24/; s/pixel_pitch_um = 7.4( |$)/pixel_pitch_um = 118.4\1/' > rig.toml
printf '[[preprocess.steps]]\nkind = "subtract_minimum"\n' > chain.toml
"$tomorig" simulate --sets 2 --config rig.toml -o simulate.h5 > /dev/null 2>&1 || { echo "simulate failed"; exit 1; }
# The undamaged file must go all the way through, or the fuzz below would only test refusals.
"$tomorig" reconstruct simulate.h5 --calib truth --grid 32,24,16,0.2 --set 0 --threads 1 -o vol.h5 > /dev/null 2>&1 &&
  "$tomorig" process simulate.h5 --calib truth --grid 32,24,16,0.2 --window 8,8,8 --sets 1 --threads 1 -o res.h5 \
    > /dev/null 2>&1 || { echo "the undamaged session does not reconstruct and process"; exit 1; }
rm -f vol.h5 vol.xdmf res.h5 res.xdmf

# A live recording killed (SIGKILL) once it holds at least 3 durable sets.
"$tomorig" run --sets 100000 --status none --config rig.toml -o live.h5 > /dev/null 2>&1 &
runner=$!
for ((i = 0; i < 600; i++)); do
  sets=$("$tomorig" inspect --json live.h5.partial 2> /dev/null | grep -o '"sets": *[0-9]*' | tail -1 | grep -o '[0-9]*$')
  if [[ -n "$sets" ]] && ((sets >= 3)); then break; fi
  sleep 0.1
done
kill -KILL "$runner" 2> /dev/null
wait "$runner" 2> /dev/null
[[ -f live.h5.partial ]] || { echo "the killed run left no live.h5.partial"; exit 1; }
mv live.h5.partial live.partial.h5
rm -f live.h5.lock

declare -A tally
failures=0
runs=0

# Runs one command on damaged.h5 and counts how it ended.
check() {
  local label=$1
  shift
  runs=$((runs + 1))
  timeout --signal=KILL 10 "$tomorig" "$@" > /dev/null 2> err.txt
  last_code=$?
  tally_code "$label" "$last_code" "$*"
}

tally_code() {
  local label=$1 code=$2 what=$3
  case $code in
    0) tally[ok]=$((${tally[ok]:-0} + 1)) ;;
    2) tally[refused]=$((${tally[refused]:-0} + 1)) ;;
    137) tally[timeout]=$((${tally[timeout]:-0} + 1)) ;;
    *) if ((code > 128)); then tally[signal]=$((${tally[signal]:-0} + 1)); else tally[other]=$((${tally[other]:-0} + 1)); fi ;;
  esac
  if ((code != 0 && code != 2)); then
    failures=$((failures + 1))
    cp damaged.h5 "failure-$failures.h5"
    echo "FAIL ($code): $label: tomorig $what: $(head -c 300 err.txt)"
  fi
}

# replay into a recorder bound on an ipc path; the recorder ends with the session end, or is
# stopped when replay refused the file.
replay_into_record() {
  local label=$1
  rm -rf rec.h5 rec.h5.partial rec.h5.lock
  timeout --signal=KILL 20 "$tomorig" record --bind --from "ipc://$work/sink" -o rec.h5 --idle-timeout 10 \
    > /dev/null 2> record-err.txt &
  local recorder=$!
  check "$label" replay damaged.h5 --connect --to "ipc://$work/sink" --rate max --timeout 5 --wait 5
  local stopped=0
  if ((last_code != 0)); then kill -INT "$recorder" 2> /dev/null; stopped=1; fi
  wait "$recorder" 2> /dev/null
  local rcode=$?
  # The recorder may fail (exit 1: no set arrived, or sets missing), never crash or hang. A
  # SIGINT sent before it installed its handler ends it with 130: that one is ours.
  if ((rcode > 2 && !(stopped && rcode == 130))); then
    failures=$((failures + 1)); cp damaged.h5 "failure-$failures.h5"
    echo "FAIL (record $rcode): $label: $(head -c 300 record-err.txt)"
  fi
}

command_number=0
run_command() {
  local label=$1 k=$2
  rm -rf png out.h5 out.h5.partial out.h5.lock vol.h5 vol.xdmf vol.h5.lock res.h5 res.h5.partial res.h5.lock res.xdmf
  case $k in
    0) check "$label" inspect --json damaged.h5 ;;
    1) check "$label" inspect damaged.h5 --png png --set 1 ;;
    2) check "$label" preprocess damaged.h5 --chain chain.toml -o out.h5 ;;
    3) replay_into_record "$label" ;;
    4) check "$label" reconstruct damaged.h5 --calib truth --grid 32,24,16,0.2 --set 0 --threads 1 -o vol.h5 ;;
    5) check "$label" process damaged.h5 --calib truth --grid 32,24,16,0.2 --window 8,8,8 --sets 1 \
         --threads 1 -o res.h5 ;;
  esac
}
kCommands=6

# One line per 100 damaged files, so that a long run shows where it is.
damaged_files=0
progress() {
  damaged_files=$((damaged_files + 1))
  ((damaged_files % 100 == 0)) || return 0
  echo "$damaged_files damaged files, $runs runs: ok ${tally[ok]:-0}, refused ${tally[refused]:-0}, signal ${tally[signal]:-0}, timeout ${tally[timeout]:-0}, other ${tally[other]:-0}"
}

read_all() {
  if [[ $mode == rotate ]]; then
    run_command "$1" $((command_number % kCommands))
    command_number=$((command_number + 1))
  else
    for ((k = 0; k < kCommands; k++)); do run_command "$1" "$k"; done
  fi
  progress
}

# Byte `offset` of damaged.h5 with bit `bit` flipped.
flip() {
  local offset=$1 bit=$2 byte
  byte=$(od -An -tu1 -j "$offset" -N1 damaged.h5 | tr -d ' ')
  printf "$(printf '\\%03o' $((byte ^ (1 << bit))))" | dd of=damaged.h5 bs=1 seek="$offset" conv=notrunc status=none
}

for source in simulate.h5 live.partial.h5; do
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

echo "sessions: simulate.h5 $(stat -c %s simulate.h5) bytes, live.partial.h5 (a killed run) $(stat -c %s live.partial.h5) bytes"
echo "$((flips * 2)) bit flips and $((truncations * 2)) truncations, mode $mode: $runs runs"
for key in ok refused signal timeout other; do echo "  $key: ${tally[$key]:-0}"; done
if ((failures > 0)); then
  echo "FAILED: $failures runs ended otherwise than 0 or 2 (files kept in $work)"
  exit 1
fi
rm -rf "$work"
echo "every run exited 0 or 2"
