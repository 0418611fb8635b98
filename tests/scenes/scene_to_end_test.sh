#!/usr/bin/env bash
# One example scene through `motes run` on one backend, for the scene's own settings.duration or a
# shorter one (tests/scenes/scenes.cmake says which and why), without files (--format none).
# Fails on a non-zero exit, on any warning (the motion guard's `motes: warning: ...`, a validation
# layer message, anything else that says warning), on a run that did not do every step, and when
# the summary's guard line is missing, counts no check or does not say `no warning`. Words after
# the check count (an energy check's, say) are fine; a count of warnings is not.
# Usage: scene_to_end_test.sh MOTES SCENE BACKEND DURATION|full FULL_DURATION WHY LOG
#   DURATION: simulated seconds (--duration), `steps:N` (--steps N), or `full` for the scene's own;
#   FULL_DURATION and WHY only label the result. CUDA without a CUDA device (or in a build without CUDA) exits 77, which
#   ctest reports as skipped (SKIP_RETURN_CODE). With MOTES_SCENE_TABLE=FILE set, a Markdown row
#   `| scene | backend | steps | wall time | steps/s | guard line | verdict |` is appended to FILE
#   (scripts/gpu/run-suite.sh scenes).
set -euo pipefail
motes=$1 scene=$2 backend=$3 duration=$4 full=$5 why=$6 log=$7
name=$(basename "$scene" .json)
mkdir -p "$(dirname "$log")"
: >"$log"
steps_done="" wall="" speed="" guards=""

# finish VERDICT EXIT [REASON]: the table row, a line for ctest's log, the exit code.
finish() {
  local verdict=$1 code=$2 reason=${3:-}
  if [ -n "${MOTES_SCENE_TABLE:-}" ]; then
    printf '| %s | %s | %s | %s | %s | %s | %s |\n' "$name" "$backend" "${steps_done:--}" \
      "${wall:--}" "${speed:--}" "${guards:--}" "$verdict${reason:+: ${reason//|/\\|}}" \
      >>"$MOTES_SCENE_TABLE"
  fi
  if [ "$verdict" = pass ]; then
    echo "$name on $backend: $steps_done steps, $what, in $wall; $guards"
  elif [ "$code" -eq 77 ]; then
    echo "skipped: $reason"
  else
    echo "FAILED: $name on $backend, $what: $reason"
    echo "command: $motes ${args[*]}"
    echo "--- output (the last 60 lines; all of it in $log)"
    tail -n 60 "$log"
  fi
  exit "$code"
}

# No files; --out only takes the checkpoint that a run stopped by a signal writes (a time limit).
args=(run "$scene" --backend "$backend" --format none --out "${log%.log}-out")
what="the full ${full} s"
if [[ $duration == steps:* ]]; then
  args+=(--steps "${duration#steps:}")
  what="the first ${duration#steps:} steps of the scene's ${full} s (${why})"
elif [ "$duration" != full ]; then
  args+=(--duration "$duration")
  what="${duration} s of the scene's ${full} s (shortened: ${why})"
fi

if [ "$backend" = cuda ]; then
  cuda=$("$motes" devices 2>&1 | grep -E '^cuda ' || true)
  if [ -z "$cuda" ] || grep -qE '^cuda +(unavailable|not built)' <<<"$cuda"; then
    finish skipped 77 "no CUDA device: ${cuda:-motes devices lists no cuda line}"
  fi
fi

start=$(date +%s%N)
status=0
"$motes" "${args[@]}" >"$log" 2>&1 || status=$?
wall=$(awk -v ns=$(($(date +%s%N) - start)) 'BEGIN { printf "%.1f s", ns / 1e9 }')

# The summary's numbers, where it got that far.
steps_line=$(grep -E '^ +steps +[0-9]+ of [0-9]+' "$log" || true)
total=""
[ -z "$steps_line" ] || read -r _ steps_done _ total <<<"$steps_line"
speed=$(sed -nE 's/^ +speed +([0-9.]+ ?[kM]?) steps\/s.*/\1/p' "$log" | head -n 1)
guards=$(grep -E '^ +guards +' "$log" | sed -E 's/^ +guards +//' || true)

[ "$status" -eq 0 ] || finish FAIL 1 "motes run exited with $status"
# Every line that says warning, but the summary's guard line (checked below) and other summary
# lines ("  name    value") that say "no warning" and count none.
warnings=$(awk 'tolower($0) ~ /warning|vuid-/ {
  if ($0 ~ /^ +guards /) next
  if ($0 ~ /^  [a-z][a-z ]*[a-z]  / && $0 ~ /no warning/ && $0 !~ /[0-9]+ (with [a-z ]*)?warning/) next
  print NR ": " $0 }' "$log")
if [ -n "$warnings" ]; then
  finish FAIL 1 "$(grep -c . <<<"$warnings") warning line(s), the first: $(head -n 1 <<<"$warnings")"
fi
[ -n "$steps_line" ] || finish FAIL 1 "the summary has no steps line"
[ "$steps_done" -gt 0 ] && [ "$steps_done" = "$total" ] ||
  finish FAIL 1 "the run did $steps_done of $total steps"
[ -n "$guards" ] || finish FAIL 1 "the summary has no guard line"
[ "$(grep -c . <<<"$guards")" -eq 1 ] || finish FAIL 1 "the summary has more than one guard line"
# "N <what> checks..., no warning"; a warning is counted as "K with a ... warning".
[[ $guards =~ ^([0-9]+)\ (.*)$ ]] || finish FAIL 1 "guard line without a check count: $guards"
checks=${BASH_REMATCH[1]} rest=${BASH_REMATCH[2]}
[ "$checks" -gt 0 ] || finish FAIL 1 "no guard check ran: $guards"
if [[ $rest =~ [0-9]+\ (with\ [a-z\ ]*)?warnings? ]] || [[ ! $rest =~ (^|[^a-z])no\ warning ]]; then
  finish FAIL 1 "the guard line reports warnings or does not say 'no warning': $guards"
fi
finish pass 0
