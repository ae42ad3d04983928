#!/usr/bin/env bash
# tests/check_api.sh - enumerate the public declarations of tiledtex.h and check
# that each follows THE API CONTRACT stated at the top of the header. Prints one
# "ok   api: NAME" or "FAIL api: NAME: why" line per function and per object
# type; tests/run.sh counts them. Plain bash and awk: runs on a fresh machine.
set -u
header=${1:-tiledtex.h}

# One line per declaration: "comment<TAB>declaration", the comment being the
# block of comment lines right above it (shared by consecutive declarations).
decls=$(awk '
  /^#ifndef TILEDTEX_H/ { on = 1 }
  /^#endif \/\* TILEDTEX_H/ { on = 0 }
  !on { next }
  /^\/\*/ { comment = ""; incomment = 1 }
  incomment { comment = comment " " $0; if ($0 ~ /\*\//) incomment = 0; next }
  /^TTDEF/ {
    decl = $0
    while (decl !~ /\);/) { getline line; decl = decl " " line }
    sub(/\);.*/, ");", decl)
    gsub(/[ \t]+/, " ", decl)
    gsub(/\t/, " ", comment)
    print comment "\t" decl
    next
  }
  /^$/ { comment = "" }
' "$header")

# Objects the library allocates: every `T **` output names one, and each has
# exactly one tt_T_free.
objects=$(printf '%s\n' "$decls" | cut -f2 | grep -oE '\btt_[a-z0-9_]+ \*\*' | sed 's/ \*\*//' | sort -u)
frees=$(printf '%s\n' "$decls" | cut -f2 | grep -oE 'void tt_[a-z0-9_]+_free\(' | sed 's/void //; s/($//')

# Functions that return their answer directly and cannot fail by definition.
total_functions=" tt_result_string tt_version tt_srgb_to_linear tt_linear_to_srgb "

while IFS=$'\t' read -r comment decl; do
  [ -n "$decl" ] || continue
  name=$(printf '%s' "$decl" | sed -E 's/^TTDEF [^(]*[ *](tt_[a-z0-9_]+)\(.*/\1/')
  params=$(printf '%s' "$decl" | sed -E 's/^[^(]*\((.*)\);$/\1/')
  last=$(printf '%s' "$params" | awk -F', ' '{ print $NF }')
  why=""
  case "$decl" in
  "TTDEF tt_result "*)
    [ "$last" = "tt_error *error" ] || why="a fallible function must end with tt_error *error (ends with '$last')"
    if [ -z "$why" ] && printf '%s' "$params" | grep -q 'tt_allocator'; then
      # The allocator stands before the outputs: nothing after it is const.
      after=$(printf '%s' "$params" | sed -E 's/.*const tt_allocator \*allocator, //')
      if printf '%s' "$after" | grep -q 'const '; then why="an input stands after the allocator: '$after'"; fi
    fi
    ;;
  "TTDEF void tt_"*"_free("*)
    obj=$(printf '%s' "$params" | sed -E 's/^(tt_[a-z0-9_]+) \*.*/\1/')
    [ "$name" = "${obj}_free" ] || why="$name frees a $obj: it should be called ${obj}_free"
    ;;
  *)
    case "$total_functions" in
    *" $name "*) ;;
    *) printf '%s' "$comment" | grep -q 'Preconditions (TT_ASSERT)' ||
         why="returns no tt_result, so its comment must state its preconditions ('Preconditions (TT_ASSERT): ...')" ;;
    esac
    ;;
  esac
  if printf '%s' "$params" | grep -qE 'tt_allocator \*allocator' &&
     ! printf '%s' "$params" | grep -q 'const tt_allocator \*allocator'; then
    why="${why:+$why; }the allocator parameter must be 'const tt_allocator *allocator'"
  fi
  if [ -z "$why" ]; then echo "ok   api: $name follows the contract"; else echo "FAIL api: $name: $why"; fi
done <<<"$decls"

for obj in $objects; do
  if printf '%s\n' "$frees" | grep -qx "${obj}_free"; then
    echo "ok   api: $obj comes out through $obj ** and goes with ${obj}_free"
  else
    echo "FAIL api: $obj is returned through $obj ** but there is no ${obj}_free"
  fi
done

# Allocators are passed, never carried in option or description structs: a
# struct with a tt_allocator member must be an object the library returns.
structs=$(awk '
  /^#ifndef TILEDTEX_H/ { on = 1 }
  /^#endif \/\* TILEDTEX_H/ { on = 0 }
  on && /^typedef struct tt_[a-z0-9_]+ \{/ { name = $3; has = 0 }
  on && name != "" && /tt_allocator allocator;/ { has = 1 }
  on && /^\} tt_[a-z0-9_]+;/ { if (has) print name; name = "" }
' "$header")
for s in $structs; do
  if printf '%s\n' $objects | grep -qx "$s"; then
    echo "ok   api: $s remembers the allocator it was made with"
  else
    echo "FAIL api: $s carries a tt_allocator but is not an object the library returns (pass the allocator instead)"
  fi
done

# The contract test (tests/test_contract.c) calls every fallible function with
# hostile arguments and checks that each has cases; its list of them must be
# exactly the header's `TTDEF tt_result` declarations, in order, so that a new
# function fails here until it has contract cases.
contract_test=$(dirname "$0")/test_contract.c
listed=$(sed -n '/CONTRACT FUNCTIONS BEGIN/,/CONTRACT FUNCTIONS END/p' "$contract_test" 2>/dev/null |
  grep -oE '"tt_[a-z0-9_]+"' | tr -d '"')
declared=$(printf '%s\n' "$decls" | cut -f2 | grep '^TTDEF tt_result ' |
  sed -E 's/^TTDEF tt_result (tt_[a-z0-9_]+)\(.*/\1/')
if [ -n "$declared" ] && [ "$listed" = "$declared" ]; then
  echo "ok   api: the contract test lists the $(printf '%s\n' "$declared" | wc -l | tr -d ' ') fallible functions the header declares"
else
  missing=$(comm -23 <(printf '%s\n' "$declared" | sort) <(printf '%s\n' "$listed" | sort) | tr '\n' ' ')
  extra=$(comm -13 <(printf '%s\n' "$declared" | sort) <(printf '%s\n' "$listed" | sort) | tr '\n' ' ')
  echo "FAIL api: the function list of $contract_test is not the header's fallible functions in order" \
    "(not listed: ${missing:-none}; not declared: ${extra:-none})"
fi
