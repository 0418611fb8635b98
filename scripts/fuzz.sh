#!/usr/bin/env bash
# Fuzzing (docs/fuzzing.md): scripts/fuzz.sh TARGET SECONDS, TARGET one of scene, mesh, checkpoint,
# frames or all. Configures and builds the fuzz build with clang if needed (only the fuzz targets),
# seeds each target's corpus from the repository's scenes, meshes and test data (checkpoints and
# frames from the targets' own small simulation), runs libFuzzer for SECONDS seconds per target (the
# targets side by side, one per core) and fails on any crash, leak, timeout, out-of-memory or
# sanitizer report, printing the reproducer.
# Environment: MOTES_FUZZ_BUILD (default build-fuzz), JOBS (build parallelism),
# MOTES_FUZZ_PARALLEL (targets at once, default the number of cores), MOTES_FUZZ_ARGS (more
# libFuzzer flags, e.g. -jobs=2 -workers=2).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${MOTES_FUZZ_BUILD:-$root/build-fuzz}
all_targets=(scene mesh checkpoint frames)

usage() {
  echo "usage: scripts/fuzz.sh TARGET SECONDS   (TARGET: ${all_targets[*]} or all)" >&2
  exit 2
}
[ $# -eq 2 ] || usage
case "$1" in
  all) targets=("${all_targets[@]}") ;;
  scene | mesh | checkpoint | frames) targets=("$1") ;;
  *) usage ;;
esac
seconds=$2
[[ "$seconds" =~ ^[1-9][0-9]*$ ]] || usage

for tool in clang clang++; do
  command -v "$tool" >/dev/null || {
    echo "fuzz: $tool not found (Debian: apt-get install clang libclang-rt-14-dev)" >&2
    exit 1
  }
done

# Debug information as line tables only (-g1): the reports name files and lines, at less build time.
if [ ! -f "$build/CMakeCache.txt" ]; then
  echo "== configuring $build (clang, libFuzzer, ASan + UBSan)"
  cmake -S "$root" -B "$build" -G Ninja -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" \
    -DMOTES_FUZZ=ON -DMOTES_BUILD_TESTS=OFF \
    -DMOTES_WITH_CUDA=OFF -DMOTES_WITH_VULKAN=OFF -DMOTES_WITH_PYTHON=OFF >/dev/null
fi
grep -q '^MOTES_FUZZ:BOOL=ON' "$build/CMakeCache.txt" || {
  echo "fuzz: $build is not a fuzz build (configure it with -DMOTES_FUZZ=ON and clang, or remove it)" >&2
  exit 1
}
echo "== building ${targets[*]/#/fuzz_}"
cmake --build "$build" -j "${JOBS:-$(nproc)}" --target "${targets[@]/#/fuzz_}"

# Seeds: written afresh each run, never kept in the repository.
seed_scene() {
  cp "$root"/examples/scenes/*.json "$root"/tests/data/scenes/*.json \
    "$root"/tests/data/scenes/bad/*.json "$root"/tests/data/cli/*.json "$1/"
}
seed_mesh() {
  # The first byte picks the importer (tests/fuzz/fuzz_mesh.cpp): 0 obj, 1 ply, 2 stl, 3 off.
  local f name ext byte
  for f in "$root"/tests/data/meshes/* "$root"/tests/data/scenes/*.obj \
    "$root"/tests/data/scenes/bad/*.obj "$root"/examples/assets/*.obj; do
    name=$(basename "$f")
    ext=${name##*.}
    case "$ext" in obj) byte='\000' ;; ply) byte='\001' ;; stl) byte='\002' ;; off) byte='\003' ;; *) continue ;; esac
    { printf '%b' "$byte"; cat "$f"; } >"$1/$(basename "$(dirname "$f")")_$name"
  done
  # Binary STL and binary PLY of tests/data/meshes/cube.obj (the text seeds cover the rest).
  /usr/bin/python3 - "$root/tests/data/meshes/cube.obj" "$1" <<'EOF'
import struct, sys
v, f = [], []
for line in open(sys.argv[1]):
    p = line.split()
    if p and p[0] == "v":
        v.append(tuple(float(x) for x in p[1:4]))
    elif p and p[0] == "f":
        idx = [int(x.split("/")[0]) - 1 for x in p[1:]]
        f += [(idx[0], idx[i], idx[i + 1]) for i in range(1, len(idx) - 1)]
stl = bytearray(b"\x02" + b"motes fuzz seed: cube".ljust(80, b" ") + struct.pack("<I", len(f)))
for t in f:
    stl += struct.pack("<3f", 0, 0, 0)
    for i in t:
        stl += struct.pack("<3f", *v[i])
    stl += b"\0\0"
open(sys.argv[2] + "/cube_binary.stl", "wb").write(stl)
ply = (b"\x01ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\n"
       b"property float y\nproperty float z\nelement face %d\n"
       b"property list uchar int vertex_indices\nend_header\n" % (len(v), len(f)))
ply += b"".join(struct.pack("<3f", *p) for p in v)
ply += b"".join(struct.pack("<B3i", 3, *t) for t in f)
open(sys.argv[2] + "/cube_binary.ply", "wb").write(ply)
# Meshes built without assimp (selector 4): vertex count, int8 coordinates, index triples.
def raw(name, verts, tris):
    out = bytearray(b"\x04" + bytes([len(verts) - 1]))
    out += b"".join(struct.pack("<3b", *p) for p in verts)
    out += b"".join(bytes(t) for t in tris)
    open(sys.argv[2] + "/raw_" + name, "wb").write(out)
raw("cube", [tuple(int(4 * c) for c in p) for p in v], f)
raw("tetrahedron", [(0, 0, 0), (6, 0, 0), (0, 6, 0), (0, 0, 6)],
    [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)])
raw("octahedron", [(3, 0, 0), (-3, 0, 0), (0, 3, 0), (0, -3, 0), (0, 0, 3), (0, 0, -3)],
    [(0, 2, 4), (2, 1, 4), (1, 3, 4), (3, 0, 4), (2, 0, 5), (1, 2, 5), (3, 1, 5), (0, 3, 5)])
EOF
}
# The checkpoint and frame targets write their own seeds (valid files from a small simulation).
seed_generated() {
  MOTES_FUZZ_WRITE_SEEDS="$1" "$build/tests/fuzz/fuzz_$2" >"$1.log" 2>&1 || {
    cat "$1.log" >&2
    echo "fuzz: fuzz_$2 could not write its seeds" >&2
    exit 1
  }
}

# Per target: extra libFuzzer flags (the mesh target's seeds include the 110 KB bunny, which
# would otherwise set the mutation length limit).
flags_for() {
  case "$1" in
    mesh) echo "-max_len=16384" ;;
    *) echo "" ;;
  esac
}

files() { find "$1" -type f | wc -l; }

# One target: seeds, then libFuzzer for SECONDS; its one-line summary goes to its folder's
# summary.txt and its report (on a finding) to report.txt. Exit status 1 on a finding.
fuzz_one() {
  local t=$1 work="$build/fuzz/$1"
  rm -rf "$work/seeds"
  mkdir -p "$work/seeds" "$work/corpus" "$work/artifacts"
  case "$t" in
    scene) seed_scene "$work/seeds" ;;
    mesh) seed_mesh "$work/seeds" ;;
    checkpoint | frames) seed_generated "$work/seeds" "$t" ;;
  esac
  local dict=()
  [ -f "$root/tests/fuzz/$t.dict" ] && dict=("-dict=$root/tests/fuzz/$t.dict")
  local log="$work/fuzz.log"
  echo "== fuzz_$t for ${seconds} s ($(files "$work/seeds") seeds, $(files "$work/corpus") in the corpus; log: $log)"
  rm -rf "$work"/artifacts/* "$work/tmp" "$work/summary.txt" "$work/report.txt"
  mkdir -p "$work/tmp"  # the targets' files; a crashed run leaves its folder here
  local rc=0
  # Every UB report aborts (the targets are built with -fno-sanitize-recover); leaks inside
  # assimp's own error paths are suppressed (tests/fuzz/lsan.supp says why).
  export LSAN_OPTIONS="suppressions=$root/tests/fuzz/lsan.supp:print_suppressions=0"
  export ASAN_OPTIONS="${ASAN_OPTIONS:-fast_unwind_on_malloc=0}"
  # shellcheck disable=SC2046,SC2086
  (cd "$work" && TMPDIR="$work/tmp" "$build/tests/fuzz/fuzz_$t" -max_total_time="$seconds" -timeout=25 \
    -rss_limit_mb=2560 -print_final_stats=1 -artifact_prefix="$work/artifacts/" \
    "${dict[@]}" $(flags_for "$t") ${MOTES_FUZZ_ARGS:-} "$work/corpus" "$work/seeds") \
    >"$log" 2>&1 || rc=$?
  local execs rate found
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  mapfile -t found < <(find "$work/artifacts" -type f | sort)
  if [ "$rc" -ne 0 ] || [ ${#found[@]} -gt 0 ] ||
    grep -qE "ERROR: (AddressSanitizer|LeakSanitizer|libFuzzer)|runtime error:|SUMMARY: " "$log"; then
    {
      echo "!! fuzz_$t FAILED (exit $rc): the report:"
      awk '/ERROR:|runtime error:|ai_assert|terminate called|^motes fuzz|Test unit written/ {p = 1} p' \
        "$log" | head -60 || true
      for a in "${found[@]}"; do
        echo "!! reproducer: $a"
        echo "!!   replay: LSAN_OPTIONS=$LSAN_OPTIONS $build/tests/fuzz/fuzz_$t $a"
      done
    } >"$work/report.txt"
    echo "fuzz_$t: FAILED after ${execs:-?} executions (${found[*]:-no reproducer; see $log})" \
      >"$work/summary.txt"
    return 1
  fi
  echo "fuzz_$t: ${execs:-?} executions in ${seconds} s (${rate:-?}/s), corpus $(files "$work/corpus") inputs, no findings" \
    >"$work/summary.txt"
}

# The targets run side by side, one per core (MOTES_FUZZ_PARALLEL, default the number of cores):
# each is one single-threaded libFuzzer process, so each still gets SECONDS of a core, and four
# targets on two cores take two rounds instead of four.
parallel=${MOTES_FUZZ_PARALLEL:-$(nproc)}
[[ "$parallel" =~ ^[1-9][0-9]*$ ]] || {
  echo "fuzz: MOTES_FUZZ_PARALLEL must be a positive number, not '$parallel'" >&2
  exit 2
}
for t in "${targets[@]}"; do
  rm -f "$build/fuzz/$t/summary.txt" "$build/fuzz/$t/report.txt"
  while [ "$(jobs -rp | wc -l)" -ge "$parallel" ]; do wait -n || true; done
  fuzz_one "$t" &
done
wait
# The outcome comes from each target's files, not from exit statuses (wait -n has collected some).
status=0
summary=()
for t in "${targets[@]}"; do
  if [ -f "$build/fuzz/$t/report.txt" ]; then
    cat "$build/fuzz/$t/report.txt" >&2
    status=1
  fi
  if [ -f "$build/fuzz/$t/summary.txt" ]; then
    summary+=("$(cat "$build/fuzz/$t/summary.txt")")
  else
    summary+=("fuzz_$t: FAILED: it stopped before its summary (see the messages above)")
    status=1
  fi
done

echo "== fuzz summary"
printf '  %s\n' "${summary[@]}"
exit "$status"
