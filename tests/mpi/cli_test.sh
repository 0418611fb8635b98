#!/bin/sh
# `mpirun -np 2 motes run` (docs/scale-out.md): the domino chain and every example scene over two
# ranks write the same frames as one process, bit for bit (also with --halo host); a wrong
# --decomposition is refused once, with exit 2, and --halo in one process or with a wrong value;
# the motion guard warns over ranks.
# Usage: cli_test.sh MPIEXEC MOTES SOURCE_DIR WORK_DIR [quick]
#   quick (the sanitizer build, tests/CMakeLists.txt): a quarter of the steps, the same runs and
#   comparisons (that stage looks for memory errors along the paths; it took 125 s in full)
set -eu
mpiexec=$1 motes=$2 src=$3 work=$4 quick=${5:-}
rm -rf "$work" && mkdir -p "$work"
chain_steps=3000 chain_every=1000 scene_steps=400 scene_every=200 frames=60 frames_every=30
if [ "$quick" = quick ]; then
  chain_steps=750 chain_every=250 scene_steps=100 scene_every=50 frames=16 frames_every=8
fi
args="run $src/examples/scenes/dominoes.json --backend openmp --steps $chain_steps --every $chain_every --format csv"
# shellcheck disable=SC2086
"$motes" $args --out "$work/one" > "$work/one.log"
shift_np() { n=$1; shift; "$mpiexec" -np "$n" --oversubscribe --bind-to none "$motes" "$@"; }
# shellcheck disable=SC2086
shift_np 2 $args --out "$work/two" > "$work/two.log"
grep -q "over 2 MPI ranks (bricks 2 x 1 x 1)" "$work/two.log" || { cat "$work/two.log"; exit 1; }
cmp "$work/one/particles.csv" "$work/two/particles.csv"
cmp "$work/one/bodies.csv" "$work/two/bodies.csv"
echo "2 ranks: particles.csv and bodies.csv equal to one process's"
# The halo through host memory, asked for (on CUDA the default goes device to device): the same
# frames, and the summary says which way the halo went.
# shellcheck disable=SC2086
shift_np 2 $args --halo host --out "$work/host" > "$work/host.log"
grep -q "halos .* sent through host memory" "$work/host.log" || { cat "$work/host.log"; exit 1; }
cmp "$work/one/particles.csv" "$work/host/particles.csv"
echo "2 ranks, --halo host: particles.csv equal to one process's"
# --halo means nothing in one process, and takes auto or host only.
for wrong in "--halo host" "--halo sideways"; do
  status=0
  # shellcheck disable=SC2086
  "$motes" run "$src/examples/scenes/dominoes.json" --steps 1 --format none $wrong \
    > /dev/null 2> "$work/halo.err" || status=$?
  [ "$status" -ne 0 ] && grep -q "halo" "$work/halo.err" ||
    { echo "motes run $wrong in one process: exit $status"; cat "$work/halo.err"; exit 1; }
  echo "motes run $wrong in one process refused: $(head -1 "$work/halo.err")"
done

# Every example scene over two ranks (soft bodies, cloth and ropes, attachments, impulse
# contacts, meshes): frames byte-identical to one process's.
for scene in "$src"/examples/scenes/*.json; do
  name=$(basename "$scene" .json)
  # Liquids run in one process only (docs/fluids.md): over two ranks the run is refused, naming
  # the fluid and why, before anything runs.
  if grep -qE '"kind": "fluid"' "$scene"; then
    status=0
    shift_np 2 run "$scene" --backend openmp --steps 1 --format none --out "$work/$name-two" \
      > "$work/$name-two.log" 2> "$work/$name-two.err" || status=$?
    [ "$status" -ne 0 ] && grep -q "fluids do not run over MPI ranks yet" "$work/$name-two.err" ||
      { echo "$name over 2 ranks: exit $status, not the fluids' refusal"; cat "$work/$name-two.err"; exit 1; }
    echo "$name over 2 ranks refused: $(grep -m1 "fluids do not run" "$work/$name-two.err")"
    continue
  fi
  # A step of position contacts is a frame of 10 to 16 substeps: 60 of them (1 s) for those.
  steps=$scene_steps
  every=$scene_every
  if grep -qE '"contact_model": "position"' "$scene"; then
    steps=$frames
    every=$frames_every
  fi
  each="run $scene --backend openmp --steps $steps --every $every --format csv"
  # Runs over ranks drop the impulse and position contacts' memory at list builds
  # (docs/scale-out.md): one process the same, through the scene's impulse_memory_across_builds.
  # (In a folder beside a link to the assets, for the scenes' relative mesh paths.)
  alone=$scene
  if grep -qE '"contact_model": "(impulse|position)"' "$scene"; then
    mkdir -p "$work/scenes"
    ln -sfn "$src/examples/assets" "$work/assets"
    alone=$work/scenes/$name-alone.json
    sed -E 's/"contact_model": "(impulse|position)"/"contact_model": "\1", "impulse_memory_across_builds": false/' \
      "$scene" > "$alone"
  fi
  # shellcheck disable=SC2086
  "$motes" run "$alone" --backend openmp --steps "$steps" --every "$every" --format csv \
    --out "$work/$name-one" > "$work/$name-one.log"
  # shellcheck disable=SC2086
  shift_np 2 $each --out "$work/$name-two" > "$work/$name-two.log" 2> "$work/$name-two.err" ||
    { echo "$name over 2 ranks failed:"; cat "$work/$name-two.log" "$work/$name-two.err"; exit 1; }
  cmp "$work/$name-one/particles.csv" "$work/$name-two/particles.csv"
  cmp "$work/$name-one/bodies.csv" "$work/$name-two/bodies.csv"
  # The energy guard over ranks (on the host, in double, from the gathered state) has the margin
  # of one process's (on the device, in float): the same number ending the guard line. (A rise,
  # when there is one, is rounding: 5e-8 J in pendulum.json, a few percent apart on the two.)
  one=$(sed -n 's/^  guards .*; energy .* \([0-9.e+-]*\) J)$/\1/p' "$work/$name-one.log")
  two=$(sed -n 's/^  guards .*; energy .* \([0-9.e+-]*\) J)$/\1/p' "$work/$name-two.log")
  [ -n "$one" ] && [ "$one" = "$two" ] ||
    { echo "$name: energy margin '$one' J in one process, '$two' J over 2 ranks"; exit 1; }
done
echo "every example scene over 2 ranks: frames and the energy guard's margin equal to one process's"

# --decomposition that does not multiply to the rank count.
status=0
shift_np 2 run "$src/examples/scenes/dominoes.json" --steps 10 --format none --backend openmp \
  --decomposition 3,1,1 > /dev/null 2> "$work/bricks.err" || status=$?
[ "$status" -eq 2 ] && grep -q "must multiply to the 2 ranks" "$work/bricks.err" ||
  { echo "--decomposition 3,1,1 over 2 ranks: exit $status"; cat "$work/bricks.err"; exit 1; }
echo "wrong --decomposition refused: $(head -1 "$work/bricks.err")"

# The motion guard over ranks: two balls 1 m apart (one per rank) falling at dt 1e-3 s, the second
# thrown down at 1 m/s, which passes a quarter diameter per substep (2.5 m/s) at t = 0.153 s:
# from the frame at step 200 (2.96 m/s) on, the warning names it (scene particle 1 of body 1, on
# rank 1) and the largest safe dt, on the state gathered at the frames.
cat > "$work/balls.json" <<'JSON'
{"settings": {"dt": 1e-3, "substeps": 1, "particle_diameter": 0.01, "gravity": [0, -9.81, 0],
  "contact": {"stiffness": 1000, "damping": 10}},
 "bodies": [{"name": "still", "shape": {"type": "particle"}, "position": [0, 0, 0]},
            {"name": "fast", "shape": {"type": "particle"}, "position": [1, 0, 0],
             "velocity": [0, -1, 0]}]}
JSON
shift_np 2 run "$work/balls.json" --steps 400 --every 100 --format none --backend openmp \
  > "$work/balls.log" 2> "$work/balls.err"
grep -q "over 2 MPI ranks" "$work/balls.log" &&
  grep -q "step 200 (t = 0.2 s): particle 1 of body 1 'fast' moves 0.296 of its diameter" "$work/balls.err" &&
  grep -q "the largest safe dt at this speed is" "$work/balls.err" &&
  grep -q "guards          5 motion checks on the gathered state, 3 with a tunnelling warning" \
    "$work/balls.log" &&
  grep -Eq "tunnelling warning \(the worst: [0-9.]+ of a diameter per substep\); energy (never above its start \(margin [0-9.e+-]+ J\)|at most [0-9.e+-]+ of its margin above its start)" \
    "$work/balls.log" ||
  { echo "no tunnelling warning over 2 ranks:"; cat "$work/balls.log" "$work/balls.err"; exit 1; }
echo "tunnelling warned over 2 ranks: $(grep -m1 warning "$work/balls.err")"
