#!/usr/bin/env bash
# Writes docs/CLI.md from the probecast command's own --help: the top level, every command and
# every `bench` subcommand, in the order the binary lists them.
#   bash scripts/cli-reference.sh [BINARY] [OUTPUT]   (defaults: build/probecast, docs/CLI.md)
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BIN=${1:-$ROOT/build/probecast}
OUT=${2:-$ROOT/docs/CLI.md}

if [ ! -x "$BIN" ]; then
  echo "cli-reference: $BIN is not built (bash scripts/dev.sh test builds it)" >&2
  exit 1
fi

# The names listed under "Subcommands:" in a CLI11 help text.
subcommands() {
  awk '/^Subcommands:/ { on = 1; next } on && /^[^ ]/ { on = 0 } on && NF { print $1 }'
}

help_of() {
  # CLI11 exits 0 on --help; keep the text whatever the status, and never let it end the script.
  # The binary's path becomes plain `probecast`; trailing spaces and blank lines go.
  { "$BIN" "$@" --help 2>&1 || true; } |
    sed -e "s|$BIN|probecast|g" -e 's/[[:space:]]*$//' |
    awk 'NF { while (blank > 0) { print ""; blank-- } print; next } { blank++ }'
}

section() {
  local title=$1
  shift
  printf '\n## `probecast %s`\n\n```\n' "$title"
  help_of "$@"
  printf '```\n'
}

tmp=$(mktemp)
trap 'rm -f "$tmp"' EXIT
{
  printf '# probecast command-line reference\n\n'
  printf 'Generated from the command'"'"'s own `--help` by `bash scripts/cli-reference.sh`; do not edit by\n'
  printf 'hand. Regenerate it after changing an option. The [README](../README.md) shows the commands in use.\n'
  printf '\n## `probecast`\n\n```\n'
  help_of
  printf '```\n'
  for cmd in $(help_of | subcommands); do
    section "$cmd" "$cmd"
    if [ "$cmd" = bench ]; then
      for sub in $(help_of bench | subcommands); do
        section "bench $sub" bench "$sub"
      done
    fi
  done
} >"$tmp"
mkdir -p "$(dirname "$OUT")"
mv "$tmp" "$OUT"
trap - EXIT
echo "cli-reference: wrote $OUT"
