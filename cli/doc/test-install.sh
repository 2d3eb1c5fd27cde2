#!/usr/bin/env bash
# test-install.sh BUILD_DIR: `cmake --install` into a temporary prefix installs bin/pvs, the man
# page (which names every subcommand of `pvs --help`) and the bash completion, and the completion
# offers the subcommands and a subcommand's options.
set -euo pipefail
build=$1
prefix=$(mktemp -d)
trap 'rm -rf "$prefix"' EXIT
cmake --install "$build" --prefix "$prefix" > /dev/null
pvs="$prefix/bin/pvs"
man1="$prefix/share/man/man1/pvs.1"
comp="$prefix/share/bash-completion/completions/pvs"
for f in "$pvs" "$man1" "$comp"; do
  [ -s "$f" ] || { echo "not installed: $f"; exit 1; }
done
cmds=$("$pvs" --help | awk '/^Subcommands:/{on=1; next} on && /^  [a-z]/{print $1}')
[ -n "$cmds" ] || { echo "no subcommands in pvs --help"; exit 1; }
for c in $cmds; do
  grep -q "pvs $c" "$man1" || { echo "man page lacks subcommand $c"; exit 1; }
done
# shellcheck source=/dev/null
source "$comp"
COMP_WORDS=("$pvs" ba); COMP_CWORD=1; _pvs
[ "${COMPREPLY[*]}" = "bake" ] || { echo "completion of 'ba': '${COMPREPLY[*]}'"; exit 1; }
COMP_WORDS=("$pvs" bake --outp); COMP_CWORD=2; _pvs
[ "${COMPREPLY[*]}" = "--output" ] || { echo "completion of 'bake --outp': '${COMPREPLY[*]}'"; exit 1; }
echo "installed and completes: $(echo $cmds | wc -w) subcommands"
