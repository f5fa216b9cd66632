#!/usr/bin/env bash
# tools/check-function-length.sh on a fixture of tricky constructs (member brace initialisers,
# lambdas in initialiser lists, raw strings, braces in literals and comments, digit
# separators, default arguments `= {}`): every function found with its exact length, and the
# exit status for each limit. Usage: function_length_heuristic.sh SOURCE_DIR
set -euo pipefail
src="${1:?usage: function_length_heuristic.sh SOURCE_DIR}"
check="$src/tools/check-function-length.sh"
cd "$src/tests/data/function-length"
fail() { echo "function_length_heuristic: $*" >&2; exit 1; }

rc=0; got=$("$check" --max 0 sample.cpp 2>/dev/null) || rc=$?
[[ $rc == 1 ]] || fail "--max 0: exit status $rc, expected 1"
diff -u expected.txt <(echo "$got") || fail "functions found differ from expected.txt"

# The longest function (auto f, 9 lines) is the only one over 8 and none is over 9.
rc=0; got=$("$check" --max 8 sample.cpp 2>/dev/null) || rc=$?
[[ $rc == 1 && "$got" == "sample.cpp:16: function body is 9 lines (limit 8): auto f(int a) -> int" ]] ||
  fail "--max 8: exit status $rc, output '$got'"
rc=0; got=$("$check" --max 9 sample.cpp 2>/dev/null) || rc=$?
[[ $rc == 0 && -z "$got" ]] || fail "--max 9: exit status $rc, output '$got'"
# --report lists without failing.
rc=0; got=$("$check" --max 8 --report sample.cpp 2>/dev/null) || rc=$?
[[ $rc == 0 && "$got" == *"sample.cpp:16: function body is 9 lines"* ]] || fail "--report: exit status $rc, output '$got'"
echo "function_length_heuristic: 7 functions, lengths and exit statuses as expected"
