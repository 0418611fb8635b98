#!/usr/bin/env bash
# Proves that scene_to_end_test.sh can fail: a real run that tunnels (the motion guard's warning),
# and summaries from a stand-in for motes (a guard line counting warnings, none, one without
# `no warning`, a short run, a non-zero exit) must fail it; a guard line with extra words after
# the check count (an energy check's) and CUDA without a device (exit 77) must not.
# Usage: scene_to_end_selftest.sh MOTES WORK_DIR
set -euo pipefail
motes=$1 work=$2
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work" && mkdir -p "$work"
failures=0 cases=0
# expect EXIT_CODE PATTERN LABEL MOTES SCENE BACKEND: runs the test, checks its exit and output.
expect() {
  local want=$1 pattern=$2 label=$3 status=0
  shift 3
  bash "$here/scene_to_end_test.sh" "$1" "$2" "$3" full 1 "" "$work/$label.log" \
    >"$work/$label.out" 2>&1 || status=$?
  if [ "$status" -ne "$want" ] || ! grep -qE "$pattern" "$work/$label.out"; then
    echo "$label: exit $status (wanted $want), output:"
    cat "$work/$label.out"
    failures=$((failures + 1))
  fi
  cases=$((cases + 1))
}

# A particle of 1 cm leaving at 20 m/s and sped up by 1000 m/s^2, dt 0.1 ms: 0.3 of a diameter
# per substep after 10 ms, and the guard warns.
cat >"$work/tunnelling.json" <<'EOF'
{"settings": {"dt": 1e-4, "substeps": 1, "particle_diameter": 0.01, "gravity": [1000, 0, 0],
              "duration": 0.05, "output_interval": 0.01,
              "contact": {"stiffness": 1000, "damping": 10}},
 "bodies": [{"name": "still", "shape": {"type": "particle"}, "position": [0, 0, 0]},
            {"name": "fast", "shape": {"type": "particle"}, "position": [1, 0, 0],
             "velocity": [20, 0, 0]}]}
EOF
expect 1 "FAILED: tunnelling on openmp.*warning line.*motes: warning: step" real-warning \
  "$motes" "$work/tunnelling.json" openmp
# The same scene without the push: passes.
sed 's/\[1000, 0, 0\]/[0, 0, 0]/' "$work/tunnelling.json" >"$work/calm.json"
expect 0 "calm on openmp: 500 steps.*no warning" real-calm "$motes" "$work/calm.json" openmp

# A stand-in for motes printing GUARDS as the guard line, STEPS done, an extra summary line
# EXTRA, exit EXIT.
fake() {
  local label=$1 guards=$2 steps=${3:-100} exit=${4:-0} extra=${5:-}
  cat >"$work/$label-motes" <<EOF
#!/usr/bin/env bash
echo "motes: done"
echo "  steps           $steps of 100"
[ -z "$extra" ] || echo "  $extra"
[ -z "$guards" ] || echo "  guards          $guards"
exit $exit
EOF
  chmod +x "$work/$label-motes"
  echo "$work/$label-motes"
}
expect 1 "reports warnings" counted "$(fake counted \
  "6 motion checks, 3 with a tunnelling warning (the worst: 0.49 of a diameter per substep)")" \
  "$work/calm.json" openmp
expect 1 "reports warnings" energy-counted \
  "$(fake energy-counted "6 motion and energy checks, 2 warnings")" "$work/calm.json" openmp
expect 1 "no guard line" missing "$(fake missing "")" "$work/calm.json" openmp
expect 1 "no guard check ran" none "$(fake none "0 motion checks, no warning")" \
  "$work/calm.json" openmp
expect 1 "did 50 of 100 steps" short "$(fake short "6 motion checks, no warning" 50)" \
  "$work/calm.json" openmp
expect 1 "exited with 2" stopped "$(fake stopped "6 motion checks, no warning" 100 2)" \
  "$work/calm.json" openmp
expect 0 "no warning" energy-words "$(fake energy-words \
  "6 motion checks (energy at most 0.2% above its start), no warning")" "$work/calm.json" openmp
expect 0 "no warning" energy-line "$(fake energy-line "6 motion checks, no warning" 100 0 \
  "energy          at most 0.2% above its start, no warning")" "$work/calm.json" openmp
expect 1 "warning line.*energy +2 warnings" energy-line-counted "$(fake energy-line-counted \
  "6 motion checks, no warning" 100 0 "energy          2 warnings, no warning since step 9")" \
  "$work/calm.json" openmp
# CUDA without a device: reported skipped, never passed.
cat >"$work/nocuda-motes" <<'EOF'
#!/usr/bin/env bash
echo "cuda    unavailable: no NVIDIA driver"
echo "openmp  0  some CPU"
EOF
chmod +x "$work/nocuda-motes"
expect 77 "skipped: no CUDA device: cuda +unavailable: no NVIDIA driver" nocuda \
  "$work/nocuda-motes" "$work/calm.json" cuda
[ "$failures" -eq 0 ] || { echo "$failures of $cases cases went the wrong way"; exit 1; }
echo "all $cases cases went the right way (the outputs: $work/*.out)"
