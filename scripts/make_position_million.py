#!/usr/bin/python3
"""Writes issue 27's mixed scene of about a million particles with position contacts.

Usage: scripts/make_position_million.py OUT.json [--small]

A cloth of 512 x 512 particles of 1 cm held at its corners 0.6 m above the floor, 200 ropes of 100
particles pinned at both ends across it, 512 soft cubes of 6 x 6 x 6 particles and 10,125 rigid
dice of 4 x 4 x 4 dropped onto it from 0.1 to 0.5 m above: 1,040,736 particles, 10,838 bodies. A
step is a frame of 1/60 s in 20 substeps (the highest die meets the cloth at about 3 m/s: 0.25 of
a diameter a substep). For `motes bench --workload realtime --scenes OUT.json` (docs/benchmarks.md);
too large for the example scenes CI runs to their end. --small writes the same scene at a sixteenth
of the area (a 128 x 128 cloth, 12 ropes, 32 soft cubes, 605 dice: 63,216 particles), which shows
the same weakness (particles squeezed between bodies shot out at up to 11 m/s; docs/benchmarks.md)
in under a minute on one CPU core. Standard library only.
"""
import json
import sys


def main():
    if len(sys.argv) not in (2, 3) or (len(sys.argv) == 3 and sys.argv[2] != "--small"):
        sys.exit(__doc__.strip().splitlines()[2])
    small = len(sys.argv) == 3
    side = 128 if small else 512
    d = 0.01
    width = d * (side - 1)
    x0 = -0.5 * width
    y_cloth = 0.6
    bodies = [{
        "name": "hammock",
        "kind": "cloth",
        "diameter": d,
        "cloth": {
            "corner": [x0, y_cloth, x0],
            "edge_u": [width, 0.0, 0.0],
            "edge_v": [0.0, 0.0, width],
            "particles": [side, side],
            "bend": False,
            "stiffness": 1.0,
            "pin": [[0, 0], [side - 1, 0], [0, side - 1], [side - 1, side - 1]],
        },
        "color": [0.2, 0.4, 0.85],
    }]
    # Ropes along x across the cloth, 2.4 cm apart along z, each sagging a little.
    for k in range(12 if small else 200):
        z = x0 + 0.1 + 0.024 * k
        bodies.append({
            "name": f"rope{k}",
            "kind": "rope",
            "diameter": d,
            "rope": {"from": [-0.5, y_cloth + 0.05, z], "to": [0.49, y_cloth + 0.05, z],
                     "particles": 100, "pin": [0, -1]},
            "color": [0.8, 0.6, 0.3],
        })
    bodies.append({
        "name": "cube",
        "kind": "soft",
        "shape": {"type": "box", "particles": [6, 6, 6]},
        "position": [x0 + 0.2, y_cloth + 0.45, x0 + 0.2],
        "soft": {"frequency": 20.0, "damping": 40.0, "mode": "rigid"},
        "repeat": {"grid": [4, 2, 4] if small else [16, 2, 16], "spacing": [0.3, 0.09, 0.3]},
        "color": [0.9, 0.9, 0.85],
    })
    bodies.append({
        "name": "die",
        "shape": {"type": "box", "particles": [4, 4, 4]},
        "position": [x0 + 0.3, y_cloth + 0.1, x0 + 0.3],
        "rotation": {"axis": [1.0, 0.0, 0.3], "degrees": 20.0},
        "repeat": {"grid": [11, 5, 11] if small else [45, 5, 45], "spacing": [0.1, 0.06, 0.1]},
        "color": [0.85, 0.2, 0.15],
    })
    scene = {
        "description": "Issue 27's mixed scene of about a million particles with position contacts "
                       "(scripts/make_position_million.py)",
        "settings": {
            "dt": 1.0 / 60.0,
            "substeps": 20,
            "contact_model": "position",
            "gravity": [0.0, -9.81, 0.0],
            "particle_diameter": d,
            "duration": 2.0,
            "output_interval": 1.0 / 30.0,
            "constraint_iterations": 4,
            "link_damping": 1.0,
            "contact": {"density": 1000.0, "friction": 0.5},
        },
        "bodies": bodies,
        "planes": [{"name": "floor", "normal": [0.0, 1.0, 0.0], "point": [0.0, 0.0, 0.0]}],
    }
    with open(sys.argv[1], "w") as f:
        json.dump(scene, f, indent=1)


if __name__ == "__main__":
    main()
