#!/usr/bin/python3
"""The least friction a configuration of particle bodies needs to stand still.

Reads the state a property-test case left (MOTES_PROPERTY_DUMP=DIR, tests/properties) and asks
whether its bodies could stand as they lie: is there a set of contact forces, each pushing (never
pulling) along the line of the two particles' centres (the floor: along its normal) with a
tangential part at most mu times its normal part, that balances every dynamic body's weight, in
force and in torque about its centre of mass? That is a linear program (the friction cone as a
pyramid of K sides); bisection on mu gives the least friction that balances (docs/validation.md,
"Random impulse scenes").

The pyramid inside the cone (its edges on the cone) gives an upper bound of the true answer, the
one around it (edges at mu / cos(pi / K)) a lower bound: both are printed. A case whose bodies
drift with more friction than the upper bound can stand, and a solver that lets them slide is
wrong; a case that needs more than it has must slide.

Needs Debian's python3-numpy and python3-scipy: run it with /usr/bin/python3.

  scripts/static_balance.py DUMP.txt [...] [--gap METRES] [--sides K]

A dump's lines: "mu F", "body INDEX static|dynamic INV_MASS X Y Z" (centre of mass), "particle
BODY X Y Z RADIUS VX VY VZ"; the floor is the plane y = 0.
"""
import argparse
import math
import sys

import numpy as np
from scipy.optimize import linprog

GRAVITY = 9.81


def load(path):
    """(mu, bodies, particles) of a dump: bodies {index: dict(static, inv_mass, com)}, particles
    [(body, centre, radius)]."""
    mu, bodies, particles = None, {}, []
    with open(path, encoding="utf-8") as f:
        for number, line in enumerate(f, 1):
            fields = line.split()
            if not fields:
                continue
            try:
                if fields[0] == "mu":
                    mu = float(fields[1])
                elif fields[0] == "body":
                    bodies[int(fields[1])] = dict(
                        static=fields[2] == "static", inv_mass=float(fields[3]),
                        com=np.array([float(v) for v in fields[4:7]]))
                elif fields[0] == "particle":
                    particles.append((int(fields[1]), np.array([float(v) for v in fields[2:5]]),
                                      float(fields[5])))
                else:
                    raise ValueError(f"unknown record '{fields[0]}'")
            except (IndexError, ValueError) as e:
                sys.exit(f"{path}:{number}: {e}")
    if mu is None or not bodies:
        sys.exit(f"{path}: no 'mu' line or no bodies: not a MOTES_PROPERTY_DUMP file")
    return mu, bodies, particles


def contacts(bodies, particles, gap):
    """Contacts as the impulse model makes them: (body a, body b or None for a static one or the
    floor, point, unit normal from b towards a) for every two particles of different bodies (one
    of them dynamic) whose surfaces are at most `gap` apart, at their midpoint; and every particle
    of a dynamic body within `gap` of the floor (y = 0), at its lowest point."""
    centres = np.array([p[1] for p in particles])
    radii = np.array([p[2] for p in particles])
    owner = np.array([p[0] for p in particles])
    found = []
    for i, (body, x, r) in enumerate(particles):
        if bodies[body]["static"]:
            continue
        d = x - centres
        dist = np.linalg.norm(d, axis=1)
        for j in np.nonzero((dist - (r + radii) <= gap) & (owner != body))[0]:
            other = int(owner[j])
            if not bodies[other]["static"] and j < i:
                continue  # two dynamic bodies: once, from the lower particle
            found.append((body, None if bodies[other]["static"] else other,
                          (x + centres[j]) / 2.0, d[j] / dist[j]))
        if x[1] - r <= gap:
            found.append((body, None, x - np.array([0.0, r, 0.0]), np.array([0.0, 1.0, 0.0])))
    return found


def imbalance(mu, bodies, found, sides=24, around=True):
    """The least total imbalance (weights of the whole case) the contacts can leave at friction
    mu: 0 when the bodies can stand. around: the pyramid around the cone, else inside it."""
    dynamic = [b for b in bodies if not bodies[b]["static"]]
    if not dynamic:
        return 0.0
    row = {b: 6 * k for k, b in enumerate(dynamic)}
    total = sum(1.0 / bodies[b]["inv_mass"] for b in dynamic) * GRAVITY
    arm = 0.01  # torques in units of the case's weight times 1 cm (a particle diameter)
    spread = mu / math.cos(math.pi / sides) if around else mu
    columns = []
    for a, b, point, n in found:
        t1 = np.cross(n, [1.0, 0.0, 0.0] if abs(n[0]) < 0.9 else [0.0, 1.0, 0.0])
        t1 /= np.linalg.norm(t1)
        t2 = np.cross(n, t1)
        for k in range(sides):
            angle = 2.0 * math.pi * k / sides
            force = n + spread * (math.cos(angle) * t1 + math.sin(angle) * t2)
            col = np.zeros(6 * len(dynamic))
            for body, sign in ((a, 1.0), (b, -1.0)):
                if body is None:
                    continue
                col[row[body]:row[body] + 3] += sign * force / total
                col[row[body] + 3:row[body] + 6] += (
                    sign * np.cross(point - bodies[body]["com"], force) / (total * arm))
            columns.append(col)
    weight = np.zeros(6 * len(dynamic))
    for b in dynamic:
        weight[row[b] + 1] = GRAVITY / bodies[b]["inv_mass"] / total
    if not columns:
        return float(np.abs(weight).sum())
    a = np.array(columns).T
    rows = a.shape[0]
    # min sum |a x - weight| over x >= 0, as an LP with the residual split into two slacks.
    cost = np.concatenate([np.zeros(a.shape[1]), np.ones(2 * rows)])
    res = linprog(cost, A_eq=np.hstack([a, np.eye(rows), -np.eye(rows)]), b_eq=weight,
                  bounds=(0, None), method="highs")
    if res.status != 0:
        raise RuntimeError(f"linprog: {res.message}")
    return float(res.fun)


def needed_friction(bodies, found, sides=24, around=True, tolerance=1e-7, most=4.0):
    """The least mu at which the bodies can stand (bisection to 1e-4), or inf above `most`."""
    if imbalance(most, bodies, found, sides, around) > tolerance:
        return math.inf
    lo, hi = 0.0, most
    if imbalance(0.0, bodies, found, sides, around) <= tolerance:
        return 0.0
    while hi - lo > 1e-4:
        mid = 0.5 * (lo + hi)
        if imbalance(mid, bodies, found, sides, around) > tolerance:
            lo = mid
        else:
            hi = mid
    return hi


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("dumps", nargs="+", help="files written with MOTES_PROPERTY_DUMP")
    parser.add_argument("--gap", type=float, default=2e-6,
                        help="surfaces this far apart (m) count as touching (default 2e-6: a "
                             "resting impulse contact keeps a gap of about g h^2, 0.15 um at the "
                             "property tests' substep h = 0.125 ms)")
    parser.add_argument("--sides", type=int, default=24, help="sides of the friction pyramid")
    args = parser.parse_args()
    for path in args.dumps:
        mu, bodies, particles = load(path)
        found = contacts(bodies, particles, args.gap)
        low = needed_friction(bodies, found, args.sides, around=True)
        high = needed_friction(bodies, found, args.sides, around=False)
        verdict = ("can stand" if mu >= high else "cannot stand" if mu < low else "undecided")
        print(f"{path}: mu {mu:.3f}, {len(found)} contacts: needs mu between {low:.3f} and "
              f"{high:.3f} ({verdict}; {high / mu:.0%} of its friction)")


if __name__ == "__main__":
    main()
