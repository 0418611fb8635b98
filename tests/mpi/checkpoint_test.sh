#!/bin/sh
# `mpirun -np 2 motes run --checkpoint-every`, `mpirun motes resume SET`, signals and --render over
# ranks (docs/reliability.md "Checkpoints over MPI ranks", docs/cli.md).
#   resume:  a resumed run writes the uninterrupted run's frames byte for byte (partitions and
#            migrations between the set and the end; rigid bodies in the halos); a set of
#            another rank count, a single process's checkpoint under mpirun, one rank's file,
#            damaged or incomplete sets and a changed scene are refused once, with exit 2, and
#            nothing is written
#   signals: SIGTERM to one rank, or to mpirun, stops every rank at one step with a last set that
#            resumes; SIGKILL while sets are written leaves the newest complete set usable
#   render:  --render over 2 ranks draws the pictures of one process, byte for byte
# Usage: checkpoint_test.sh MODE MPIEXEC MOTES SOURCE_DIR WORK_DIR
set -eu
mode=$1 mpiexec=$2 motes=$3 src=$4 work=$5
rm -rf "$work" && mkdir -p "$work"
np() { n=$1; shift; "$mpiexec" -np "$n" --oversubscribe --bind-to none "$motes" "$@"; }
die() { echo "FAILED: $*"; for f in "$work"/*.log "$work"/*.err; do [ -f "$f" ] && { echo "== $f"; cat "$f"; }; done; exit 1; }

# Ten free spheres in two rows flying at each other across the two ranks' boundary (x = 0) at
# 1 m/s without gravity: a partition every few steps, spheres changing rank, collisions.
cat > "$work/balls.json" <<'JSON'
{"settings": {"dt": 1e-3, "substeps": 1, "particle_diameter": 0.01, "gravity": [0, 0, 0],
  "contact": {"stiffness": 1000, "damping": 1}},
 "bodies": [
  {"name": "a0", "shape": {"type": "particle"}, "position": [-0.10, 0, 0], "velocity": [1, 0, 0]},
  {"name": "a1", "shape": {"type": "particle"}, "position": [-0.12, 0.004, 0], "velocity": [1, 0, 0]},
  {"name": "a2", "shape": {"type": "particle"}, "position": [-0.14, -0.004, 0], "velocity": [1, 0, 0]},
  {"name": "a3", "shape": {"type": "particle"}, "position": [-0.16, 0.002, 0.003], "velocity": [1, 0, 0]},
  {"name": "a4", "shape": {"type": "particle"}, "position": [-0.18, 0, -0.003], "velocity": [1, 0, 0]},
  {"name": "b0", "shape": {"type": "particle"}, "position": [0.10, 0.001, 0], "velocity": [-1, 0, 0]},
  {"name": "b1", "shape": {"type": "particle"}, "position": [0.12, 0.005, 0], "velocity": [-1, 0, 0]},
  {"name": "b2", "shape": {"type": "particle"}, "position": [0.14, -0.003, 0], "velocity": [-1, 0, 0]},
  {"name": "b3", "shape": {"type": "particle"}, "position": [0.16, 0.003, 0.002], "velocity": [-1, 0, 0]},
  {"name": "b4", "shape": {"type": "particle"}, "position": [0.18, 0.001, -0.002], "velocity": [-1, 0, 0]}]}
JSON
partitions() { sed -n 's/^  decomposition *\([0-9]*\) partitions, \([0-9]*\) bodies migrated.*/\1 \2/p' "$1"; }

case $mode in
resume)
  # 200 steps uninterrupted against 100 with sets at 50 and 100 and a resume from 100.
  run="run $work/balls.json --backend openmp --threads 1 --every 20 --format csv"
  # shellcheck disable=SC2086
  np 2 $run --steps 200 --out "$work/whole" > "$work/whole.log" 2>&1 || die "whole run"
  # shellcheck disable=SC2086
  np 2 $run --steps 100 --checkpoint-every 50 --out "$work/part" > "$work/part.log" 2>&1 ||
    die "run with checkpoints"
  sets="$work/part/checkpoints"
  [ -f "$sets/checkpoint-000000000050.mckset/manifest.mcks" ] &&
    [ -f "$sets/checkpoint-000000000100.mckset/rank-00000.mck" ] &&
    [ -f "$sets/checkpoint-000000000100.mckset/rank-00001.mck" ] || die "sets at 50 and 100"
  grep -q "checkpoints     2 sets written, the last $sets/checkpoint-000000000100.mckset" \
    "$work/part.log" || die "summary of the sets"
  set100="$sets/checkpoint-000000000100.mckset"
  np 2 resume "$set100" --steps 100 > "$work/resume.log" 2>&1 || die "resume"
  grep -q "resuming .* from $set100: step 100 of 200" "$work/resume.log" || die "resume header"
  cmp "$work/whole/particles.csv" "$work/part/particles.csv" || die "particles.csv differs"
  cmp "$work/whole/bodies.csv" "$work/part/bodies.csv" || die "bodies.csv differs"
  # Partitions and migrations happened between the set and the end, and the resumed run's
  # counters go on from the set's to the uninterrupted run's.
  at100=$(partitions "$work/part.log") at200=$(partitions "$work/whole.log")
  [ "$(partitions "$work/resume.log")" = "$at200" ] || die "counters: $at200 vs resumed"
  # shellcheck disable=SC2086
  set -- $at100; p100=$1 m100=$2
  # shellcheck disable=SC2086
  set -- $at200; p200=$1 m200=$2
  [ "$p200" -gt "$p100" ] && [ "$m200" -gt "$m100" ] ||
    die "no partitions or migrations between the set and the end ($at100 -> $at200)"
  echo "balls over 2 ranks: 100 + resume 100 = 200 steps byte for byte; partitions, migrations $at100 at the set, $at200 at the end"

  # Rigid bodies copied to the other rank, their poses and momenta in the halo: the dice.
  dice="run $src/examples/scenes/dice.json --backend openmp --threads 1 --every 200 --format csv"
  # shellcheck disable=SC2086
  np 2 $dice --steps 800 --out "$work/dwhole" > "$work/dwhole.log" 2>&1 || die "dice whole"
  # shellcheck disable=SC2086
  np 2 $dice --steps 400 --checkpoint-every 400 --out "$work/dpart" > "$work/dpart.log" 2>&1 ||
    die "dice with a set"
  grep -q "at the end [1-9][0-9]* halo copies" "$work/dpart.log" || die "dice: no halo copies"
  np 2 resume "$work/dpart/checkpoints/checkpoint-000000000400.mckset" --steps 400 \
    > "$work/dresume.log" 2>&1 || die "dice resume"
  cmp "$work/dwhole/particles.csv" "$work/dpart/particles.csv" || die "dice particles.csv"
  cmp "$work/dwhole/bodies.csv" "$work/dpart/bodies.csv" || die "dice bodies.csv"
  echo "dice over 2 ranks (rigid halo copies): 400 + resume 400 byte for byte"

  # The set at the end of its run: nothing to do.
  end="$work/part/checkpoints/checkpoint-000000000200.mckset"
  np 2 resume "$end" > "$work/end.log" 2>&1 || die "resume at the end"
  grep -q "nothing to do" "$work/end.log" || die "nothing to do"

  # Refusals: exit 2, one message, nothing written into the run's outputs. (The set at 100 is
  # gone: the resumed run kept its last two, at 150 and 200.)
  [ ! -e "$set100" ] && [ -d "$sets/checkpoint-000000000150.mckset" ] || die "the last two sets kept"
  touch "$work/marker"
  sleep 0.01
  refused() {  # refused NAME 'REASON' COMMAND...
    name=$1 reason=$2; shift 2
    status=0
    "$@" > "$work/$name.log" 2> "$work/$name.err" || status=$?
    [ "$status" -eq 2 ] || die "$name: exit $status"
    grep -qF -- "$reason" "$work/$name.err" || die "$name: no '$reason'"
    [ "$(grep -c 'motes: error' "$work/$name.err")" -eq 1 ] || die "$name: not one message"
    [ -z "$(find "$work/part" -newer "$work/marker" -type f)" ] || die "$name: files written"
    echo "refused ($name): $(grep -m1 'motes: error' "$work/$name.err")"
  }
  refused one-process "$end: a checkpoint set of 2 MPI ranks; this run has 1: resume it with mpirun -np 2 motes resume $end" \
    "$motes" resume "$end"
  refused four-ranks "a checkpoint set of 2 MPI ranks; this run has 4: resume it with mpirun -np 2" \
    np 4 resume "$end"
  refused rank-file "one rank's file of the checkpoint set $end of 2 MPI ranks: resume the whole set with mpirun -np 2 motes resume $end" \
    "$motes" resume "$end/rank-00001.mck"
  "$motes" run "$work/balls.json" --backend openmp --steps 10 --format none \
    --checkpoint-every 10 --out "$work/single" > /dev/null
  refused single-checkpoint "a checkpoint of one process; this run has 2 MPI ranks" \
    np 2 resume "$work/single/checkpoints/checkpoint-000000000010.mck"
  damaged() { rm -rf "$work/$1.mckset" && cp -r "$end" "$work/$1.mckset" && echo "$work/$1.mckset"; }
  bad=$(damaged flipped)
  printf '\377' | dd of="$bad/rank-00001.mck" bs=1 seek=400 conv=notrunc status=none
  refused flipped "rank 1: $bad/rank-00001.mck: corrupt checkpoint (checksum mismatch" np 2 resume "$bad"
  bad=$(damaged truncated)
  truncate -s 1000 "$bad/rank-00000.mck"
  refused truncated "$bad/rank-00000.mck: truncated checkpoint (1000 of" np 2 resume "$bad"
  bad=$(damaged missing)
  rm "$bad/rank-00001.mck"
  refused missing "$bad/rank-00001.mck: cannot open checkpoint: No such file or directory" \
    np 2 resume "$bad"
  bad=$(damaged incomplete)
  rm "$bad/manifest.mcks"
  refused incomplete "$bad/manifest.mcks: the checkpoint set has no manifest" np 2 resume "$bad"
  bad=$(damaged version)
  printf '\007' | dd of="$bad/manifest.mcks" bs=1 seek=8 conv=notrunc status=none
  refused version "$bad/manifest.mcks: checkpoint set format version 7; this motes reads 1" \
    np 2 resume "$bad"
  cp "$work/balls.json" "$work/changed.json"
  np 2 run "$work/changed.json" --backend openmp --steps 10 --format none --checkpoint-every 10 \
    --out "$work/changed" > /dev/null
  echo " " >> "$work/changed.json"
  refused changed-scene "has changed since the checkpoint set was written" \
    np 2 resume "$work/changed/checkpoints/checkpoint-000000000010.mckset"
  ;;

signals)
  # SIGTERM to rank 1 alone (as a batch system may signal one task): every rank stops at the
  # same step with a last set; the run exits 143 and says how to go on.
  long="run $work/balls.json --backend openmp --threads 1 --steps 100000000 --every 2000"
  rank_pid() {  # rank_pid MPIRUN_PID RANK
    for p in $(pgrep -P "$1"); do
      if tr '\0' '\n' < "/proc/$p/environ" | grep -qx "OMPI_COMM_WORLD_RANK=$2"; then echo "$p"; fi
    done
  }
  wait_frames() {  # wait_frames PVD: until frame 2 is listed (60 s at most)
    i=0
    while [ $i -lt 600 ] && ! grep -q particles_000002.vtu "$1" 2> /dev/null; do
      sleep 0.1; i=$((i + 1))
    done
  }
  interrupted() {  # interrupted NAME EXPECTED_EXIT: the messages, the set, and its resume
    name=$1 want=$2
    [ "$status" -eq "$want" ] || die "$name: exit $status, not $want"
    grep -q "motes: interrupted by SIGTERM at step [0-9]* of 100000000" "$work/$name.err" ||
      die "$name: no interruption message"
    set=$(sed -n 's/^motes: continue with: mpirun -np 2 motes resume \(.*\)$/\1/p' "$work/$name.err")
    [ -n "$set" ] && [ -f "$set/manifest.mcks" ] || die "$name: no set named"
    step=$(sed -n 's/.*interrupted by SIGTERM at step \([0-9]*\) .*/\1/p' "$work/$name.err")
    grep -q "steps           $step of 100000000" "$work/$name.log" || die "$name: summary"
    np 2 resume "$set" --steps 2100 > "$work/$name-resume.log" 2>&1 || die "$name: resume"
    grep -q "steps           $((step + 2100)) of $((step + 2100)) (resumed at step $step)" \
      "$work/$name-resume.log" || die "$name: resumed steps"
    echo "$name: stopped at step $step with $set; resumed"
  }
  # mpirun itself in the background (not through np, whose subshell would get the signal).
  mpi2="$mpiexec -np 2 --oversubscribe --bind-to none $motes"
  # shellcheck disable=SC2086
  $mpi2 $long --out "$work/term1" > "$work/term1.log" 2> "$work/term1.err" &
  pid=$!
  wait_frames "$work/term1/particles.pvd"
  r1=$(rank_pid "$pid" 1)
  [ -n "$r1" ] || die "no rank 1 under mpirun $pid"
  kill -TERM "$r1"
  status=0
  wait "$pid" || status=$?
  interrupted term1 143

  # SIGTERM to mpirun (Ctrl-C reaches it the same way): OpenMPI passes SIGTERM on to every rank
  # odls_base_sigkill_timeout seconds later and kills them as long after it; 4 s here.
  # shellcheck disable=SC2086
  OMPI_MCA_odls_base_sigkill_timeout=4 $mpi2 $long --out "$work/term2" \
    > "$work/term2.log" 2> "$work/term2.err" &
  pid=$!
  wait_frames "$work/term2/particles.pvd"
  kill -TERM "$pid"
  status=0
  wait "$pid" || status=$?
  [ "$status" -ne 0 ] || die "term2: exit 0"
  interrupted term2 "$status"

  # SIGKILL while a set is being written, in a run that writes one every step (two rigid blocks
  # of 4,096 particles, about 600 kB a rank file): the kill comes as soon as a set's .tmp
  # directory is seen after a complete set; whenever it is left behind (the kill came before the
  # rename), the newest complete set still resumes.
  cat > "$work/blocks.json" <<'JSON'
{"settings": {"dt": 5e-5, "particle_diameter": 0.01, "contact": {"stiffness": 2000, "damping": 200}},
 "planes": [{"name": "floor", "normal": [0, 1, 0], "point": [0, 0, 0]}],
 "bodies": [{"name": "left", "shape": {"type": "box", "particles": [16, 16, 16]}, "position": [-0.5, 0.09, 0]},
            {"name": "right", "shape": {"type": "box", "particles": [16, 16, 16]}, "position": [0.5, 0.09, 0]}]}
JSON
  mid=0 attempt=0
  while [ $mid -lt 2 ] && [ $attempt -lt 6 ]; do
    attempt=$((attempt + 1))
    out="$work/kill$attempt"
    $mpi2 run "$work/blocks.json" --backend openmp --threads 1 --steps 1000000 --format none \
      --checkpoint-every 1 --out "$out" > "$work/kill.log" 2>&1 &
    pid=$!
    ranks=""
    i=0
    while [ $i -lt 30000 ]; do  # at most about a minute
      [ -n "$ranks" ] || ranks=$(pgrep -P "$pid" || true)
      set -- "$out"/checkpoints/checkpoint-*.mckset.tmp
      tmp=$1
      set -- "$out"/checkpoints/checkpoint-*.mckset
      [ -e "$tmp" ] && [ -e "$1" ] && break
      sleep 0.002
      i=$((i + 1))
    done
    # shellcheck disable=SC2086
    kill -KILL $ranks "$pid" 2> /dev/null || true
    wait "$pid" 2> /dev/null || true
    newest=$(ls -d "$out"/checkpoints/checkpoint-*.mckset 2> /dev/null | sort | tail -1)
    [ -n "$newest" ] || die "no complete set after the kill (attempt $attempt)"
    left=$(ls -d "$out"/checkpoints/*.mckset.tmp 2> /dev/null || true)
    if [ -n "$left" ]; then
      mid=$((mid + 1))
      # (The resume's own set removes what the kill left.)
      np 2 resume "$newest" --steps 2 > "$work/kill-resume.log" 2>&1 ||
        die "the newest complete set $newest after a kill while writing $left"
      echo "killed while $(basename "$left") was written: $(basename "$newest") resumes"
    fi
  done
  [ $mid -ge 1 ] || die "no kill in $attempt came while a set was being written"
  echo "$attempt kills, $mid while a set was being written"
  ;;

render)
  # The pictures of 2 ranks are the pictures of one process.
  r="run $src/examples/scenes/dominoes.json --backend openmp --threads 1 --steps 600 --every 300 --format none --no-video --size 320x180"
  # shellcheck disable=SC2086
  "$motes" $r --render "$work/one" > "$work/one.log" 2>&1 || die "render in one process"
  # shellcheck disable=SC2086
  np 2 $r --render "$work/two" > "$work/two.log" 2>&1 || die "render over 2 ranks"
  n=0
  for f in "$work"/one/frame_*.png; do
    cmp "$f" "$work/two/$(basename "$f")" || die "$(basename "$f") differs"
    n=$((n + 1))
  done
  [ $n -eq 3 ] && [ "$(ls "$work"/two/frame_*.png | wc -l)" -eq 3 ] || die "$n pictures"
  grep -q "pictures" "$work/two.log" || die "no pictures line"
  echo "--render over 2 ranks: $n PNGs equal to one process's byte for byte"
  ;;
*)
  echo "unknown mode $mode"; exit 2 ;;
esac
