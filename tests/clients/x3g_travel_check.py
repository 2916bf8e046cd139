#!/usr/bin/env python3
"""Checks that every move of an .x3g file stays inside a Replicator 2X's travel.

Usage: x3g_travel_check.py FILE.x3g

Positions are followed in bed coordinates (mm from the bed centre), as the board has them:
homing puts an axis at its endstop (X, Y at their maxima, Z at its minimum), 144 (M132) recalls
the board's home offsets — a 2X's factory values, X 152 mm, Y 75 mm, Z 0, the corner's bed
coordinates — and 140 (G92) renames where the head is. Then every queued point (139, 155) must
lie inside GPX's r2x volume centred on the bed (246 x 152 x 155 mm), the X/Y homing corner
itself excepted (the endstops sit past the bed's edge), and never past an endstop; every point
that extrudes must lie on the profile's bed (225 x 145 mm, 150 mm high). Exit 1 with the
offending moves listed (or the byte where a file stops being x3g).
"""
import struct
import sys

SPM = (88.888889, 88.888889, 400.0)  # GPX's r2x steps/mm
HOME = (152.0, 75.0, 0.0)  # bed coordinates of the homing corner (factory home offsets)
HOMES_TO_MAX = (True, True, False)
VOLUME = (246.0, 152.0, 155.0)  # GPX's r2x axis lengths
BED = (225.0, 145.0, 150.0)  # config/printers/replicator2x.toml
TOL = 0.02  # mm: a step and a half of rounding

FIXED = {131: 8, 132: 8, 133: 5, 134: 2, 135: 6, 137: 2, 139: 25, 140: 21, 141: 6, 142: 26, 143: 2,
         144: 2, 145: 3, 146: 6, 147: 6, 148: 5, 150: 3, 151: 2, 152: 2, 154: 2, 155: 32, 156: 2,
         157: 21, 158: 5}


class Where:
    """The head's position, formatted only when a problem is reported."""

    def __init__(self, phys):
        self.phys = list(phys)

    def __format__(self, spec):
        return "(" + ", ".join("?" if p is None else f"{p:.2f}" for p in self.phys) + ")"


POINT = struct.Struct("<5i")
QUEUE = struct.Struct("<5iIB")


def actions(data):
    at = 0
    while at < len(data):
        code = data[at]
        if code == 136:
            n = 4 + data[at + 3] if at + 3 < len(data) else len(data) + 1
        elif code in (149, 153):
            start = at + (5 if code == 149 else 5)
            end = data.find(b"\0", start)
            n = (end + 1 - at) if end >= 0 else len(data) + 1
        elif code in FIXED:
            n = FIXED[code]
        else:
            sys.exit(f"x3g_travel_check: byte {at}: {code} is not an x3g action")
        if at + n > len(data):
            sys.exit(f"x3g_travel_check: byte {at}: action {code} is cut short")
        yield at, code, data[at:at + n]
        at += n


def main(path):
    data = open(path, "rb").read()
    phys = [None, None, None]    # mm, bed coordinates
    origin = [None, None, None]  # steps: the board's count at the bed centre
    homed = [False, False, False]  # homed since the count was last defined
    problems, moves, bad = [], 0, 0

    def check(i, extruding):
        nonlocal moves, bad
        moves += 1
        before = len(problems)
        where = Where(phys)
        for a, name in enumerate("XYZ"):
            p = phys[a]
            if p is None:
                problems.append(f"action {i}: a move with {name} unknown {where}")
                continue
            lo, hi = (-VOLUME[a] / 2, VOLUME[a] / 2) if a < 2 else (0.0, VOLUME[2])
            at_corner = a < 2 and abs(p - HOME[a]) <= TOL
            if HOMES_TO_MAX[a] and p > HOME[a] + TOL:
                problems.append(f"action {i}: {p - HOME[a]:.2f} mm past the {name} maximum endstop {where}")
            elif not HOMES_TO_MAX[a] and p < HOME[a] - TOL:
                problems.append(f"action {i}: {HOME[a] - p:.2f} mm past the {name} minimum endstop {where}")
            elif not at_corner and not (lo - TOL <= p <= hi + TOL):
                problems.append(f"action {i}: {name} {p:.2f} mm is outside the machine's travel {where}")
            elif extruding:
                blo, bhi = (-BED[a] / 2, BED[a] / 2) if a < 2 else (0.0, BED[2])
                if not (blo - TOL <= p <= bhi + TOL):
                    problems.append(f"action {i}: extrudes at {name} {p:.2f} mm, off the bed {where}")
        bad += len(problems) > before

    def absolute(i, a, steps):
        if origin[a] is None:
            problems.append(f"action {i}: an absolute {'XYZ'[a]} before the board's position was defined")
            return
        phys[a] = (steps - origin[a]) / SPM[a]

    for i, (at, code, p) in enumerate(actions(data), 1):
        if code in (131, 132):
            axes = p[1]
            for a in range(3):
                if axes & (1 << a):
                    if (code == 132) != HOMES_TO_MAX[a]:
                        problems.append(f"action {i}: homes {'XYZ'[a]} to an endstop the machine lacks")
                    phys[a], homed[a] = HOME[a], True
        elif code == 144:
            for a in range(3):
                if p[1] & (1 << a):
                    if not homed[a]:
                        problems.append(f"action {i}: recalls the {'XYZ'[a]} offset without homing first")
                        continue
                    origin[a] = round(HOME[a] * SPM[a]) - round(phys[a] * SPM[a])
                    homed[a] = False
        elif code == 140:
            v = POINT.unpack_from(p, 1)
            for a in range(3):
                if phys[a] is None:
                    problems.append(f"action {i}: sets {'XYZ'[a]} before homing it")
                    continue
                origin[a] = v[a] - round(phys[a] * SPM[a])
                homed[a] = False
        elif code == 139:
            v = POINT.unpack_from(p, 1)
            for a in range(3):
                absolute(i, a, v[a])
            check(i, False)
        elif code == 155:
            v = QUEUE.unpack_from(p, 1)
            mask = v[6]
            for a in range(3):
                if mask & (1 << a):
                    if phys[a] is not None:
                        phys[a] += v[a] / SPM[a]
                else:
                    absolute(i, a, v[a])
            check(i, v[3] < 0 or v[4] < 0)  # A/B are negated: forward is negative
    if problems:
        print(f"{path}: {bad} of {moves} moves leave the machine's travel or the bed:")
        for line in problems[:10]:
            print("  " + line)
        return 1
    print(f"{path}: all {moves} moves inside the machine's travel, extrusion on the bed")
    return 0


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    sys.exit(main(sys.argv[1]))
