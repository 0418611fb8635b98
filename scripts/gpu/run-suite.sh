#!/usr/bin/env bash
# Runs on the GPU machine, in the repository root, after scripts/gpu/bundle.sh built gpu-bundle/
# here and it travelled along: devices, the conformance suite on every backend side by side
# (openmp, cuda, vulkan with the validation layer on), compute-sanitizer's memcheck and racecheck
# over the suite's CUDA cases, the benchmarks, and every example scene to its end on CUDA and
# Vulkan, each part under its own time limit so that one slow part cannot lose the others'
# results. Results go to ${OUT:-gpu-out}/ (at most 8 files come back from the GPU machine):
# conformance.txt, conformance.md, sanitize.txt, bench.txt, bench.json, bench.md
# (scripts/gpu/bench-tables.py), scenes.md.
# Usage: scripts/gpu/run-suite.sh
#          [conformance|unit|properties|sanitize|bench|mpi|scenes|scaling|all]...
#   (default all but scaling, which needs several GPUs, and properties; all writes 9 files, one
#   more than come back from the GPU machine in one call, so run scenes in a call of its own, as
#   its time asks)
#   properties: the seeded random impulse scenes (tests/properties), and the same scenes with
#     position contacts (RandomPositionScenes), on CUDA and Vulkan,
#     MOTES_PROPERTY_SEEDS per kind and backend (default 500) in batches of MOTES_PROPERTY_BATCH
#     (default 250), the kept seeds and the far ones (FarImpulseScenes), into properties.txt;
#     LIMIT_PROPERTIES seconds each backend
#   unit: the unit tests' CUDA cases (checkpoint resume on CUDA, the CLI on CUDA), into unit.txt
#   scenes: every examples/scenes/*.json to its end (its settings.duration) on CUDA and on Vulkan
#     with the validation layer (MOTES_SCENE_BACKENDS, default "cuda vulkan"), one after another,
#     each checked as CI checks openmp and lavapipe (tests/scenes/scene_to_end_test.sh: exit code
#     0, no warning line, every step done, the summary's guard line says "no warning"), into
#     scenes.md: a row per run (scene, backend, steps, wall time, steps/s, guard line, verdict),
#     then the output of each run that failed. Any warning, failure or run cut off fails the part.
#     LIMIT_SCENE seconds a run (default 240), LIMIT_SCENES seconds for them all (default 540);
#     MOTES_SCENES: the scene files (a glob; default examples/scenes/*.json)
#   mpi: the MPI tests on CUDA and Vulkan (MOTES_MPI_BACKENDS) at 1, 2 and 4 ranks (sharing the
#     machine's GPUs), and W1 over 1, 2, 4 ranks (motes_mpi_bench, MOTES_MPI_SIZES; empty: none),
#     into mpi.txt
#   scaling: W1 over 1 and N GPUs, a rank each (motes_mpi_bench), into scaling.txt:
#     MOTES_SCALING_RUNS="BACKEND:SIZE:RANKS[:HALO] ..." (default CUDA at 67 M on 1 and 2 GPUs,
#     134 M on 2; HALO auto or host, motes_mpi_bench --halo), MOTES_SCALING_STEPS,
#     LIMIT_SCALING_RUN seconds each
#   MOTES_BENCH_RUNS="cuda:falling cuda:dominoes cuda:dense vulkan:falling ..."   what is measured
#     (also BACKEND:huge: W1 at 67 M and 134 M particles, one short repeat, the host's build on
#     transparent huge pages (GLIBC_TUNABLES=glibc.malloc.hugetlb=1); BACKEND:dominoes-1m:
#     W2 with 1,000,000 dominoes; BACKEND:cloth: W3 at 256 x 256 and 1024 x 1024;
#     BACKEND:soft: W4 with 1,000 and 10,000 soft cubes; BACKEND:impulse-dominoes: W2's chain
#     with impulse contacts, 100,000 dominoes;
#     openmp:scaling: W1 at 1 M on 1, 2, 4, 8 and 16 threads)
#   MOTES_GPU_SIZES, MOTES_GPU_DENSE_SIZES   W1 sizes of the falling and dense phases
#   MOTES_SANITIZE_TOOLS="memcheck racecheck"   compute-sanitizer tools
#   LIMIT_CONFORMANCE, LIMIT_SANITIZE, LIMIT_FALLING, LIMIT_DENSE, LIMIT_DOMINOES, LIMIT_HUGE,
#   LIMIT_SCALING, LIMIT_CLOTH, LIMIT_SOFT   seconds
set -uo pipefail
parts=${*:-all}
out=${OUT:-gpu-out}
mkdir -p "$out"
. "$(dirname "$0")/prelude.sh"
want() { [[ (" $parts " == *" all "* && $1 != scaling) || " $parts " == *" $1 "* ]]; }
# The device list heads the conformance log.
{ nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader; motes devices; } \
  2>&1 | tee -a "$out/conformance.txt"
status=0
part() {  # part SECONDS LOG COMMAND...: runs COMMAND, its output appended to $out/LOG.txt
  local limit=$1 name=$2
  shift 2
  echo "== $name: $* (at most ${limit} s)" | tee -a "$out/$name.txt"
  timeout "$limit" "$@" >>"$out/$name.txt" 2>&1
  local rc=$?
  tail -n "${TAIL_LINES:-12}" "$out/$name.txt"
  echo "== $name: exit $rc" | tee -a "$out/$name.txt"
  return $rc
}
if want conformance; then
  MOTES_VULKAN_VALIDATION=1 MOTES_CONFORMANCE_TABLE="$out/conformance.md" \
    part "${LIMIT_CONFORMANCE:-240}" conformance motes_conformance_tests --gtest_brief=1 || status=1
  # Again with at most 3 workgroups per dimension (every shader through the 2D-dispatch path), the
  # scans without subgroup arithmetic, the neighbour list in blocks of at most 3 columns and the
  # conditional rebuild through its passes in conditional rendering at every size (the first run
  # takes neighbours_update_small.glsl's one workgroup up to 65,536 buckets, the GPU's default; CI
  # runs the passes without conditional rendering, MOTES_VULKAN_NO_CONDITIONAL=1, on lavapipe).
  MOTES_VULKAN_VALIDATION=1 MOTES_VULKAN_MAX_GROUPS_X=3 MOTES_VULKAN_NO_SUBGROUPS=1 \
    MOTES_VULKAN_LIST_COLUMNS=3 MOTES_VULKAN_SMALL_REBUILD=0 \
    MOTES_CONFORMANCE_BACKENDS=vulkan \
    part "${LIMIT_2D:-150}" conformance motes_conformance_tests --gtest_brief=1 --gtest_filter=-*Scenes* ||
    status=1
  # The kernel cases once more with every buffer a call neither reads nor writes poisoned
  # (core/include/motes/backend/kernels.h: a kernel reading a buffer its entry does not list fails),
  # and CUDA's impulse sweeps over the particles their counting pass listed at every size (by
  # default only from one wave of particles up: impulses_compute.cu).
  MOTES_CONFORMANCE_POISON_UNREAD=1 MOTES_CONFORMANCE_BACKENDS=cuda,vulkan MOTES_CUDA_IMPULSE_LIST_FROM=0 \
    part "${LIMIT_POISON:-180}" conformance motes_conformance_tests --gtest_brief=1 \
    --gtest_filter='Conformance/*:-*Scenes*' || status=1
  # The README's main job, on each GPU backend.
  for backend in cuda vulkan; do
    MOTES_VULKAN_VALIDATION=1 part 60 conformance motes run examples/scenes/dominoes.json \
      --backend "$backend" --out "${TMPDIR:-/tmp}/motes-dominoes-$backend" || status=1
  done
fi
if [[ " $parts " == *" properties "* ]]; then
  for backend in cuda vulkan; do
    MOTES_VULKAN_VALIDATION=0 MOTES_PROPERTY_SEEDS=${MOTES_PROPERTY_SEEDS:-500} \
      MOTES_PROPERTY_BATCH=${MOTES_PROPERTY_BATCH:-250} TAIL_LINES=30 \
      part "${LIMIT_PROPERTIES:-240}" properties motes_property_tests --gtest_brief=1 \
      --gtest_filter="*/${backend}_*:*KeptImpulseSeeds*/${backend}:*FarImpulseScenes*/${backend}" ||
      status=1
  done
fi
if want unit; then
  part "${LIMIT_UNIT:-120}" unit motes_unit_tests --gtest_brief=1 --gtest_filter='*cuda*:*Cuda*' ||
    status=1
fi
if want mpi; then
  # The machine's own OpenMPI runs the ranks (run as root: its two allow variables).
  export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
  export OMPI_MCA_btl_vader_single_copy_mechanism=none
  for backend in ${MOTES_MPI_BACKENDS:-cuda vulkan}; do
    for n in 1 2 4; do
      MOTES_MPI_BACKEND=$backend MOTES_VULKAN_VALIDATION=1 part "${LIMIT_MPI:-120}" mpi \
        mpirun --oversubscribe --bind-to none -np "$n" motes_mpi_tests || status=1
    done
  done
  for size in ${MOTES_MPI_SIZES-1048576}; do
    for backend in cuda vulkan; do
      for n in 1 2 4; do
        part "${LIMIT_MPI:-120}" mpi mpirun --oversubscribe --bind-to none -np "$n" \
          motes_mpi_bench --backend "$backend" --size "$size" --steps 200 || status=1
      done
    done
  done
fi
if want scaling; then
  # W1 over the machine's GPUs, one rank each (docs/benchmarks.md, "Scale-out"): strong scaling
  # (the same size on 1 and N GPUs) and weak scaling (the size per GPU kept). The MPI library's
  # CUDA awareness and the GPUs' links head the log.
  export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
  { nvidia-smi topo -m; ompi_info --parsable --all | grep -i 'cuda_support' ; } \
    >>"$out/scaling.txt" 2>&1
  for run in ${MOTES_SCALING_RUNS:-cuda:67108864:1 cuda:67108864:2 cuda:134217728:2}; do
    IFS=: read -r backend size n halo <<<"$run"
    part "${LIMIT_SCALING_RUN:-280}" scaling mpirun --bind-to none -np "$n" motes_mpi_bench \
      --backend "$backend" --size "$size" --steps "${MOTES_SCALING_STEPS:-200}" --warmup 20 \
      --halo "${halo:-auto}" ||
      status=1
  done
fi
if want scenes; then
  # Every example scene to its end, each run under its own limit and all under the part's (runs
  # not started by then are listed as not run, and fail the part).
  table=$out/scenes.md logs=${TMPDIR:-/tmp}/motes-scenes
  rm -rf "$logs" && mkdir -p "$logs"
  {
    echo "# Every example scene to its end on $(nvidia-smi --query-gpu=name --format=csv,noheader |
      head -n 1) ($(date -u +%F), $(motes --version 2>&1 | head -n 1))"
    echo
    echo "| scene | backend | steps | wall time | steps/s | guard line | verdict |"
    echo "|---|---|---|---|---|---|---|"
  } >"$table"
  scenes_status=0 deadline=$((SECONDS + ${LIMIT_SCENES:-540}))
  for backend in ${MOTES_SCENE_BACKENDS:-cuda vulkan}; do
    for scene in ${MOTES_SCENES:-examples/scenes/*.json}; do
      name=$(basename "$scene" .json)
      full=$(python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["settings"]["duration"])' "$scene")
      limit=$((deadline - SECONDS))
      [ "$limit" -le "${LIMIT_SCENE:-240}" ] || limit=${LIMIT_SCENE:-240}
      if [ "$limit" -le 0 ]; then
        echo "| $name | $backend | - | - | - | - | FAIL: not run, LIMIT_SCENES ran out |" >>"$table"
        scenes_status=1
        continue
      fi
      rc=0
      MOTES_VULKAN_VALIDATION=1 MOTES_SCENE_TABLE=$table timeout -k 10 "$limit" bash \
        tests/scenes/scene_to_end_test.sh "$(command -v motes)" "$scene" "$backend" full "$full" "" \
        "$logs/$name-$backend.log" >"$logs/$name-$backend.out" 2>&1 || rc=$?
      head -n 1 "$logs/$name-$backend.out"
      if [ "$rc" -eq 124 ]; then
        echo "| $name | $backend | - | > $limit s | - | - | FAIL: cut off at its limit of $limit s |" \
          >>"$table"
        echo "$name on $backend: cut off at its limit of $limit s"
      fi
      if [ "$rc" -ne 0 ]; then
        scenes_status=1
        { echo; echo "## $name on $backend: exit $rc"; echo; echo '```'
          cat "$logs/$name-$backend.out"; tail -n 40 "$logs/$name-$backend.log"; echo '```'
        } >>"$logs/failures.md"
      fi
    done
  done
  [ ! -f "$logs/failures.md" ] || cat "$logs/failures.md" >>"$table"
  echo "== scenes: exit $scenes_status ($out/scenes.md)"
  [ "$scenes_status" -eq 0 ] || status=1
fi
if want sanitize; then
  sanitizer=$(command -v compute-sanitizer || echo /usr/local/cuda/bin/compute-sanitizer)
  # Every CUDA case under memcheck; racecheck (much slower) leaves out the one-second domino
  # chain (83,000 steps of the same kernels that the other scene cases run).
  # The rebuild goes through the host (MOTES_CUDA_HOST_REBUILD=1: no graph, no conditional node),
  # which compute-sanitizer 13.0 follows; the kernels are the same.
  for tool in ${MOTES_SANITIZE_TOOLS:-memcheck racecheck}; do
    filter=*
    [ "$tool" = racecheck ] && filter=-*DominoChain*
    MOTES_CUDA_HOST_REBUILD=1 MOTES_CONFORMANCE_BACKENDS=cuda part "${LIMIT_SANITIZE:-300}" \
      sanitize "$sanitizer" --tool "$tool" --error-exitcode 1 motes_conformance_tests \
      --gtest_brief=1 --gtest_filter="$filter" || status=1
  done
fi
if want bench; then
  mkdir -p bench-cache "${TMPDIR:-/tmp}/motes-bench"
  sizes=${MOTES_GPU_SIZES:-16384,65536,262144,1048576,4194304,16777216}
  # The floors, in the same run: device-to-device copy and CUB's sort of N (key, value) pairs.
  part 60 bench motes_gpu_floors $(echo "$sizes" | tr , ' ')
  for run in ${MOTES_BENCH_RUNS:-cuda:falling cuda:dominoes cuda:dense vulkan:falling vulkan:dominoes vulkan:dense}; do
    backend=${run%%:*} what=${run#*:} j=${TMPDIR:-/tmp}/motes-bench/${run/:/-}.json
    case $what in
      falling)
        part "${LIMIT_FALLING:-200}" bench motes bench --backend "$backend" --workload settle \
          --phase falling --sizes "$sizes" --json "$j" ;;
      dominoes)
        part "${LIMIT_DOMINOES:-60}" bench motes bench --backend "$backend" --workload dominoes \
          --dominoes 100000 --domino-rows 100 --json "$j" ;;
      dense)
        part "${LIMIT_DENSE:-200}" bench motes bench --backend "$backend" --workload settle \
          --phase dense --sizes "${MOTES_GPU_DENSE_SIZES:-16384,65536,262144,1048576}" --json "$j" ;;
      cloth)
        part "${LIMIT_CLOTH:-120}" bench motes bench --backend "$backend" --workload cloth \
          --cloth-sides 256,1024 --json "$j" ;;
      impulse-dominoes)
        part "${LIMIT_DOMINOES:-60}" bench motes bench --backend "$backend" \
          --workload impulse-dominoes --dominoes 100000 --domino-rows 100 --domino-steps 500 \
          --json "$j" ;;
      soft)
        part "${LIMIT_SOFT:-120}" bench motes bench --backend "$backend" --workload soft \
          --soft-counts 1000,10000 --json "$j" ;;
      dominoes-1m)
        part "${LIMIT_DOMINOES:-60}" bench motes bench --backend "$backend" --workload dominoes \
          --dominoes 1000000 --domino-rows 1000 --json "$j" ;;
      huge)
        part "${LIMIT_HUGE:-300}" bench env GLIBC_TUNABLES=glibc.malloc.hugetlb=1 \
          motes bench --backend "$backend" --workload settle \
          --phase falling --sizes 67108864,134217728 --repeats 1 --falling-steps 200 --json "$j" ;;
      scaling)
        for t in 1 2 4 8 16; do
          part "${LIMIT_SCALING:-100}" bench motes bench --backend openmp --threads "$t" \
            --workload settle --phase falling --sizes 1048576 --repeats 1 --falling-steps 100 \
            --json "${j%.json}-$t.json"
        done ;;
    esac
  done
  # Every JSON result in one file, and the tables of docs/benchmarks.md made from it.
  python3 - "$out/bench.json" "${TMPDIR:-/tmp}"/motes-bench/*.json <<'PY'
import json, sys
rows = []
for path in sys.argv[2:]:
    try:
        rows += json.load(open(path))
    except (OSError, ValueError) as e:
        print(f"{path}: {e}", file=sys.stderr)
json.dump(rows, open(sys.argv[1], "w"), indent=1)
PY
  python3 "$(dirname "$0")/bench-tables.py" "$out/bench.json" --floors "$out/bench.txt" \
    --out "$out/bench.md"
fi
exit "$status"
