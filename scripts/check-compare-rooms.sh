#!/usr/bin/env bash
# Checks that no file of compare includes a header from a room above its own: pipeline, then
# calibration, then writers, then commands (docs/architecture.md). Exit 1 naming each offence.
set -euo pipefail
compare=${1:-"$(dirname "$0")/../compare"}
rooms=(pipeline calibration writers commands)
floor() {
  local i
  for i in "${!rooms[@]}"; do [[ ${rooms[$i]} == "$1" ]] && { echo "$i"; return; }; done
  echo -1
}
status=0
for room in "${rooms[@]}"; do
  here=$(floor "$room")
  for dir in "$compare/src/$room" "$compare/include/msfem/compare/$room"; do
    [[ -d $dir ]] || continue
    while IFS= read -r file; do
      while IFS= read -r other; do
        there=$(floor "$other")
        if [[ $there -lt 0 ]]; then
          echo "check-compare-rooms: ${file#"$compare"/} includes from $other, which is no room"
          status=1
        elif [[ $there -gt $here ]]; then
          echo "check-compare-rooms: ${file#"$compare"/} ($room) includes from $other, a room above"
          status=1
        fi
      done < <(sed -n 's|^#include "msfem/compare/\([^/]*\)/.*|\1|p' "$file")
    done < <(find "$dir" -type f \( -name '*.cpp' -o -name '*.hpp' \))
  done
done
exit $status
