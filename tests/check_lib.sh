# Sourced by the shell tests (cli_test.sh, cli_geometry_test.sh, fem_samples_test.sh): a scratch
# folder removed on exit, pass/fail counting, and the summary line that decides the exit status.
#   . check_lib.sh; check NAME CONDITION...; ...; finish NAME
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
fails=0; passes=0
check() {  # check NAME CONDITION...
  local name=$1; shift
  if "$@"; then passes=$((passes+1)); else echo "FAILED: $name"; fails=$((fails+1)); fi
}
finish() {  # finish NAME: prints the counts; the status is 0 only when nothing failed
  echo "$1: $passes passed, $fails failed"
  [ "$fails" -eq 0 ]
}
