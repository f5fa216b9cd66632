#!/usr/bin/env bash
# Lists C++ functions whose body is longer than a limit (the code rule: functions of at most
# ~100 lines, split into named steps) and fails when a library folder has one.
#
# Usage: tools/check-function-length.sh [--max N] [--report DIR]... DIR...
#   DIR          folders whose *.cpp/*.hpp/*.h files are checked: any function over the limit
#                makes the exit status 1
#   --report DIR folders that are only listed (exit status unaffected), e.g. app/src
#   --max N      the limit [lines]; default 100
# Output: one line per function over the limit, `file:line: function body is N lines (limit M):
# head`, where line is the line where the definition starts (its name, or `template`) and head
# is the text before the opening brace, shortened.
# Exit status: 0 none in the checked folders, 1 some, 2 usage error.
#
# Heuristic (a lexer, not a C++ parser), stated so that its numbers can be checked by hand
# (tests/function_length_heuristic.sh runs it on tests/data/function-length/sample.cpp):
# * Comments, string literals (raw strings too), character literals and preprocessor lines
#   (with their continuations) are blanked first; digit separators (1'000) are not quotes.
# * Braces are tracked with a stack of what each one opened. Outside any function body, the
#   text since the previous `;`, `{`, `}` or access label is the head. An opening brace opens
#   a function body when the head has a parenthesised parameter list followed only by
#   qualifiers (const, noexcept, override, final, mutable, volatile, `&`, `&&`), a trailing
#   return type (`-> T`) or a constructor's member initialiser list, and the head is not an
#   `if`/`for`/`while`/`switch`/`catch`/`do`/`else` head. Braces inside an open parenthesis
#   (a default argument `= {}`, a lambda handed to a member initialiser) and a member's brace
#   initialiser in such a list (`: a_{x}`) belong to the head. Any other brace opens a
#   namespace, class, enum or initialiser.
# * Everything between a function body's braces belongs to it: lambdas, local classes and
#   nested blocks count to their enclosing function; member functions defined inside a
#   class body count on their own.
# * Length = line of the closing brace - line of the opening brace + 1, blank and comment
#   lines included (what a reader scrolls through).
set -euo pipefail

max=100
checked=()
reported=()
while (($#)); do
  case "$1" in
    --max) max="${2:?--max needs a number}"; shift 2 ;;
    --report) reported+=("${2:?--report needs a folder}"); shift 2 ;;
    -h|--help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    -*) echo "check-function-length.sh: unknown option $1" >&2; exit 2 ;;
    *) checked+=("$1"); shift ;;
  esac
done
if ((${#checked[@]} == 0 && ${#reported[@]} == 0)); then
  echo "usage: tools/check-function-length.sh [--max N] [--report DIR]... DIR..." >&2
  exit 2
fi
for d in "${checked[@]}" "${reported[@]}"; do
  [[ -e "$d" ]] || { echo "check-function-length.sh: no such file or folder: $d" >&2; exit 2; }
done
[[ "$max" =~ ^[0-9]+$ ]] || { echo "check-function-length.sh: --max expects a number, got '$max'" >&2; exit 2; }

# Prints the functions over the limit in the files named on stdin (one path a line).
scan() {
  local files
  files=$(find "$@" -type f \( -name '*.cpp' -o -name '*.hpp' -o -name '*.h' \) | LC_ALL=C sort)
  [[ -z "$files" ]] && return 0
  # shellcheck disable=SC2086
  awk -v max="$max" -v sq="'" '
  function reset_file() { depth = 0; head = ""; head_line = 0; in_block = 0; in_raw = 0; in_pp = 0; fn_depth = 0; expr_depth = 0 }
  # Blanks comments, literals and preprocessor lines of one line, keeping the state that
  # crosses lines (block comments, raw strings, preprocessor continuations).
  function clean(s,    out, i, n, c, d, j, delim, e, tok) {
    out = ""; n = length(s); i = 1
    if (in_pp) { in_pp = (s ~ /\\$/); return "" }
    if (!in_block && !in_raw && s ~ /^[ \t]*#/) { in_pp = (s ~ /\\$/); return "" }
    while (i <= n) {
      c = substr(s, i, 1)
      if (in_block) {
        e = index(substr(s, i), "*/")
        if (!e) return out
        i += e + 1; in_block = 0; out = out " "; continue
      }
      if (in_raw) {
        e = index(substr(s, i), ")" raw_delim "\"")
        if (!e) return out
        i += e + length(raw_delim) + 1; in_raw = 0; out = out "\"\""; continue
      }
      d = substr(s, i, 2)
      if (d == "//") return out
      if (d == "/*") { in_block = 1; i += 2; continue }
      if (c == "\"") {
        if (i > 1 && substr(s, i - 1, 1) == "R" && (i == 2 || substr(s, i - 2, 1) !~ /[A-Za-z0-9_]/ || substr(s, i - 3, 3) ~ /^(u8R|[uUL]R)$/)) {
          j = index(substr(s, i + 1), "(")
          raw_delim = substr(s, i + 1, j - 1)
          in_raw = 1; i += j + 1; continue
        }
        for (j = i + 1; j <= n; j++) {
          if (substr(s, j, 1) == "\\") { j++; continue }
          if (substr(s, j, 1) == "\"") break
        }
        out = out "\"\""; i = j + 1; continue
      }
      if (c == sq) {
        # A digit separator when the token it sits in starts with a digit.
        tok = out; sub("[^A-Za-z0-9_." sq "]*$", "", tok); tok = substr(out, length(tok) + 1)
        if (tok ~ /^[0-9]/) { out = out c; i++; continue }
        for (j = i + 1; j <= n; j++) {
          if (substr(s, j, 1) == "\\") { j++; continue }
          if (substr(s, j, 1) == sq) break
        }
        out = out sq sq; i = j + 1; continue
      }
      out = out c; i++
    }
    return out
  }
  function trim(s) { sub(/^[ \t]+/, "", s); sub(/[ \t]+$/, "", s); return s }
  # Drops balanced (...) groups so that the text after the parameter list can be checked.
  function strip_parens(s,    t) {
    t = s
    while (gsub(/\([^()]*\)/, "@", t)) {}
    return t
  }
  function is_function(h,    t, u) {
    t = trim(h)
    if (t !~ /\(/) return 0
    if (t ~ /^(if|for|while|switch|catch|do|else)([^A-Za-z0-9_]|$)/) return 0
    u = strip_parens(t)
    if (u ~ /[()]/) return 0
    # Qualifiers after the (last) parameter list, or a trailing return type.
    match(u, /@[^@]*$/)
    u = trim(substr(u, RSTART + 1))
    # The tail after the parameter list: for `f() const noexcept` it is `const noexcept`; for
    # `f() -> std::vector<T>` it is `-> std::vector<T>`.
    if (u ~ /^->/) return 1
    gsub(/(const|noexcept|override|final|mutable|volatile|try|&&|&|@)/, "", u)
    return trim(u) == ""
  }
  # `X::X(int a) : a_{a}, b_(b) {`: a constructor with an initialiser list.
  function has_ctor_init(h) { return strip_parens(trim(h)) ~ /@[ \t]*(noexcept[ \t]*)?:([^:]|$)/ }
  # In such a head, a brace after a member name (`a_{`, `Base<T>{`) initialises that member.
  function is_ctor_init_open(h) { return has_ctor_init(h) && trim(h) ~ /[A-Za-z0-9_>]$/ }
  function check_balance() { if (prev_file != "" && depth != 0 && !warned[prev_file]) print prev_file ": warning: unbalanced {" > "/dev/stderr" }
  FNR == 1 { check_balance(); reset_file() }
  END { check_balance() }
  {
    prev_file = FILENAME
    line = clean($0)
    n = length(line)
    for (i = 1; i <= n; i++) {
      c = substr(line, i, 1)
      if (expr_depth > 0) {
        # Inside braces that are part of a declaration head (see below): skipped whole.
        if (c == "{") { kind[++depth] = "i"; expr_depth++ }
        else if (c == "}") { depth--; if (--expr_depth == 0) head = head "{}" }
        continue
      }
      if (c == "{") {
        if (fn_depth > 0) { kind[++depth] = "b"; continue }
        # A brace inside an open parenthesis (a default argument `= {}`, a lambda passed to a
        # member initialiser) or a member brace initialiser belongs to the head.
        if (strip_parens(head) ~ /\(/ || is_ctor_init_open(head)) { kind[++depth] = "i"; expr_depth = 1; continue }
        if (is_function(head) || has_ctor_init(head)) {
          kind[++depth] = "f"; fn_depth = depth; fn_open = FNR; fn_line = head_line ? head_line : FNR; fn_head = trim(head); fn_file = FILENAME
        } else kind[++depth] = "s"
        head = ""; head_line = 0
      } else if (c == "}") {
        if (depth == 0) { if (!warned[FILENAME]++) print FILENAME ":" FNR ": warning: unbalanced }" > "/dev/stderr"; continue }
        k = kind[depth--]
        if (k == "f") {
          fn_depth = 0
          len = FNR - fn_open + 1
          if (len > max) {
            h = fn_head; gsub(/[ \t]+/, " ", h)
            if (length(h) > 90) h = substr(h, 1, 87) "..."
            printf "%s:%d: function body is %d lines (limit %d): %s\n", fn_file, fn_line, len, max, h
          }
        }
        if (fn_depth == 0) { head = ""; head_line = 0 }
      } else if (c == ";") {
        if (fn_depth == 0) { head = ""; head_line = 0 }
      } else if (fn_depth == 0) {
        if (head_line == 0 && c !~ /[ \t]/) head_line = FNR
        head = head c
        # An access label ends the previous head like a `;` does.
        if (c == ":" && head ~ /^[ \t]*(public|private|protected)[ \t]*:$/ && substr(line, i + 1, 1) != ":") { head = ""; head_line = 0 }
      }
    }
    if (fn_depth == 0) head = head " "
  }' $files
}

status=0
if ((${#checked[@]})); then
  out=$(scan "${checked[@]}")
  if [[ -n "$out" ]]; then
    echo "$out"
    status=1
  fi
fi
if ((${#reported[@]})); then
  out=$(scan "${reported[@]}")
  if [[ -n "$out" ]]; then
    echo "report only (not failing):"
    echo "$out"
  fi
fi
if ((status)); then
  echo "check-function-length.sh: functions over $max lines in ${checked[*]} (split them into named steps)" >&2
fi
exit "$status"
