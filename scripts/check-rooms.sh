#!/usr/bin/env bash
# Checks that no source in massspring/src includes a header from a room above its own
# (massspring/src/README.md gives the rooms, ground floor first). Exit 1 naming each offence.
set -euo pipefail
src=${1:-"$(dirname "$0")/../massspring/src"}
rooms=(geometry model fields builders kernels solvers)
floor() {
  local i
  for i in "${!rooms[@]}"; do [[ ${rooms[$i]} == "$1" ]] && { echo "$i"; return; }; done
  echo -1
}
status=0
for room in "${rooms[@]}"; do
  [[ -d "$src/$room" ]] || { echo "check-rooms: room $room missing in $src"; status=1; continue; }
done
while IFS= read -r file; do
  relative=${file#"$src"/}
  room=${relative%%/*}
  here=$(floor "$room")
  if [[ $here -lt 0 ]]; then
    echo "check-rooms: $relative is in no room"; status=1; continue
  fi
  while IFS= read -r included; do
    other=${included%%/*}
    [[ $included == */* ]] || other=$room  # a bare name is a header of the same room
    there=$(floor "$other")
    if [[ $there -gt $here ]]; then
      echo "check-rooms: $relative ($room) includes $included from $other, a room above"
      status=1
    elif [[ $there -lt 0 || ! -f "$src/$other/${included##*/}" ]]; then
      echo "check-rooms: $relative includes $included, which is in no room"
      status=1
    fi
  done < <(sed -n 's/^#include "\([^"]*\)".*/\1/p' "$file" | grep -v '^msfem/')
done < <(find "$src" -mindepth 1 -type f \( -name '*.cpp' -o -name '*.hpp' -o -name '*.inc' \))
exit $status
