#!/usr/bin/env bash
# Verilator --lint-only -Wall on every RTL module (one module per file, top = file name).
# Every rtl/ subfolder is on the search path so instantiated modules resolve. Zero warnings.
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
cd "$top"
mapfile -t files < <(find rtl -name '*.sv' | sort)
if [ ${#files[@]} -eq 0 ]; then
  echo "lint: no RTL modules yet"
  exit 0
fi
dirs=()
while IFS= read -r d; do dirs+=("-y" "$d"); done < <(find rtl -type d | sort)
fail=0
for f in "${files[@]}"; do
  mod=$(basename "$f" .sv)
  # Packages (*_pkg.sv) are linted through the modules that import them.
  case "$mod" in *_pkg) continue ;; esac
  pkgs=$(find rtl -name '*_pkg.sv' | sort)
  if verilator --lint-only -Wall --assert "${dirs[@]}" $pkgs "$f" --top-module "$mod"; then
    echo "lint: $mod clean"
  else
    echo "lint: $mod FAILED"
    fail=1
  fi
done
exit $fail
