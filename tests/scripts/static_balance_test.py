#!/usr/bin/python3
"""scripts/static_balance.py against closed forms: a ladder of particles against a wall (friction
at both ends), two rods leaning on each other, a box lying on the floor. Exit 77 (skipped) when
Debian's python3-scipy is missing."""
import math
import os
import sys
import tempfile

try:
    import numpy as np  # noqa: F401
    import scipy  # noqa: F401
except ImportError as e:
    print(f"skipped: {e} (Debian: python3-numpy python3-scipy)")
    sys.exit(77)

sys.path.insert(0, os.path.join(sys.argv[1], "scripts"))
import static_balance as sb  # noqa: E402

R = 0.005  # particle radius (1 cm particles, as the property tests use)
failures = []


def rod(body, foot, angle, count, lines, direction=1.0):
    """A straight rod of `count` touching particles from `foot` (its lowest centre) at `angle`
    above the floor, leaning towards +x (direction 1) or -x; returns its centres."""
    step = 2.0 * R
    centres = [(foot[0] + direction * k * step * math.cos(angle), foot[1] + k * step * math.sin(angle))
               for k in range(count)]
    com = np.mean(np.array(centres), axis=0)
    lines.append(f"body {body} dynamic {1.0 / (0.001 * count)} {com[0]} {com[1]} 0")
    lines.extend(f"particle {body} {x} {y} 0 {R} 0 0 0" for x, y in centres)
    return centres, com


def needed(lines, gap=1e-9):
    with tempfile.NamedTemporaryFile("w", suffix=".txt", delete=False) as f:
        f.write("mu 0.5\n" + "\n".join(lines) + "\n")
        path = f.name
    try:
        _, bodies, particles = sb.load(path)
    finally:
        os.unlink(path)
    found = sb.contacts(bodies, particles, gap)
    return (sb.needed_friction(bodies, found, around=True),
            sb.needed_friction(bodies, found, around=False))


def check(name, exact, bounds):
    low, high = bounds
    ok = low <= exact + 2e-4 and exact <= high + 2e-4 and high - exact < 2e-3
    print(f"{name}: exact {exact:.4f}, the pyramids give {low:.4f} to {high:.4f}"
          f"{'' if ok else '  FAILED'}")
    if not ok:
        failures.append(name)


for degrees in (50.0, 60.0, 75.0):
    angle = math.radians(degrees)
    lines = []
    centres, com = rod(0, (0.0, R), angle, 8, lines)
    top = centres[-1]
    lines.append(f"body 1 static 0 {top[0] + 2 * R} {top[1]} 0")
    lines.append(f"particle 1 {top[0] + 2 * R} {top[1]} 0 {R} 0 0 0")
    # Foot at a = 0 on the floor, the wall's contact at (b, h), centre of mass at gx; both
    # frictions at their limit: mu^2 (b - gx) + mu h - gx = 0.
    b, h, gx = top[0] + R, top[1], com[0]
    exact = (-h + math.sqrt(h * h + 4.0 * (b - gx) * gx)) / (2.0 * (b - gx))
    check(f"ladder at {degrees:.0f} degrees", exact, needed(lines))

for degrees in (45.0, 65.0):
    angle = math.radians(degrees)
    lines = []
    left, com = rod(0, (0.0, R), angle, 6, lines)
    span = 2.0 * (left[-1][0] + R)  # the two tops touch at x = span / 2
    rod(1, (span, R), angle, 6, lines, direction=-1.0)
    # By symmetry the top contact is horizontal and carries no friction: mu = gx / h.
    exact = com[0] / left[-1][1]
    check(f"two rods leaning at {degrees:.0f} degrees", exact, needed(lines))

lines = ["body 0 dynamic 10 0.01 0.005 0"]
lines += [f"particle 0 {x} {R} 0 {R} 0 0 0" for x in (0.0, 0.01, 0.02)]
check("a box lying on the floor", 0.0, needed(lines))

sys.exit(1 if failures else 0)
