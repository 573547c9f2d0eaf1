#!/usr/bin/env bash
# Checks that no source includes a header from a room above its own. Exit 1 naming each offence.
#   check-rooms.sh massspring [massspring/src]  rooms geometry model fields builders kernels
#                                               solvers (massspring/src/README.md); a private
#                                               header is "room/name.hpp", a bare name its own room's
#   check-rooms.sh compare [compare]            rooms pipeline calibration writers commands
#                                               (docs/architecture.md), in src/<room> and
#                                               include/msfem/compare/<room>
set -euo pipefail
project=${1:?"usage: check-rooms.sh massspring|compare [folder]"}
here_dir="$(dirname "$0")/.."
case $project in
  massspring) root=${2:-"$here_dir/massspring/src"}; rooms=(geometry model fields builders kernels solvers) ;;
  compare) root=${2:-"$here_dir/compare"}; rooms=(pipeline calibration writers commands) ;;
  *) echo "check-rooms: unknown project '$project' (massspring, compare)"; exit 2 ;;
esac
floor() {
  local i
  for i in "${!rooms[@]}"; do [[ ${rooms[$i]} == "$1" ]] && { echo "$i"; return; }; done
  echo -1
}
# The rooms a file includes from, one line each, "room<TAB>header".
included_rooms() {
  local file=$1 room=$2 included
  if [[ $project == compare ]]; then
    sed -n 's|^#include "\(msfem/compare/\([^/]*\)/.*\)".*|\2\t\1|p' "$file"
    return
  fi
  while IFS= read -r included; do
    if [[ $included == */* ]]; then printf '%s\t%s\n' "${included%%/*}" "$included"; else printf '%s\t%s\n' "$room" "$included"; fi
  done < <(sed -n 's/^#include "\([^"]*\)".*/\1/p' "$file" | grep -v '^msfem/')
}
status=0
for room in "${rooms[@]}"; do
  here=$(floor "$room")
  if [[ $project == massspring ]]; then dirs=("$root/$room"); else dirs=("$root/src/$room" "$root/include/msfem/compare/$room"); fi
  [[ $project == compare || -d ${dirs[0]} ]] || { echo "check-rooms: room $room missing in $root"; status=1; continue; }
  for dir in "${dirs[@]}"; do
    [[ -d $dir ]] || continue
    while IFS= read -r file; do
      relative=${file#"$root"/}
      while IFS=$'\t' read -r other included; do
        there=$(floor "$other")
        if [[ $there -gt $here ]]; then
          echo "check-rooms: $relative ($room) includes $included from $other, a room above"
          status=1
        elif [[ $there -lt 0 || ( $project == massspring && ! -f "$root/$other/${included##*/}" ) ]]; then
          echo "check-rooms: $relative includes $included, which is in no room"
          status=1
        fi
      done < <(included_rooms "$file" "$room")
    done < <(find "$dir" -type f \( -name '*.cpp' -o -name '*.hpp' -o -name '*.inc' \))
  done
done
# massspring: every source is in a room.
if [[ $project == massspring ]]; then
  while IFS= read -r file; do
    relative=${file#"$root"/}
    [[ $(floor "${relative%%/*}") -ge 0 ]] || { echo "check-rooms: $relative is in no room"; status=1; }
  done < <(find "$root" -mindepth 1 -type f \( -name '*.cpp' -o -name '*.hpp' -o -name '*.inc' \))
fi
exit $status
