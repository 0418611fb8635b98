#!/usr/bin/env python3
"""Markdown tables of one GPU sitting: `motes bench --json` results and the floors that
motes_gpu_floors printed in the same run (JSON lines in bench.txt).

Usage: scripts/gpu/bench-tables.py BENCH_JSON... --floors BENCH_TXT [--out FILE]
scripts/gpu/run-suite.sh writes bench.md with it; docs/benchmarks.md quotes those tables.
"""
import argparse
import json
import sys

KERNELS = ["neighbours_update", "grid_build", "neighbours_build", "contacts_compute",
           "bodies_reduce", "bodies_integrate", "particles_update", "particles_integrate",
           "constraints_solve"]
# Bytes per particle of a fused grid-DEM step (../shared/gpu/README.md): the step's floor at the
# copy bandwidth measured in the same run.
FUSED_FLOOR_BYTES = 200
GOALS_MS = {("settle", "falling", 16384): 0.030, ("settle", "falling", 1048576): 0.20,
            ("settle", "falling", 16777216): 2.5, ("settle", "dense", 16384): 0.030,
            ("settle", "dense", 1048576): 0.20, ("settle", "dense", 16777216): 2.5,
            ("dominoes", "falling", 15000000): 1.6, ("cloth", "falling", 1048576): 2.0}


def load_rows(paths):
    rows = []
    for path in paths:
        try:
            with open(path) as f:
                rows += json.load(f)
        except (OSError, ValueError) as e:
            print(f"{path}: {e}", file=sys.stderr)
    return rows


def load_floors(path):
    floors = {}
    if not path:
        return floors
    with open(path) as f:
        for line in f:
            if line.startswith('{"gpu"'):
                d = json.loads(line)
                floors[d["n"]] = d  # the last run of a size wins
    return floors


def key(r):
    return (r["workload"], r["phase"], r["particles"])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("bench", nargs="+")
    ap.add_argument("--floors")
    ap.add_argument("--out")
    a = ap.parse_args()
    rows = load_rows(a.bench)
    floors = load_floors(a.floors)
    by = {}
    for r in rows:
        by.setdefault(key(r), {})[r["backend"]] = r
    order = sorted(by, key=lambda k: (k[0] != "settle", k[1] != "falling", k[2]))
    out = []
    devices = sorted({r["device"] for r in rows})
    out.append(f"Device: {', '.join(devices)}.\n")

    out.append("| workload | N | CUDA ms/step | CUDA particle-steps/s | Vulkan ms/step | "
               "Vulkan / CUDA | goal (ms) | device B/particle | list builds |")
    out.append("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for k in order:
        c, v = by[k].get("cuda"), by[k].get("vulkan")
        cm = f"{c['median_ms_per_step']:.3f}" if c else "-"
        cp = f"{c['particle_steps_per_s']:.2e}" if c else "-"
        vm = f"{v['median_ms_per_step']:.3f}" if v else "-"
        ratio = (f"{v['median_ms_per_step'] / c['median_ms_per_step']:.2f}"
                 if c and v else "-")
        goal = GOALS_MS.get(k)
        any_row = c or v
        bpp = f"{any_row.get('bytes_per_particle', 0):.0f}" if any_row else "-"
        builds = (f"{any_row.get('neighbour_builds', 0)} in {any_row['steps']}"
                  if any_row else "-")
        out.append(f"| {k[0]} {k[1]} | {k[2]:,} | {cm} | {cp} | {vm} | {ratio} | "
                   f"{goal if goal else ''} | {bpp} | {builds} |")

    out.append("\nCUDA kernel families, from the extra run with kernel timing on (each family "
               "launched alone between CUDA events, the body passes unfused, the neighbour-list "
               "rebuild decided on the host): ms per step (grid_build and neighbours_build: their "
               "time over all steps, so the rebuilds' share), and in brackets the compulsory bytes "
               "of `motes bench` over that time (GB/s).\n")
    out.append("| workload | N | " + " | ".join(KERNELS) + " |")
    out.append("|---|---:|" + "---:|" * len(KERNELS))
    for k in order:
        c = by[k].get("cuda")
        if not c:
            continue
        cells = [f"{c['kernel_ms_per_step'].get(n, 0):.3f} "
                 f"({c['kernel_compulsory_gb_per_s'].get(n, 0):.0f})" for n in KERNELS]
        out.append(f"| {k[0]} {k[1]} | {k[2]:,} | " + " | ".join(cells) + " |")

    if floors:
        out.append("\nFloors in the same sitting (motes_gpu_floors: CUDA events, median of 20): "
                   "device-to-device copy bandwidth, CUB `DeviceRadixSort::SortPairs` of N pairs "
                   "on the grid's key bits; the fused-step floor is "
                   f"{FUSED_FLOOR_BYTES} B/particle at that bandwidth.\n")
        out.append("| N | copy GB/s | CUB sort ms (bits) | fused floor ms | CUDA falling ms/step "
                   "| x floor | CUDA dense ms/step | x floor |")
        out.append("|---:|---:|---:|---:|---:|---:|---:|---:|")
        for n in sorted(floors):
            f = floors[n]
            floor_ms = FUSED_FLOOR_BYTES * n / (f["copy_gb_per_s"] * 1e6)
            cells = []
            for phase in ("falling", "dense"):
                c = by.get(("settle", phase, n), {}).get("cuda")
                ms = c["median_ms_per_step"] if c else None
                cells += [f"{ms:.3f}", f"{ms / floor_ms:.1f}"] if c else ["-", "-"]
            out.append(f"| {n:,} | {f['copy_gb_per_s']:.0f} | {f['cub_sort_pairs_ms']:.3f} "
                       f"({f['key_bits']}) | {floor_ms:.3f} | " + " | ".join(cells) + " |")
    text = "\n".join(out) + "\n"
    if a.out:
        with open(a.out, "w") as f:
            f.write(text)
    else:
        sys.stdout.write(text)


if __name__ == "__main__":
    main()
