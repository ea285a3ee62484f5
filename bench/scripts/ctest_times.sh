#!/usr/bin/env bash
# The suite's time per test from a ctest log (`scripts/test` or `ctest -j2` output): the total and
# the slowest N tests (issue #36: the suite stays under 10 minutes on 2 cores; the slowest tests are
# the ones to make smaller or split). Prints Markdown.
#   bench/scripts/ctest_times.sh LOG [N]        (N: 25)
set -euo pipefail
log=$1
n=${2:-25}
total=$(grep -E '^Total Test time \(real\)' "$log" | tail -1 | sed -E 's/.*= *([0-9.]+) sec.*/\1/')
count=$(grep -cE '^ *[0-9]+/[0-9]+ Test +#' "$log")
sum=$(grep -E '^ *[0-9]+/[0-9]+ Test +#' "$log" | sed -E 's/.* ([0-9.]+) sec$/\1/' | awk '{s += $1} END {printf "%.1f", s}')
echo "ctest: $count tests, ${total} s wall, ${sum} s summed over tests"
echo
echo "| test | seconds |"
echo "| --- | --- |"
grep -E '^ *[0-9]+/[0-9]+ Test +#' "$log" |
  sed -E 's/^ *[0-9]+\/[0-9]+ Test +#[0-9]+: ([^ ]+) .* ([0-9.]+) sec$/\2 \1/' |
  sort -g -r | head -n "$n" | awk '{printf "| %s | %s |\n", $2, $1}'
