#!/usr/bin/env python3
"""Random G-code programs through `salient export-x3g` and Debian's gpx: byte-identical x3g.

Usage: x3g_random_peer_check.py SALIENT WORKDIR [COUNT]

Each program mixes the commands the translator covers (moves absolute and relative, E absolute
and relative, homing, G92, M132, temperatures and waits, fans, tool changes, G10 offsets, M73,
M220/M221, unknown codes) with random values; a fixed seed per program, so a failure names the
program to replay. G0 always carries F: without it gpx reverses relative G0 moves, a bug we fix.
"""
import os
import random
import subprocess
import sys

COMMANDS = ["G1", "G0", "G1", "G1", "G92", "G28", "G161", "G162", "G90", "G91", "M82", "M83", "M104", "M109",
            "M140", "M190", "M133", "M134", "M106", "M107", "M126", "M127", "M132", "M18", "M84", "M17", "M73",
            "G4", "T0", "T1", "M220", "M221", "M136", "M137", "G10", "G54", "G55", "G53", "M6", "M116", "M135",
            "M300", "M72", "M320", "M321", "G130", "M131", "G29", "M999", "X5", "M70", "M71"]


def program(seed):
    r = random.Random(seed)
    num = lambda lo, hi, d=3: f"{r.uniform(lo, hi):.{d}f}"
    lines = []
    for _ in range(r.randint(5, 60)):
        c = r.choice(COMMANDS)
        if c in ("G1", "G0"):
            w = [c] + [a + num(-50, 50) for a in "XYZE" if r.random() < 0.5]
            if r.random() < 0.4 or c == "G0":
                w.append("F" + num(0, 20000, 0))
        elif c in ("G92", "G28", "G161", "G162", "M132", "M18", "M17", "M131"):
            w = [c] + [a + (num(-10, 10) if c == "G92" else "") for a in ("XYZE" if c == "G92" else "XYZAB")
                       if r.random() < 0.5]
            if c in ("G28", "G161", "G162") and r.random() < 0.5:
                w.append("F" + num(100, 3000, 0))
        elif c in ("M104", "M109", "M140", "M190", "M134"):
            w = [c] + (["S" + str(r.randint(0, 300))] if r.random() < 0.9 else []) + \
                (["T" + str(r.randint(0, 2))] if r.random() < 0.4 else [])
        elif c == "M73":
            w = [c, f"P{r.randint(0, 100)}"]
        elif c == "G4":
            w = [c, f"P{r.randint(0, 2000)}"]
        elif c in ("M220", "M221"):
            w = [c, f"S{r.randint(10, 200)}"]
        elif c == "G10":
            w = [c, f"P{r.randint(0, 3)}", "X" + num(-5, 5), "Y" + num(-5, 5), f"R{r.randint(0, 250)}",
                 f"S{r.randint(0, 250)}"]
        elif c in ("M106", "M107"):
            w = [c] + ([f"S{r.randint(0, 255)}"] if r.random() < 0.5 else [])
        elif c == "M300":
            w = [c, f"S{r.randint(0, 5000)}", f"P{r.randint(0, 3000)}"]
        elif c in ("M70", "M71"):
            w = [c] + [f"{a}{r.randint(-2, 25)}" for a in "XYP" if r.random() < 0.4]
            if r.random() < 0.8:
                w.append("(" + "".join(r.choice("abc xyz()") for _ in range(r.randint(0, 90))) + ")")
        elif c == "M72":
            w = [c, f"P{r.randint(0, 5)}"]
        elif c == "G130":
            w = [c, f"X{r.randint(-5, 300)}", f"Y{r.randint(0, 127)}"]
        else:
            w = [c]
        if r.random() < 0.1:
            w.append(r.choice(["; note", "(aside)", ";", "( nested (x) )"]))
        lines.append(" ".join(w))
    return "\n".join(lines) + "\n"


def main(salient, work, count):
    os.makedirs(os.path.join(work, "gpx"), exist_ok=True)
    os.makedirs(os.path.join(work, "ours"), exist_ok=True)
    failed = []
    for machine in ("r2x", "r2", "r2h"):
        for seed in range(count):
            name = f"p{seed}"
            src = os.path.join(work, name + ".gcode")
            with open(src, "w") as f:
                f.write(program(seed))
            theirs, ours = os.path.join(work, "gpx", name + ".x3g"), os.path.join(work, "ours", name + ".x3g")
            subprocess.run(["gpx", "-I", "-q", "-m", machine, src, theirs], check=True)
            subprocess.run([salient, "export-x3g", src, "-o", ours, "--machine", machine], check=True,
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            if open(theirs, "rb").read() != open(ours, "rb").read():
                failed.append(f"{machine} seed {seed}")
    if failed:
        print(f"{len(failed)} programs differ from gpx: " + ", ".join(failed[:10]))
        return 1
    print(f"{3 * count} random programs, byte-identical to gpx on r2x, r2 and r2h")
    return 0


if __name__ == "__main__":
    if len(sys.argv) not in (3, 4):
        sys.exit(__doc__)
    sys.exit(main(sys.argv[1], sys.argv[2], int(sys.argv[3]) if len(sys.argv) == 4 else 150))
