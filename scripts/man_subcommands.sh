#!/usr/bin/env bash
# Writes a help2man include file with a SUBCOMMANDS section holding every
# subcommand's --help (its options and defaults), so monomap(1) documents
# them all.   scripts/man_subcommands.sh MONOMAP_BINARY OUT_FILE
set -euo pipefail
bin=$1
out=$2
subs=$("$bin" --help | awk '/^Subcommands:/ {f = 1; next} f && /^  [a-z]/ {print $1}')
{
  echo "[SUBCOMMANDS]"
  for s in $subs; do
    echo ".SS $s"
    echo ".nf"
    # roff: escape backslashes, protect lines starting with . or '.
    "$bin" "$s" --help | sed -e "s|Usage: [^ ]*monomap|Usage: monomap|" -e 's/\\/\\e/g' -e "s/^\([.']\)/\\\\\&\1/"
    echo ".fi"
  done
} > "$out.tmp"
mv "$out.tmp" "$out"
