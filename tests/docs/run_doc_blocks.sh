#!/usr/bin/env bash
# The docs test (issue 23): every command block of README.md and docs/*.md fenced as
# ```sh runnable
# runs, in a fresh folder, with the built `tomorig` first on PATH. A block fails if a command
# fails (bash -e, pipefail) or if a `#> TEXT` line under a command names text missing from that
# command's output (stdout and stderr). One command per line (no continuation lines). Blocks of
# one file share a folder, in order, so a later
# block can use what an earlier one wrote.
# usage: run_doc_blocks.sh <tomorig binary> <repository root>
set -uo pipefail
tomorig="$(realpath "$1")"
root="$(realpath "$2")"
bin="$(mktemp -d)"
trap 'rm -rf "$bin"' EXIT
ln -s "$tomorig" "$bin/tomorig"
export PATH="$bin:$PATH"

failures=0 blocks=0
for doc in "$root/README.md" "$root"/docs/*.md; do
  work="$(mktemp -d -p "$bin")"
  # Split the file into runnable blocks: block_<n>.sh, each with its start line.
  awk -v dir="$work" '
    /^```sh runnable[[:space:]]*$/ { n++; inside = 1; file = sprintf("%s/block_%03d.sh", dir, n);
                                     printf "# line %d\n", NR + 1 > file; next }
    inside && /^```[[:space:]]*$/ { inside = 0; close(file); next }
    inside { print >> file }' "$doc"
  for block in "$work"/block_*.sh; do
    [[ -e $block ]] || continue
    blocks=$((blocks + 1))
    where="${doc#$root/}:$(head -1 "$block" | cut -d' ' -f3)"
    # Each command's output goes to a file; each `#> TEXT` checks the last command's output.
    script="$work/run.sh"
    {
      echo 'set -eo pipefail'
      awk '
        /^#> / { text = substr($0, 4); gsub(/\x27/, "\x27\\\x27\x27", text);
                 printf "grep -qF -- \x27%s\x27 \"$out\" || { echo \"expected in the output: %s\"; cat \"$out\"; exit 1; }\n", text, text; next }
        /^#/ || /^[[:space:]]*$/ { next }
        { printf "out=.doc_output; { %s ; } >\"$out\" 2>&1 || { cat \"$out\"; exit 1; }\n", $0 }' "$block"
    } > "$script"
    if (cd "$work" && bash "$script" > "$work/log" 2>&1); then
      echo "ok: $where"
    else
      echo "FAILED: $where"
      sed 's/^/    /' "$work/log"
      failures=$((failures + 1))
    fi
  done
done
echo "$blocks runnable blocks, $failures failed"
[[ $blocks -gt 0 && $failures -eq 0 ]]
