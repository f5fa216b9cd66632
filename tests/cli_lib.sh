# Shell helpers shared by the tests/cli_*.sh scripts (sourced, not run).
# json_num FILE KEY: the number of a top-level key of a metrics.json, or nothing.
json_num() { sed -n "s/^ *\"$2\": \([-0-9.e+]*\),\{0,1\}$/\1/p" "$1" | head -1; }
